//! genklemsamp from the command line: counts and formats, every direction in its Klems
//! patch (binned by our rcalc with lib/klems_full.cal, and by the oracle's rcalc with its
//! own klems_full.cal), origins on the window, reproducibility, errors; and the D matrix
//! of the reference office from our rays agreeing with the reference D within Monte Carlo
//! error (the PyPI oracle has no genklemsamp to compare with directly).

mod common;

use std::path::PathBuf;
use std::process::Command;

fn window() -> PathBuf {
    common::fixture("genklemsamp/window_out.rad")
}

fn gks(args: &[&str]) -> Vec<u8> {
    common::run_ok(common::fenestra("genklemsamp").args(args))
}

fn window_rays(n: usize, fmt: &str) -> Vec<u8> {
    let w = window();
    gks(&[
        fmt,
        "-c",
        &n.to_string(),
        "-vd",
        "0",
        "-1",
        "0",
        "-vu",
        "0",
        "0",
        "1",
        w.to_str().unwrap(),
    ])
}

fn rows(text: &[u8]) -> Vec<Vec<f64>> {
    String::from_utf8_lossy(text)
        .lines()
        .map(|l| l.split('\t').map(|w| w.parse().unwrap()).collect())
        .collect()
}

#[test]
fn counts_and_formats() {
    let a = window_rays(3, "-fa");
    let r = rows(&a);
    assert_eq!(r.len(), 435);
    assert!(r.iter().all(|x| x.len() == 6));
    let f = window_rays(3, "-ff");
    assert_eq!(f.len(), 435 * 6 * 4);
    let d = window_rays(3, "-fd");
    assert_eq!(d.len(), 20880);
    // the three formats carry the same rays
    for (i, row) in r.iter().enumerate() {
        for k in 0..6 {
            let dv =
                f64::from_ne_bytes(d[(i * 6 + k) * 8..(i * 6 + k + 1) * 8].try_into().unwrap());
            let fv =
                f32::from_ne_bytes(f[(i * 6 + k) * 4..(i * 6 + k + 1) * 4].try_into().unwrap());
            assert!(
                (dv - row[k]).abs() <= 1e-8 * dv.abs().max(1e-5),
                "{dv} {}",
                row[k]
            );
            assert!((fv as f64 - dv).abs() <= 1e-6 * dv.abs().max(1e-5));
        }
    }
    // no geometry: the -vh x -vv rectangle centred on -vp
    let r = rows(&gks(&[
        "-c", "4", "-vd", "0", "-1", "0", "-vu", "0", "0", "1", "-vp", "0", "0", "0", "-vh", "2",
        "-vv", "1",
    ]));
    assert_eq!(r.len(), 580);
    for x in &r {
        assert!(
            x[0].abs() <= 1.0 && x[2].abs() <= 0.5 && (x[1] + 1e-5).abs() < 1e-12,
            "{x:?}"
        );
    }
}

#[test]
fn origins_uniform_on_the_window_and_offset_outwards() {
    let r = rows(&window_rays(40, "-fa"));
    let (mut sx, mut sz) = (0.0, 0.0);
    for x in &r {
        // window: x 1..3, z 0.9..2.4 in the plane y = 0; -vo 1e-5 along vd = -y
        assert!(
            (1.0..=3.0).contains(&x[0]) && (0.9..=2.4).contains(&x[2]),
            "{x:?}"
        );
        assert!((x[1] + 1e-5).abs() < 1e-12, "{x:?}");
        let len = (x[3] * x[3] + x[4] * x[4] + x[5] * x[5]).sqrt();
        assert!((len - 1.0).abs() < 1e-8);
        assert!(x[4] < 0.0, "rays travel out of the window (-y): {x:?}");
        sx += x[0];
        sz += x[2];
    }
    let n = r.len() as f64;
    // uniform over the rectangle: means 2 and 1.65 (sd of the mean 0.577/sqrt(5800) and 0.433/sqrt(5800))
    assert!((sx / n - 2.0).abs() < 0.04, "{}", sx / n);
    assert!((sz / n - 1.65).abs() < 0.03, "{}", sz / n);
    // -vo moves the origins
    let w = window();
    let r = rows(&gks(&[
        "-c",
        "2",
        "-vo",
        "0.01",
        "-vd",
        "0",
        "-1",
        "0",
        "-vu",
        "0",
        "0",
        "1",
        w.to_str().unwrap(),
    ]));
    assert!(r.iter().all(|x| (x[1] + 0.01).abs() < 1e-12));
}

