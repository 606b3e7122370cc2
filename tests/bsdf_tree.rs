//! Tensor-tree `BSDF` materials (genBSDF `-t3`/`-t4` output) rendered against Radiance's
//! rtrace on the reference office (tests/fixtures/rtrace_threephase_bsdf, the blinds'
//! trees of tests/fixtures/dctimestep).

mod common;

use common::{fenestra, fixture, numbers, run_stdin, scratch};
use std::path::{Path, PathBuf};

/// A scratch copy of the reference office with the window's BSDF file replaced by `tree`
/// and the sky `sky` (a file of the fixture folder or written here).
fn office(name: &str, tree: &str) -> PathBuf {
    let dir = scratch(name);
    let src = fixture("rtrace_threephase_bsdf");
    for f in [
        "materials.rad",
        "room.rad",
        "exterior.rad",
        "skyfunc_glow.rad",
        "sensors.pts",
    ] {
        std::fs::copy(src.join(f), dir.join(f)).unwrap();
    }
    std::fs::copy(
        src.join("sky_t4_sep21_1200_overcast.rad"),
        dir.join("overcast.rad"),
    )
    .unwrap();
    std::fs::copy(fixture(&format!("dctimestep/{tree}")), dir.join(tree)).unwrap();
    let win = std::fs::read_to_string(src.join("window_bsdf.rad"))
        .unwrap()
        .replace("blinds_kf.xml", tree);
    std::fs::write(dir.join("window.rad"), win).unwrap();
    // Dec 21 noon at the reference site, sun only (gensky 12 21 12 -a 37.71 -o 122.21 -m 120 +s)
    std::fs::write(
        dir.join("sun.rad"),
        "void light solar\n0\n0\n3 6.073e+06 6.073e+06 6.073e+06\n\
         solar source sun\n0\n0\n4 0.024505 -0.875778 0.482092 0.5\n",
    )
    .unwrap();
    dir
}

/// Mean luminance over the sensors (in the order given).
fn mean(out: &[u8]) -> f64 {
    let v = numbers(out);
    let n = v.len() / 3;
    v.chunks(3)
        .map(|c| 0.265 * c[0] + 0.670 * c[1] + 0.065 * c[2])
        .sum::<f64>()
        / n as f64
}

/// The oracle's means over `orders` shuffled sensor orders (its only source of run-to-run
/// variation at `-as 0`) and ours over as many seeds.
fn both(dir: &Path, scene: &[&str], opts: &[&str], orders: u64) -> (Vec<f64>, Vec<f64>) {
    let o = common::oracle().expect("oracle");
    let mut c = o.command("oconv");
    c.args(scene).current_dir(dir);
    std::fs::write(dir.join("scene.oct"), common::run_ok(&mut c)).unwrap();
    let text = std::fs::read_to_string(dir.join("sensors.pts")).unwrap();
    let lines: Vec<&str> = text.lines().filter(|l| !l.trim().is_empty()).collect();
    let (mut theirs, mut ours) = (Vec::new(), Vec::new());
    for k in 0..orders {
        // a fixed shuffle per k
        let mut next = common::xorshift(k + 11);
        let mut order = lines.clone();
        for i in (1..order.len()).rev() {
            let j = (next() * (i + 1) as f64) as usize;
            order.swap(i, j);
        }
        let input = order.join("\n") + "\n";
        let mut c = o.command("rtrace");
        c.args(["-h", "-I+", "-aa", "0", "-as", "0"])
            .args(opts)
            .arg("scene.oct")
            .current_dir(dir);
        let out = run_stdin(c, input.as_bytes());
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        theirs.push(mean(&out.stdout));
        let mut c = fenestra("rtrace");
        c.args(["-h", "-I+", "-seed", &k.to_string()])
            .args(opts)
            .args(scene)
            .current_dir(dir);
        c.env("RAYPATH", dir);
        let out = run_stdin(c, text.as_bytes());
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        ours.push(mean(&out.stdout));
    }
    (theirs, ours)
}

