//! lib/klems_{full,half,quarter,int}.cal and lib/reinhart.cal against their previous
//! versions (tests/previous/): the rewritten files compute the bins with fewer
//! operations (cosine thresholds instead of `acos`, the ground before `asin`, row
//! constants from a `select`), and must give the same bin for every direction —
//! exactly, ring, row and azimuth boundaries included — with the fast code and with
//! the exact evaluator.

// the thresholds are the files' literals (one of them is 1/sqrt(2) to the last bit)
#![allow(clippy::approx_constant)]

use std::path::{Path, PathBuf};

use fenestra_calc::Program;

fn lib(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../lib")
        .join(name)
}

fn previous(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/previous")
        .join(name)
}

/// The bins of `expr` (after `pre`, then `file`) for every direction.
fn bins(pre: &str, file: &Path, expr: &str, ds: &[[f64; 3]], exact: bool) -> Vec<f64> {
    // the variable is read when compiling (the only test in this file: no other
    // thread reads it meanwhile)
    if exact {
        std::env::set_var("FENESTRA_CALC_EXACT", "1");
    }
    let mut p = Program::for_renderer();
    if !pre.is_empty() {
        p.load_str("-e", pre).unwrap();
    }
    p.load_file(file).unwrap();
    let vars = p.bind_vars(&["Dx", "Dy", "Dz"]);
    let id = p.add_expr("-b", expr).unwrap();
    let c = p.compile().unwrap();
    std::env::remove_var("FENESTRA_CALC_EXACT");
    let mut st = c.state();
    let out = ds
        .iter()
        .map(|d| {
            st.set_all(&vars, d);
            c.eval_expr(&mut st, id)
                .unwrap_or_else(|e| panic!("{expr} at {d:?}: {e}"))
        })
        .collect();
    // the "fast" pass must really run fast code (no quiet fall-back to the exact one)
    assert_eq!(
        c.has_fast_code(id),
        !exact,
        "{expr} ({}): fast code",
        file.display()
    );
    out
}

fn next_up(x: f64, k: i64) -> f64 {
    // k steps through the doubles (k < 0: downwards); no zero crossing needed here
    let b = x.to_bits() as i64;
    f64::from_bits(if x > 0.0 { b + k } else { b - k } as u64)
}

/// Directions (and how many of them come before the thresholds and special values): a
/// 1-degree grid in three orientations, random unit vectors, directions
/// exactly on (and 1-3 doubles beside) every cosine threshold of the files along each
/// axis, and special components (signed zeros, 1 + ulp, tiny values, non-unit).
fn directions() -> (Vec<[f64; 3]>, usize) {
    let mut ds = Vec::new();
    let deg = std::f64::consts::PI / 180.0;
    for i in 0..=180 {
        for j in 0..360 {
            let (th, ph) = (i as f64 * deg, j as f64 * deg);
            let (s, c) = (th.sin(), th.cos());
            ds.push([s * ph.cos(), s * ph.sin(), c]);
            ds.push([s * ph.sin(), c, s * ph.cos()]);
            ds.push([c, s * ph.sin(), s * ph.cos()]);
        }
    }
    let mut g = 12345u64;
    let mut r = move || {
        g = g
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((g >> 11) as f64) / ((1u64 << 53) as f64) * 2.0 - 1.0
    };
    while ds.len() < 250_000 {
        let d = [r(), r(), r()];
        let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        if n > 1e-3 && n <= 1.0 {
            ds.push([d[0] / n, d[1] / n, d[2] / n]);
        }
    }
    let dense = ds.len();
    let thresholds = [
        0.9961946980917455,
        0.9659258262890683,
        0.90630778703665,
        0.8191520442889918,
        0.7071067811865476,
        0.5735764363510462,
        0.4226182617406994,
        0.2588190451025207,
        -4.9789962505148006e-17,
        0.9935718556765876,
        0.9426414910921784,
        0.8433914458128857,
        0.7009092642998509,
        0.5224985647159489,
        0.31730465640509203,
        0.9876883405951378,
        0.8910065241883679,
        0.45399049973954675,
    ];
    for &t in &thresholds {
        for k in -3..=3 {
            let c = next_up(t, k);
            let s = (1.0 - c * c).sqrt();
            for sc in [c, -c] {
                for (a, b) in [(s, 0.0), (0.0, s), (s * 0.6, s * 0.8), (-s * 0.8, s * 0.6)] {
                    ds.push([a, b, sc]);
                    ds.push([sc, a, b]);
                    ds.push([b, sc, a]);
                }
            }
        }
    }
    let special = [
        0.0,
        -0.0,
        1.0,
        -1.0,
        1.0000000000000002,
        -1.0000000000000002,
        1e-17,
        -1e-17,
        5e-324,
        -5e-324,
        6.123233995736766e-17,
        -6.123233995736766e-17,
        0.5,
        -0.7071067811865476,
    ];
    for &x in &special {
        for &y in &special {
            for &z in &special {
                ds.push([x, y, z]);
            }
        }
    }
    (ds, dense)
}

#[test]
fn rewritten_bin_files_give_the_previous_bins() {
    let (all, dense) = directions();
    // the exact evaluator (slower) on every fourth grid or random direction
    let sparse: Vec<[f64; 3]> = all[..dense]
        .iter()
        .step_by(4)
        .chain(&all[dense..])
        .copied()
        .collect();
    let frames = [
        "0,0,1, 0,1,0",
        "0,0,-1, 0,1,0",
        "0,1,0, 0,0,1",
        "-1,0,0, 0,0,1",
        "0.6,0,0.8, 0.1,1,0.3",
        "0.48,0.6,0.64, 0,0,1",
    ];
    let mut cases: Vec<(String, &str, String)> = Vec::new();
    for (file, f) in [
        ("klems_full.cal", "kbin"),
        ("klems_half.cal", "khbin"),
        ("klems_quarter.cal", "kqbin"),
    ] {
        for fr in frames {
            cases.push((String::new(), file, format!("{f}({fr})")));
        }
        cases.push(("RHS=-1".into(), file, format!("{f}(0,0,1, 0,1,0)")));
    }
    for e in ["kbinN", "kbinE", "kbinS", "kbinW", "kbinD"] {
        cases.push((String::new(), "klems_full.cal", e.into()));
    }
    // klems_int.cal is klems_full.cal under another name (the previous one was the same)
    for e in ["kbinS", "kbin(0.6,0,0.8, 0.1,1,0.3)"] {
        cases.push((String::new(), "klems_int.cal", e.into()));
    }
    // MF 5 and 6 have rows beyond the file's select (computed by the general formula)
    for mf in 1..=6 {
        cases.push((format!("MF:{mf}"), "reinhart.cal", "rbin".into()));
    }
    for (pre, file, expr) in &cases {
        for (exact, ds) in [(false, &all), (true, &sparse)] {
            let before = if *file == "klems_int.cal" {
                "klems_full.cal"
            } else {
                file
            };
            let want = bins(pre, &previous(before), expr, ds, false);
            let got = bins(pre, &lib(file), expr, ds, exact);
            for (i, (w, g)) in want.iter().zip(&got).enumerate() {
                assert!(
                    w == g || (w.is_nan() && g.is_nan()),
                    "{file} {pre} {expr} (exact evaluator: {exact}) at {:?}: previous {w}, now {g}",
                    ds[i]
                );
            }
        }
    }
}