/// The polar angle is uniform within each ring, as Radiance's genklemsamp samples it:
/// in the centre patch |theta| is uniform on [0, 5] degrees (mean 2.5; uniform in solid
/// angle would give 3.33), in ring 2 theta is uniform on [5, 15] (mean 10).
#[test]
fn theta_uniform_within_rings() {
    let n = 2000;
    let r = rows(&window_rays(n, "-fa"));
    let theta = |x: &Vec<f64>| (-x[4]).clamp(-1.0, 1.0).acos().to_degrees();
    let m0: f64 = r[..n].iter().map(theta).sum::<f64>() / n as f64;
    assert!((m0 - 2.5).abs() < 0.1, "centre patch mean theta {m0}");
    let m1: f64 = r[n..9 * n].iter().map(theta).sum::<f64>() / (8 * n) as f64;
    assert!((m1 - 10.0).abs() < 0.1, "ring 2 mean theta {m1}");
}

fn kbin_column(rcalc: Command, rays: &[u8]) -> Vec<i64> {
    let out = common::pipe_ok(rcalc, rays);
    String::from_utf8_lossy(&out)
        .lines()
        .map(|l| l.trim().parse().unwrap())
        .collect()
}

const KBIN_ARGS: [&str; 4] = [
    "-f",
    "klems_full.cal",
    "-e",
    // the window's Klems frame as rcontrib bins it: normal -vd = +y, up +z
    "Dx=$4;Dy=$5;Dz=$6;$1=kbin(0,1,0,0,0,1)",
];

/// Every ray's direction falls in its patch (lines are patch-major), as our rcalc bins it
/// with our lib/klems_full.cal.
#[test]
fn directions_in_their_patch() {
    let n = 20;
    let rays = window_rays(n, "-fa");
    let mut c = common::fenestra("rcalc");
    c.env("RAYPATH", ".").args(KBIN_ARGS);
    let bins = kbin_column(c, &rays);
    assert_eq!(bins.len(), 145 * n);
    for (i, b) in bins.iter().enumerate() {
        assert_eq!(*b, (i / n) as i64, "ray {i}");
    }
}

/// The same with the oracle's rcalc and its klems_full.cal (exact: no ray lies within
/// 1e-9 of a patch boundary with these seeds, so the last bits of acos cannot matter).
#[test]
fn oracle_directions_in_their_patch() {
    let Some(o) = common::oracle() else { return };
    let n = 20;
    let rays = window_rays(n, "-fa");
    let mut c = o.command("rcalc");
    c.args(KBIN_ARGS);
    let bins = kbin_column(c, &rays);
    assert_eq!(bins.len(), 145 * n);
    for (i, b) in bins.iter().enumerate() {
        assert_eq!(*b, (i / n) as i64, "ray {i}");
    }
}

#[test]
fn reproducible_and_seeded() {
    assert_eq!(window_rays(5, "-fd"), window_rays(5, "-fd"));
    let w = window();
    let s1 = gks(&[
        "-s",
        "1",
        "-c",
        "5",
        "-fd",
        "-vd",
        "0",
        "-1",
        "0",
        "-vu",
        "0",
        "0",
        "1",
        w.to_str().unwrap(),
    ]);
    assert_ne!(s1, window_rays(5, "-fd"));
    assert_eq!(s1.len(), 145 * 5 * 48);
}

#[test]
fn errors() {
    let w = window();
    // the window faces -y: looking along +x finds no aperture
    let out = common::fenestra("genklemsamp")
        .args([
            "-c",
            "2",
            "-vd",
            "1",
            "0",
            "0",
            "-vu",
            "0",
            "0",
            "1",
            w.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("does not correspond to any surfaces"));
    assert!(out.stdout.is_empty());
    for bad in [
        vec!["-c", "0"],
        vec!["-fx"],
        vec!["-vd", "0", "0", "1", "-vu", "0", "0", "1"],
        vec!["-q"],
    ] {
        let out = common::fenestra("genklemsamp").args(&bad).output().unwrap();
        assert!(!out.status.success(), "{bad:?} accepted");
        assert!(!out.stderr.is_empty());
    }
    let out = common::fenestra("genklemsamp")
        .args(["-c", "1", "/nonexistent/window.rad"])
        .output()
        .unwrap();
    assert!(!out.status.success());
}

/// Reads the RGB matrix body of an ascii rcontrib output; returns rows of red values.
fn red_rows(text: &[u8]) -> Vec<Vec<f64>> {
    let s = String::from_utf8_lossy(text);
    let body = s.split("\n\n").nth(1).expect("header then body");
    body.lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            l.split_whitespace()
                .step_by(3)
                .map(|w| w.parse().unwrap())
                .collect()
        })
        .collect()
}

