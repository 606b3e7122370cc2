//! Prints in-process evaluation speed (evaluations per second, one thread) of the bin
//! expressions a contribution run evaluates per ray hit: `rbin` (reinhart.cal, MF 1)
//! and `kbin` (klems_full.cal) with host-bound `Dx Dy Dz`, the way crates/contrib uses
//! the language. Run: `cargo run --profile testopt -p fenestra-calc --example eval_speed`.

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
    let lib = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../lib");
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

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(2_000_000);
    let ds = dirs(n);
    bench("rbin", "MF:1", "reinhart.cal", "rbin", &ds);
    bench("kbin", "", "klems_full.cal", "kbin(0,1,0,0,0,1)", &ds);
    bench("kbinS", "", "klems_full.cal", "kbinS", &ds);
}