/// Means of both tools within 4 combined standard errors of the mean (each tool's spread
/// over its runs), and the gap printed.
fn agree(what: &str, theirs: &[f64], ours: &[f64]) {
    let (ta, ts) = common::mean_sem(theirs);
    let (oa, os) = common::mean_sem(ours);
    let se = (ts * ts + os * os).sqrt();
    eprintln!("{what}: oracle {ta:.4} ± {ts:.4}, fenestra {oa:.4} ± {os:.4}");
    assert!(ta > 0.0 && oa > 0.0);
    assert!(
        (ta - oa).abs() <= 4.0 * se,
        "{what}: oracle {ta} ± {ts}, ours {oa} ± {os}"
    );
}

/// Overcast sky and a sun alone through the rank-4 and rank-3 trees of the reference
/// blind, one ambient bounce: means over the 45 sensors within the runs' noise.
#[test]
fn oracle_tree_windows_agree_within_noise() {
    if common::oracle().is_none() {
        return;
    }
    for tree in ["blinds_t4.xml", "blinds_t3.xml"] {
        let dir = office(&format!("bsdf-tree-{tree}"), tree);
        let sky = [
            "materials.rad",
            "room.rad",
            "exterior.rad",
            "window.rad",
            "overcast.rad",
            "skyfunc_glow.rad",
        ];
        let opts = ["-ab", "1", "-ad", "2048", "-lw", "1e-4"];
        let (t, o) = both(&dir, &sky, &opts, 4);
        agree(&format!("{tree} overcast -ab 1"), &t, &o);
        let sun = [
            "materials.rad",
            "room.rad",
            "exterior.rad",
            "window.rad",
            "sun.rad",
        ];
        let (t, o) = both(&dir, &sun, &opts, 6);
        agree(&format!("{tree} sun -ab 1"), &t, &o);
    }
}

/// Without jitter and ambient light the direct sun through a tree is deterministic in both
/// tools: 80 view rays through the window within 1e-4 (printed digits, Radiance's single
/// precision leaves).
#[test]
fn oracle_tree_direct_exact() {
    let Some(o) = common::oracle() else { return };
    let dir = office("bsdf-tree-exact", "blinds_t4.xml");
    let mut rays = String::new();
    for th in (0..80).step_by(8) {
        for ph in (0..360).step_by(45) {
            let (t, p) = (f64::from(th).to_radians(), f64::from(ph).to_radians());
            let d = [t.sin() * p.cos(), -t.cos(), t.sin() * p.sin()];
            rays.push_str(&format!("2 1.0 1.65 {:.6} {:.6} {:.6}\n", d[0], d[1], d[2]));
        }
    }
    let scene = [
        "materials.rad",
        "room.rad",
        "exterior.rad",
        "window.rad",
        "sun.rad",
    ];
    let mut c = o.command("oconv");
    c.args(scene).current_dir(&dir);
    std::fs::write(dir.join("scene.oct"), common::run_ok(&mut c)).unwrap();
    let mut c = o.command("rtrace");
    c.args(["-h", "-aa", "0", "-ab", "0", "-ss", "0", "scene.oct"])
        .current_dir(&dir);
    let theirs = numbers(&run_stdin(c, rays.as_bytes()).stdout);
    let mut c = fenestra("rtrace");
    c.args(["-h", "-ab", "0", "-ss", "0"])
        .args(scene)
        .current_dir(&dir);
    c.env("RAYPATH", &dir);
    let ours = numbers(&run_stdin(c, rays.as_bytes()).stdout);
    assert_eq!(theirs.len(), ours.len());
    let lum = |v: &[f64]| -> Vec<f64> {
        v.chunks(3)
            .map(|c| 0.265 * c[0] + 0.670 * c[1] + 0.065 * c[2])
            .collect()
    };
    let (t, u) = (lum(&theirs), lum(&ours));
    let lit = t.iter().filter(|x| **x > 0.0).count();
    assert!(lit > 40, "{lit} lit views");
    for (k, (a, b)) in t.iter().zip(&u).enumerate() {
        assert!(
            (a - b).abs() <= 1e-4 * a.abs() + 1e-6,
            "view {k}: oracle {a} ours {b}"
        );
    }
}