/// Our rays through the oracle's rcontrib give the reference office's D (computed by the
/// oracle's rcontrib from Radiance's genklemsamp, -c 1000 -ab 2 -ad 1000) within Monte
/// Carlo error. Each D row sums the share of the patch's rays that reach the sky/ground
/// glow (value 1), so a row sum is a binomial proportion: with c rays here and 1000 in
/// the reference its standard error is sqrt(p(1-p)(1/c + 1/1000)) (floor 0.01 on
/// p(1-p) for the interreflected part); every row within 4.5 standard errors (145 rows),
/// and the grand total within 1%.
#[test]
fn oracle_d_matrix_from_our_rays() {
    let Some(o) = common::oracle() else { return };
    let dir = common::scratch("gks-d");
    for f in ["materials.rad", "room.rad", "exterior.rad", "sky_dmx.rad"] {
        std::fs::copy(common::fixture(&format!("genklemsamp/{f}")), dir.join(f)).unwrap();
    }
    let oct = common::run_ok(o.command("oconv").current_dir(&dir).args([
        "materials.rad",
        "room.rad",
        "exterior.rad",
        "sky_dmx.rad",
    ]));
    std::fs::write(dir.join("dmx.oct"), oct).unwrap();
    let c = 200;
    let rays = window_rays(c, "-ff");
    let mut rc = o.command("rcontrib");
    rc.current_dir(&dir).args([
        "-n",
        "2",
        "-c",
        "200",
        "-ffa",
        "-ab",
        "2",
        "-ad",
        "256",
        "-lw",
        "1e-3",
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
        "dmx.oct",
    ]);
    let ours = red_rows(&common::pipe_ok(rc, &rays));
    let reference = red_rows(&std::fs::read(common::fixture("threephase/D.dmx")).unwrap());
    assert_eq!(ours.len(), 145);
    assert_eq!(reference.len(), 145);
    let (mut ta, mut tb, mut worst) = (0.0, 0.0, 0.0f64);
    for (k, (a, b)) in ours.iter().zip(&reference).enumerate() {
        assert_eq!(a.len(), 146);
        let (sa, sb): (f64, f64) = (a.iter().sum(), b.iter().sum());
        ta += sa;
        tb += sb;
        let p = ((sa + sb) / 2.0).clamp(0.0, 1.0);
        let se = ((p * (1.0 - p)).max(0.01) * (1.0 / c as f64 + 1.0 / 1000.0)).sqrt();
        let z = (sa - sb) / se;
        worst = worst.max(z.abs());
        assert!(
            z.abs() < 4.5,
            "row {k}: ours {sa}, reference {sb} (z = {z:.2})"
        );
    }
    eprintln!("D row sums: worst |z| {worst:.2}; totals ours {ta:.3}, reference {tb:.3}");
    assert!((ta / tb - 1.0).abs() < 0.01, "totals {ta} {tb}");
}

