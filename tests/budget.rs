//! rtcontrib -v: the run's budget (effects, rays by kind, each modifier's total with its
//! standard error), and that standard error checked against the spread of independent runs.

mod common;

/// D of the bundled office's south window at `-c 20` with `seed`; stderr of the run.
fn d_run(dir: &std::path::Path, seed: u64, extra: &[&str]) -> String {
    let ex =
        std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("examples/three-phase/scene");
    let s = seed.to_string();
    let mut g = common::fenestra("genklemsamp");
    g.args([
        "-ff", "-c", "20", "-s", &s, "-vd", "0", "-1", "0", "-vu", "0", "0", "1",
    ])
    .arg(ex.join("window_out.rad"));
    let rays = common::run_ok(&mut g);
    let mut d = common::fenestra("rtcontrib");
    d.args([
        "-v", "-fo", "-c", "20", "-ffa", "-ab", "1", "-ad", "64", "-lw", "1e-3", "-seed", &s,
    ])
    .args(extra)
    .args([
        "-o",
        "D.dmx",
        "-e",
        "MF:1",
        "-f",
        "reinhart.cal",
        "-b",
        "rbin",
        "-bn",
        "Nrbins",
        "-m",
        "skyglow",
    ])
    .args(["materials.rad", "room.rad", "exterior.rad", "sky_dmx.rad"].map(|f| ex.join(f)))
    .current_dir(dir);
    let out = common::run_stdin_ok(d, &rays);
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// (total, relative standard error %) from the modifier line of `-v`.
fn total_line(err: &str) -> (f64, Option<f64>) {
    let l = err
        .lines()
        .find(|l| l.contains("modifier skyglow: total of every value"))
        .unwrap_or_else(|| panic!("{err}"));
    let w: Vec<&str> = l.split_whitespace().collect();
    let k = w.iter().position(|x| *x == "value").unwrap();
    let total = w[k + 1].parse().unwrap();
    let se = l
        .split("standard error ")
        .nth(1)
        .and_then(|r| r.split('%').next())
        .and_then(|x| x.trim().parse().ok());
    (total, se)
}

#[test]
fn budget_lines_and_the_total_s_error_against_independent_runs() {
    let dir = common::scratch("budget");
    let err = d_run(&dir, 1, &[]);
    assert!(err.contains("effect: ambient: on (-ab 1)"), "{err}");
    assert!(
        err.contains("145 records in") && err.contains("2900 primary"),
        "{err}"
    );
    // Linux says how much memory the run held at most
    if cfg!(target_os = "linux") {
        assert!(err.contains("peak resident memory"), "{err}");
    }
    assert!(
        err.contains("standard error not computed (give -E)"),
        "{err}"
    );
    // 30 seeds with -E: the spread of the total against the predicted standard error. The
    // observed sd of 30 runs is uncertain by 1/√58 = 13%; the prediction (2 900 rays' own
    // totals per run) by about 3%: ±35% is 2.6 of their combined 13.5%.
    let runs: Vec<(f64, f64)> = (0..30)
        .map(|s| {
            let (t, se) = total_line(&d_run(&dir, 100 + s, &["-E"]));
            (t, t * se.expect("a standard error with -E") / 100.0)
        })
        .collect();
    let n = runs.len() as f64;
    let mean = runs.iter().map(|r| r.0).sum::<f64>() / n;
    let sd = (runs.iter().map(|r| (r.0 - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    let pred = (runs.iter().map(|r| r.1 * r.1).sum::<f64>() / n).sqrt();
    eprintln!(
        "total {mean:.4}: observed sd {sd:.5}, predicted {pred:.5}, ratio {:.3}",
        pred / sd
    );
    assert!(
        (pred / sd - 1.0).abs() <= 0.35,
        "predicted {pred} observed {sd}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn genbsdf_and_mkillum_print_their_budget_with_v() {
    let dir = common::scratch("budget-tools");
    let mgf = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("examples/genbsdf/blinds_curved20.mgf");
    let mut g = common::fenestra("genBSDF");
    g.args(["-v", "-q", "-c", "4", "+mgf"])
        .arg(&mgf)
        .current_dir(&dir);
    let out = common::output_ok(&mut g);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("genBSDF: effect: ambient") && err.contains("145 incident directions x "),
        "{err}"
    );
    assert!(
        err.contains("primary,") && err.contains("indirect"),
        "{err}"
    );
    // mkillum: one window under a glowing sky, -ab 0 (each ray sees the glow)
    std::fs::write(
        dir.join("sky.rad"),
        "void glow skyglow 0 0 4 2 2.5 3 0\nskyglow source sky 0 0 4 0 0 1 180\n",
    )
    .unwrap();
    let oct = common::run_ok(common::fenestra("oconv").arg("sky.rad").current_dir(&dir));
    std::fs::write(dir.join("s.oct"), oct).unwrap();
    let mut m = common::fenestra("mkillum");
    m.args(["-v", "-ab", "0", "s.oct"]).current_dir(&dir);
    let out = common::run_stdin_ok(
        m,
        b"#@mkillum d=4 s=8\nvoid polygon win 0 0 12 0 0 1  0 1 1  1 1 1  1 0 1\n",
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("1 surfaces in") && err.contains("rays traced"),
        "{err}"
    );
    assert!(err.contains("surface win: mean radiance"), "{err}");
    if cfg!(target_os = "linux") {
        assert!(err.contains("peak resident memory"), "{err}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
