//! dctimestep -Ev/-Ed/-Eo: standard errors carried from rtcontrib's -E files to every
//! result value, checked against the spread of repeated runs of the whole pipeline with
//! independent seeds on the reference office; format and shape checks.

mod common;

use std::path::Path;

fn fx(rel: &str) -> String {
    common::fixture(rel).display().to_string()
}

/// The Y (lux) of a dctimestep result (or error) file: one value per sensor.
fn lux_rows(path: &Path) -> Vec<f64> {
    let t = std::fs::read(path).unwrap();
    let k = t.windows(2).position(|w| w == b"\n\n").unwrap();
    common::numbers(&t[k + 2..])
        .chunks(3)
        .map(|c| 179.0 * (0.265 * c[0] + 0.670 * c[1] + 0.065 * c[2]))
        .collect()
}

/// One run of the pipeline with `seed`: V and D with -E (and with `replicas` > 0, `-Er`
/// replicas), then dctimestep with -Eo from the standard errors (`-Ev -Ed`) or from the
/// replicas (`-Rv -Rd`).
fn pipeline(dir: &Path, seed: u64, replicas: usize) -> (Vec<f64>, Vec<f64>) {
    let k = replicas.to_string();
    let er: &[&str] = if replicas > 0 { &["-Er", &k] } else { &[] };
    let b = common::fixture("rtrace_threephase_bsdf");
    let room = [
        b.join("materials.rad").display().to_string(),
        b.join("room.rad").display().to_string(),
    ];
    let s = seed.to_string();
    // V: 45 sensors, Klems bins of the south window
    let mut v = common::fenestra("rtcontrib");
    v.args([
        "-I+", "-ab", "2", "-ad", "256", "-lw", "1e-3", "-seed", &s, "-E",
    ])
    .args(er)
    .args([
        "-Eo",
        "V.err",
        "-o",
        "V.vmx",
        "-f",
        "klems_full.cal",
        "-bn",
        "Nkbins",
        "-b",
        "kbinS",
        "-m",
        "SouthGroup",
    ])
    .arg(fx("rcontrib/window_vmx.rad"))
    .args(&room)
    .current_dir(dir);
    common::run_stdin_ok(v, &std::fs::read(b.join("sensors.pts")).unwrap());
    // D: genklemsamp | rtcontrib, 40 rays per Klems patch
    let mut g = common::fenestra("genklemsamp");
    g.args([
        "-ff", "-c", "40", "-s", &s, "-vd", "0", "-1", "0", "-vu", "0", "0", "1",
    ])
    .arg(fx("rcontrib/window_out.rad"));
    let rays = common::run_ok(&mut g);
    let mut d = common::fenestra("rtcontrib");
    d.args([
        "-c", "40", "-ffa", "-ab", "1", "-ad", "64", "-lw", "1e-3", "-seed", &s, "-E",
    ])
    .args(er)
    .args([
        "-Eo",
        "D.err",
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
    .args(&room)
    .arg(b.join("exterior.rad"))
    .arg(fx("rcontrib/sky_dmx.rad"))
    .current_dir(dir);
    common::run_stdin_ok(d, &rays);
    let inputs = if replicas > 0 {
        ["-Rv", "V.rep", "-Rd", "D.rep"]
    } else {
        ["-Ev", "V.err", "-Ed", "D.err"]
    };
    let mut dc = common::fenestra("dctimestep");
    dc.args(inputs)
        .args(["-Eo", "res.err", "-o", "res.dat", "V.vmx"])
        .arg(fx("threephase/blinds_kf.xml"))
        .args(["D.dmx"])
        .arg(fx("threephase/sky_t4_sep21_1200_overcast.skv"))
        .current_dir(dir);
    common::run_ok(&mut dc);
    if std::env::var_os("FENESTRA_DEBUG_ERR").is_some() {
        for (flag, f) in [("-Ev", "V.err"), ("-Ed", "D.err")] {
            let mut dc = common::fenestra("dctimestep");
            dc.args([flag, f, "-Eo", "part.err", "-o", "x.dat", "V.vmx"])
                .arg(fx("threephase/blinds_kf.xml"))
                .args(["D.dmx"])
                .arg(fx("threephase/sky_t4_sep21_1200_overcast.skv"))
                .current_dir(dir);
            common::run_ok(&mut dc);
            let e = lux_rows(&dir.join("part.err"));
            eprintln!(
                "{flag} only: sensor 0 {:.2}, 20 {:.2}, 40 {:.2}",
                e[0], e[20], e[40]
            );
        }
    }
    for f in ["V.vmx", "V.err", "D.dmx", "D.err", "V.rep", "D.rep"] {
        let _ = std::fs::remove_file(dir.join(f));
    }
    (
        lux_rows(&dir.join("res.dat")),
        lux_rows(&dir.join("res.err")),
    )
}

/// Per sensor, the predicted standard error (root mean square over `runs` seeds of the
/// pipeline) against the observed standard deviation of the results: sorted ratios.
fn predicted_over_observed(name: &str, runs: u64, replicas: usize) -> Vec<f64> {
    let dir = common::scratch(name);
    let mut results: Vec<Vec<f64>> = Vec::new();
    let mut predicted: Vec<Vec<f64>> = Vec::new();
    for seed in 0..runs {
        let (r, e) = pipeline(&dir, 1000 + seed, replicas);
        results.push(r);
        predicted.push(e);
    }
    let n = results[0].len();
    assert_eq!(n, 45);
    let nr = runs as f64;
    let mut ratios = Vec::new();
    for k in 0..n {
        let xs: Vec<f64> = results.iter().map(|r| r[k]).collect();
        let m = xs.iter().sum::<f64>() / nr;
        let sd = (xs.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (nr - 1.0)).sqrt();
        let pred = (predicted.iter().map(|p| p[k] * p[k]).sum::<f64>() / nr).sqrt();
        ratios.push(pred / sd);
    }
    ratios.sort_by(f64::total_cmp);
    let within = |tol: f64| ratios.iter().filter(|r| (**r - 1.0).abs() <= tol).count();
    eprintln!(
        "{name}: predicted / observed sd over {runs} runs, 45 sensors: min {:.3} 10% {:.3} median {:.3} 90% {:.3} max {:.3}; within ±10%: {}, ±20%: {}, ±25%: {}",
        ratios[0],
        ratios[n / 10],
        ratios[n / 2],
        ratios[9 * n / 10],
        ratios[n - 1],
        within(0.1),
        within(0.2),
        within(0.25)
    );
    let _ = std::fs::remove_dir_all(&dir);
    ratios
}

#[test]
fn independent_element_errors_bound_the_spread_of_independent_runs() {
    // 40 seeds of the whole pipeline (V -ab 2 -ad 256, D -c 40 -ab 1 -ad 64, the blind's T,
    // the overcast sky). The model takes V's and D's elements as independent; they are not
    // (one record's bins share its rays, with negative covariances), so it over-states the
    // error: measured ratios min 0.91, median 1.96, max 3.09 (V's term dominates). What is
    // checked is what the model promises, a bound: the ratio at or above 0.8 for at least
    // 90% of sensors (the sample sd of 40 runs is uncertain by about 11%), and not looser
    // than 3.5 at the median.
    let ratios = predicted_over_observed("dc-errors", 40, 0);
    let n = ratios.len();
    let bounded = ratios.iter().filter(|r| **r >= 0.8).count();
    assert!(
        bounded * 10 >= n * 9,
        "only {bounded} of {n} sensors bounded"
    );
    assert!(ratios[n / 2] <= 3.5, "median ratio {}", ratios[n / 2]);
}

#[test]
fn replica_errors_match_the_spread_of_independent_runs() {
    // The same pipeline with 8 replicas per record (V: 8 traces per sensor; D: the 40 rays
    // of a patch in 8 groups), the result's errors from the replicas (every covariance
    // carried). Over RUNS seeds, the criterion: predicted / observed within ±20%
    // for at least 90% of sensors. Why that tolerance holds for a correct model: the
    // observed sd of RUNS runs is uncertain by 1/√(2(RUNS−1)) (7.1% at 100 runs), the
    // predicted rms over RUNS runs of 7 degrees of freedom by 1/√(2·7·RUNS) (2.7%): ±20%
    // is 2.6 of their combined 7.6%, so a sensor falls outside with probability ~1%.
    const RUNS: u64 = 100;
    let ratios = predicted_over_observed("dc-errors-replicas", RUNS, 8);
    let n = ratios.len();
    let within = ratios.iter().filter(|r| (**r - 1.0).abs() <= 0.2).count();
    assert!(
        within * 10 >= n * 9,
        "only {within} of {n} sensors within ±20%: {ratios:?}"
    );
    // and no systematic bias: the median within ±10%
    assert!(
        (ratios[n / 2] - 1.0).abs() <= 0.1,
        "median ratio {}",
        ratios[n / 2]
    );
}

#[test]
fn error_files_have_the_result_s_shape_and_bad_shapes_are_refused() {
    let dir = common::scratch("dc-errors-shape");
    let (r, e) = pipeline(&dir, 7, 0);
    assert_eq!(r.len(), e.len());
    assert!(e.iter().all(|v| *v > 0.0 && v.is_finite()));
    let head = std::fs::read_to_string(dir.join("res.err")).unwrap();
    common::cli::assert_contains(
        &head,
        &[
            "CONTENTS= Monte Carlo standard error",
            "NROWS=45",
            "NCOLS=1",
        ],
    );
    // an error file of another shape than its matrix: refused, naming what differs
    let t = std::fs::read_to_string(dir.join("res.err")).unwrap();
    std::fs::write(dir.join("bad.err"), t).unwrap();
    let mut dc = common::fenestra("dctimestep");
    dc.args(["-Ev", "bad.err", "-Eo", "x.err", "res.dat"])
        .arg(fx("threephase/sky_t4_sep21_1200_overcast.skv"))
        .current_dir(&dir);
    let out = dc.output().unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("standard errors are") || err.contains("columns"),
        "{err}"
    );
    // -Ev without -Eo, and -Eo without inputs
    for args in [
        &["-Ev", "bad.err", "res.dat"][..],
        &["-Eo", "x.err", "res.dat"],
    ] {
        let mut dc = common::fenestra("dctimestep");
        dc.args(args)
            .arg(fx("threephase/sky_t4_sep21_1200_overcast.skv"))
            .current_dir(&dir);
        assert!(!dc.output().unwrap().status.success(), "{args:?}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// rtcontrib's V command of the pipeline, cheaper, with extra options.
fn v_command(dir: &Path, extra: &[&str]) -> std::process::Output {
    let b = common::fixture("rtrace_threephase_bsdf");
    let mut v = common::fenestra("rtcontrib");
    v.args(["-I+", "-ab", "1", "-ad", "16", "-lw", "1e-2"])
        .args(extra)
        .args([
            "-f",
            "klems_full.cal",
            "-bn",
            "Nkbins",
            "-b",
            "kbinS",
            "-m",
            "SouthGroup",
        ])
        .arg(fx("rcontrib/window_vmx.rad"))
        .arg(b.join("materials.rad"))
        .arg(b.join("room.rad"))
        .current_dir(dir);
    common::run_stdin(v, &std::fs::read(b.join("sensors.pts")).unwrap())
}

#[test]
fn replica_files_hold_k_rows_per_record_whose_mean_is_the_value() {
    let dir = common::scratch("dc-replica-files");
    common::assert_ok(&v_command(&dir, &["-E", "-Er", "4", "-o", "V.vmx"]));
    let head = std::fs::read_to_string(dir.join("V.vmx.rep")).unwrap();
    assert!(head.contains("NREPLICAS=4\n") && head.contains("CONTENTS= 4 independent replica"));
    let body = |f: &str| {
        let t = std::fs::read(dir.join(f)).unwrap();
        let k = t.windows(2).position(|w| w == b"\n\n").unwrap();
        common::numbers(&t[k + 2..])
    };
    let (v, rep) = (body("V.vmx"), body("V.vmx.rep"));
    let row = 145 * 3;
    assert_eq!(v.len(), 45 * row);
    assert_eq!(rep.len(), 4 * v.len());
    let mut spread = 0.0f64;
    for r in 0..45 {
        for j in 0..row {
            let reps: Vec<f64> = (0..4).map(|q| rep[(r * 4 + q) * row + j]).collect();
            let mean = reps.iter().sum::<f64>() / 4.0;
            // printed with 7 digits: the mean of the printed replicas within their rounding
            assert!((mean - v[r * row + j]).abs() <= 1e-6 * v[r * row + j].abs() + 1e-12);
            spread = spread.max(reps.iter().fold(0.0, |m, x| m.max((x - mean).abs())));
        }
    }
    assert!(
        spread > 0.0,
        "the replicas are independent estimates, not copies"
    );
    // rtcontrib refuses what has no replicas
    for (extra, want) in [
        (&["-Er", "4", "-o", "a.vmx"][..], "give -E too"),
        (&["-E", "-Er", "4", "-c", "0", "-o", "b.vmx"], "-c 0"),
        (
            &["-E", "-Er", "4", "-c", "2", "-o", "c.vmx"],
            "at least one",
        ),
        (&["-E", "-Er", "1", "-o", "d.vmx"], "from 2 to 4096"),
        (&["-E", "-Er", "4"], "-Eo"),
    ] {
        common::cli::assert_refused(&v_command(&dir, extra), want, extra);
    }
    // dctimestep: replicas and standard errors of the same matrix; a file without NREPLICAS
    let sky = fx("threephase/sky_t4_sep21_1200_overcast.skv");
    let xml = fx("threephase/blinds_kf.xml");
    let d = fx("threephase/D.dmx");
    for (args, want) in [
        (&["-Ev", "V.vmx.err", "-Rv", "V.vmx.rep"][..], "give one"),
        (&["-Rv", "V.vmx.err"], "NREPLICAS"),
        (&["-Rv", "V.vmx.rep"], "-Eo"),
    ] {
        let mut dc = common::fenestra("dctimestep");
        dc.args(args)
            .args(["-Eo", "x.err"].iter().filter(|_| want != "-Eo"))
            .args(["V.vmx", &xml, &d, &sky])
            .current_dir(&dir);
        common::cli::assert_refused(&dc.output().unwrap(), want, args);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn rmtxop_carries_replicas_as_dctimestep_does() {
    // the same V·T·D·s with replicas of V and D: rmtxop -E (every operation applied to the
    // replica deviations) and dctimestep -Rv -Rd -Eo must give the same standard errors
    // (rmtxop holds values in single precision: 1e-4 relative) and the same result
    let dir = common::scratch("rmtxop-errors");
    let b = common::fixture("rtrace_threephase_bsdf");
    common::assert_ok(&v_command(&dir, &["-E", "-Er", "4", "-o", "V.vmx"]));
    // D: 8 rays per Klems patch in 4 groups
    let mut g = common::fenestra("genklemsamp");
    g.args([
        "-ff", "-c", "8", "-vd", "0", "-1", "0", "-vu", "0", "0", "1",
    ])
    .arg(fx("rcontrib/window_out.rad"));
    let rays = common::run_ok(&mut g);
    let mut d = common::fenestra("rtcontrib");
    d.args([
        "-c", "8", "-ffa", "-ab", "1", "-ad", "16", "-lw", "1e-2", "-E", "-Er", "4", "-o", "D.dmx",
    ])
    .args([
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
    .arg(b.join("materials.rad"))
    .arg(b.join("room.rad"))
    .arg(b.join("exterior.rad"))
    .arg(fx("rcontrib/sky_dmx.rad"))
    .current_dir(&dir);
    common::run_stdin_ok(d, &rays);
    let sky = fx("threephase/sky_t4_sep21_1200_overcast.skv");
    let xml = fx("threephase/blinds_kf.xml");
    let mut dc = common::fenestra("dctimestep");
    dc.args([
        "-Rv",
        "V.vmx.rep",
        "-Rd",
        "D.dmx.rep",
        "-Eo",
        "dc.err",
        "-o",
        "dc.dat",
        "V.vmx",
        &xml,
        "D.dmx",
        &sky,
    ])
    .current_dir(&dir);
    common::run_ok(&mut dc);
    let mut rm = common::fenestra("rmtxop");
    rm.args([
        "-fa",
        "-E",
        "rm.err",
        "-R",
        "V.vmx.rep",
        "V.vmx",
        &xml,
        "-R",
        "D.dmx.rep",
        "D.dmx",
        &sky,
    ])
    .current_dir(&dir);
    let res = common::run_ok(&mut rm);
    std::fs::write(dir.join("rm.dat"), res).unwrap();
    let body = |f: &str| {
        let t = std::fs::read(dir.join(f)).unwrap();
        let k = t.windows(2).position(|w| w == b"\n\n").unwrap();
        common::numbers(&t[k + 2..])
    };
    for (a, b) in [("dc.err", "rm.err"), ("dc.dat", "rm.dat")] {
        let (x, y) = (body(a), body(b));
        assert_eq!(x.len(), y.len(), "{a} {b}");
        assert_eq!(x.len(), 45 * 3);
        for (p, q) in x.iter().zip(&y) {
            assert!(
                (p - q).abs() <= 1e-4 * p.abs().max(q.abs()) + 1e-9,
                "{a}: {p} vs {b}: {q}"
            );
        }
    }
    let head = std::fs::read_to_string(dir.join("rm.err")).unwrap();
    assert!(
        head.contains("CONTENTS= Monte Carlo standard error"),
        "{head}"
    );
    // -E without -R (and -R without -E) refused; replicas of another shape refused
    for args in [
        &["-E", "x.err", "V.vmx"][..],
        &["-R", "V.vmx.rep", "V.vmx"],
        &["-E", "x.err", "-R", "D.dmx.rep", "V.vmx"],
    ] {
        let mut rm = common::fenestra("rmtxop");
        rm.args(args).current_dir(&dir);
        assert!(!rm.output().unwrap().status.success(), "{args:?}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