/// The documented fenestra-only pipeline: `oconv`, `genklemsamp | rtcontrib`, on the
/// reference office; D agrees with the reference D as in the oracle test above.
#[test]
fn d_matrix_with_rtcontrib() {
    let dir = common::scratch("gks-d-ours");
    for f in ["materials.rad", "room.rad", "exterior.rad", "sky_dmx.rad"] {
        std::fs::copy(common::fixture(&format!("genklemsamp/{f}")), dir.join(f)).unwrap();
    }
    let oct = common::run_ok(common::fenestra("oconv").current_dir(&dir).args([
        "materials.rad",
        "room.rad",
        "exterior.rad",
        "sky_dmx.rad",
    ]));
    std::fs::write(dir.join("dmx.oct"), oct).unwrap();
    let c = 200;
    let rays = window_rays(c, "-ff");
    let mut rc = common::fenestra("rtcontrib");
    rc.current_dir(&dir).env("RAYPATH", ".").args([
        "-n",
        "2",
        "-c",
        "200",
        "-ffa",
        "-ab",
        "2",
        "-ad",
        "256",
        "-lw",
        "1e-3",
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
        "dmx.oct",
    ]);
    let ours = red_rows(&common::pipe_ok(rc, &rays));
    let reference = red_rows(&std::fs::read(common::fixture("threephase/D.dmx")).unwrap());
    assert_eq!(ours.len(), 145);
    let (mut ta, mut tb, mut worst) = (0.0, 0.0, 0.0f64);
    for (k, (a, b)) in ours.iter().zip(&reference).enumerate() {
        assert_eq!(a.len(), 146);
        let (sa, sb): (f64, f64) = (a.iter().sum(), b.iter().sum());
        ta += sa;
        tb += sb;
        let p = ((sa + sb) / 2.0).clamp(0.0, 1.0);
        let se = ((p * (1.0 - p)).max(0.01) * (1.0 / c as f64 + 1.0 / 1000.0)).sqrt();
        let z = (sa - sb) / se;
        worst = worst.max(z.abs());
        assert!(
            z.abs() < 4.5,
            "row {k}: ours {sa}, reference {sb} (z = {z:.2})"
        );
    }
    eprintln!(
        "D row sums (rtcontrib): worst |z| {worst:.2}; totals ours {ta:.3}, reference {tb:.3}"
    );
    assert!((ta / tb - 1.0).abs() < 0.01, "totals {ta} {tb}");
}

/// A window group of two panes (areas 1 and 3 m², one given through `!echo`, materials
/// undefined as Radiance's genklemsamp allows): origins fall on each in proportion to
/// its area; a polygon at an angle to -vd is left out with a warning.
#[test]
fn window_group_area_weighted() {
    let dir = common::scratch("gks-group");
    std::fs::write(
        dir.join("panes.rad"),
        "glass_a polygon small\n0\n0\n12\n0 0 0  1 0 0  1 0 1  0 0 1\n\
         !echo glass_b polygon big 0 0 12 2 0 0 5 0 0 5 0 1 2 0 1\n\
         glass_c polygon tilted\n0\n0\n12\n0 0 0  1 0 0  1 1 1  0 1 1\n",
    )
    .unwrap();
    let out = common::fenestra("genklemsamp")
        .current_dir(&dir)
        .args([
            "-c",
            "100",
            "-vd",
            "0",
            "-1",
            "0",
            "-vu",
            "0",
            "0",
            "1",
            "panes.rad",
        ])
        .output()
        .unwrap();
    common::assert_ok(&out);
    assert!(String::from_utf8_lossy(&out.stderr).contains("tilted"));
    let r = rows(&out.stdout);
    assert_eq!(r.len(), 14500);
    let big = r.iter().filter(|x| x[0] >= 2.0).count() as f64 / r.len() as f64;
    // binomial sd of the share: sqrt(.75*.25/14500) = 0.0036
    assert!((big - 0.75).abs() < 0.02, "share on the 3 m2 pane {big}");
    assert!(r
        .iter()
        .all(|x| (x[0] <= 1.0 || x[0] >= 2.0) && (0.0..=1.0).contains(&x[2])));
}

/// A whole room given as the window (a newcomer's pitfall): Radiance samples every wall
/// piece perpendicular to -vd silently; fenestra samples them too but says why that is
/// probably wrong. The window alone gets no such warning.
#[test]
fn a_whole_room_instead_of_the_window_is_warned_about() {
    let room = common::fixture("rtrace_threephase_bsdf").join("room.rad");
    let window = common::fixture("rcontrib").join("window_out.rad");
    let run = |f: &std::path::Path| {
        let mut c = common::fenestra("genklemsamp");
        c.args(["-c", "1", "-vd", "0", "-1", "0"]).arg(f);
        let out = c.output().unwrap();
        assert!(out.status.success());
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    let err = run(&room);
    assert!(
        err.contains("a whole room or wall instead of the window?"),
        "{err}"
    );
    assert!(err.contains("face opposite ways"), "{err}");
    assert!(!run(&window).contains("whole room"));
}
