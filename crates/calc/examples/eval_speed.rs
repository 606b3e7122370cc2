//! Prints in-process evaluation speed (evaluations per second, one thread) of the bin
//! expressions a contribution run evaluates per ray hit: `rbin` (reinhart.cal, MF 1)
//! and `kbin` (klems_full.cal) with host-bound `Dx Dy Dz`, the way crates/contrib uses
//! the language. Run: `cargo run --profile testopt -p fenestra-calc --example eval_speed`.
//! The directions cover the sphere; half are ground for `rbin` (0, no angles computed)
//! and half lie behind the window for `kbin` (-1): the `sky` and `front` lines time
//! those expressions on the other half only.

use std::path::Path;
use std::time::Instant;

use fenestra_calc::Program;

fn dirs(n: usize) -> Vec<[f64; 3]> {
    // a deterministic spread of unit vectors (golden-angle spiral), shuffled by stride
    let mut v = Vec::with_capacity(n);
    for i in 0..n {
        let k = (i * 7919) % n;
        let z = 1.0 - 2.0 * (k as f64 + 0.5) / n as f64;
        let a = k as f64 * 2.399_963_229_728_653;
        let s = (1.0 - z * z).sqrt();
        v.push([s * a.cos(), s * a.sin(), z]);
    }
    v
}

fn bench(label: &str, setup: &str, file: &str, expr: &str, ds: &[[f64; 3]]) {
    // a second argument times only the line of that label (for profiling)
    if std::env::args().nth(2).is_some_and(|only| only != label) {
        return;
    }
    // FENESTRA_EVAL_LIB: another folder of .cal files (e.g. crates/calc/tests/previous)
    let lib = std::env::var_os("FENESTRA_EVAL_LIB")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../lib"));
    let mut p = Program::for_renderer();
    if !setup.is_empty() {
        p.load_str("-e", setup).expect("setup");
    }
    p.load_file(&lib.join(file)).expect("cal file");
    let vars = p.bind_vars(&["Dx", "Dy", "Dz"]);
    let id = p.add_expr("-b", expr).expect("expression");
    let c = p.compile().expect("compile");
    let mut st = c.state();
    let mut best = 0.0f64;
    let mut sum = 0.0;
    for _ in 0..5 {
        let t = Instant::now();
        for d in ds {
            st.set_all(&vars, d);
            sum += c.eval_expr(&mut st, id).expect("eval");
        }
        let rate = ds.len() as f64 / t.elapsed().as_secs_f64();
        best = best.max(rate);
    }
    println!(
        "{label:6} {:8.2} M evaluations/s (best of 5 x {} directions; checksum {sum})",
        best / 1e6,
        ds.len()
    );
}

/// For scale: `rbin` of reinhart.cal with MF 1 written directly in Rust (the same
/// operations: asin, atan2, floors, divisions), timed like the evaluator.
fn native_rbin(ds: &[[f64; 3]]) {
    if std::env::args().nth(2).is_some_and(|only| only != "rbin*") {
        return;
    }
    const TNAZ: [f64; 8] = [30.0, 30.0, 24.0, 24.0, 18.0, 12.0, 6.0, 1.0];
    const TSUM: [f64; 8] = [0.0, 30.0, 60.0, 84.0, 108.0, 126.0, 138.0, 144.0];
    let deg = 180.0 / std::f64::consts::PI;
    let alpha = 90.0 / (7.0 + 0.5);
    let rbin = |d: &[f64; 3]| -> f64 {
        let z = d[2].clamp(-1.0, 1.0);
        let alt = deg * z.asin();
        if -alt > 0.0 {
            return 0.0;
        }
        let a0 = deg * d[0].atan2(d[1]);
        let azi = if a0 > 0.0 { a0 } else { a0 + 360.0 };
        let row = (alt / alpha).floor();
        let r = row as usize;
        let naz = if row - 6.5 > 0.0 { 1.0 } else { TNAZ[r.min(7)] };
        let inc = 360.0 / naz;
        let col = if 359.9999 - 0.5 * inc - azi > 0.0 {
            ((azi + 0.5 * inc) / inc).floor()
        } else {
            0.0
        };
        TSUM[r.min(7)] + col + 1.0
    };
    let mut best = 0.0f64;
    let mut sum = 0.0;
    for _ in 0..5 {
        let t = Instant::now();
        for d in ds {
            sum += rbin(std::hint::black_box(d));
        }
        best = best.max(ds.len() as f64 / t.elapsed().as_secs_f64());
    }
    println!(
        "{:6} {:8.2} M evaluations/s (plain Rust for scale; checksum {sum})",
        "rbin*",
        best / 1e6
    );
}

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(2_000_000);
    let ds = dirs(n);
    bench("rbin", "MF:1", "reinhart.cal", "rbin", &ds);
    bench("kbin", "", "klems_full.cal", "kbin(0,1,0,0,0,1)", &ds);
    bench("kbinS", "", "klems_full.cal", "kbinS", &ds);
    native_rbin(&ds);
    // the same number of directions, each on the side that is binned by angle
    let sky: Vec<[f64; 3]> = ds.iter().map(|d| [d[0], d[1], d[2].abs()]).collect();
    let front: Vec<[f64; 3]> = ds.iter().map(|d| [d[0], -d[1].abs(), d[2]]).collect();
    bench("sky", "MF:1", "reinhart.cal", "rbin", &sky);
    bench("front", "", "klems_full.cal", "kbin(0,1,0,0,0,1)", &front);
    native_rbin(&sky);
}
