//! fenestra's own lib/skybright.cal and lib/perezlum.cal, evaluated by the
//! oracle's rcalc, against Radiance's files and against the Rust sky models that
//! genskyvec uses.

mod common;

use fenestra_sky::cie::SkyBright;
use fenestra_sky::skyvec::PerezLum;
use std::path::Path;

/// Directions over the whole sphere, plus the horizon, the ±0.01 switch of the
/// horizon factor, zenith and nadir.
fn directions() -> Vec<[f64; 3]> {
    let mut v = Vec::new();
    for i in 0..40 {
        let z = -1.0 + 2.0 * (i as f64 + 0.5) / 40.0;
        for j in 0..12 {
            let phi = j as f64 * std::f64::consts::FRAC_PI_6 + i as f64 * 0.1;
            let r = (1.0 - z * z).sqrt();
            v.push([r * phi.cos(), r * phi.sin(), z]);
        }
    }
    for z in [0.0, 0.01, -0.01, 0.0100001, 1.0, -1.0] {
        let r = (1.0f64 - z * z).sqrt();
        v.push([r * 0.6, r * 0.8, z]);
    }
    v
}

/// Evaluates `func` of `cal` for every direction with the oracle's rcalc (binary doubles).
fn rcalc(o: &common::Oracle, cal: &Path, args: &[f64], func: &str) -> Vec<f64> {
    let mut defs = String::from("Dx=$1;Dy=$2;Dz=$3;");
    for (i, a) in args.iter().enumerate() {
        defs += &format!("A{}={a:e};", i + 1);
    }
    let mut c = o.command("rcalc");
    c.arg("-od")
        .arg("-f")
        .arg(o.lib().join("rayinit.cal"))
        .args(["-e", &defs, "-f"])
        .arg(cal)
        .args(["-e", &format!("$1={func}")]);
    let mut input = String::new();
    for d in directions() {
        input += &format!("{:e} {:e} {:e}\n", d[0], d[1], d[2]);
    }
    common::pipe_ok(c, input.as_bytes())
        .chunks(8)
        .map(|b| f64::from_le_bytes(b.try_into().unwrap()))
        .collect()
}

/// Same formulas evaluated in double precision with a different operation order:
/// agreement to 1e-12 relative (a few ulps).
fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * a.abs().max(b.abs()).max(1e-300)
}

/// For each of `skies` (a sky function's arguments), `func` of fenestra's lib/`file` and of
/// Radiance's, both evaluated by the oracle's rcalc, and the Rust model's radiance
/// `model(sky, direction)` must agree over [`directions`]. Skipped without the oracle.
fn check_cal(file: &str, func: &str, skies: &[&[f64]], model: impl Fn(&[f64], [f64; 3]) -> f64) {
    let Some(o) = common::oracle() else { return };
    let ours = common::fixture(&format!("../../lib/{file}"));
    let theirs = o.lib().join(file);
    let dirs = directions();
    for &a in skies {
        let x = rcalc(&o, &ours, a, func);
        let y = rcalc(&o, &theirs, a, func);
        for (k, d) in dirs.iter().enumerate() {
            assert!(
                close(x[k], y[k]),
                "{a:?} {d:?}: ours {} Radiance {}",
                x[k],
                y[k]
            );
            let r = model(a, *d);
            assert!(close(r, y[k]), "{a:?} {d:?}: Rust {r} Radiance {}", y[k]);
        }
    }
}

#[test]
fn oracle_skybright_cal() {
    let skies: &[&[f64]] = &[
        &[1.0, 11.61, 23.77, 0.6942, 0.070810, -0.615688, 0.784802],
        &[4.0, 9.5, 12.1, 1.022, -0.4, 0.3, 0.866],
        &[2.0, 25.54, 3.973],
        &[3.0, 20.0, 4.0],
        &[1.0, 3.6, 4.8, 0.3045, -0.045, -0.97294, 0.226623],
    ];
    check_cal("skybright.cal", "skybr", skies, |a, d| {
        SkyBright::from_args(a).unwrap().radiance(d)
    });
}

#[test]
fn oracle_perezlum_cal() {
    let skies: &[&[f64]] = &[
        &[
            37.58, 27.17, -0.969191, -0.175739, 20.531681, -5.689187, 1.276820, 0.070635,
            -0.615559, 0.784919,
        ],
        &[
            22.43, 8.225, 0.933613, -0.528373, 0.779155, -0.552602, -0.029074, 0.067850, -0.617254,
            0.783832,
        ],
        &[
            30.01, 6.92, -0.533332, -1.714516, 10.991083, -3.282816, -0.140719, 0.622228,
            -0.770308, 0.139489,
        ],
    ];
    check_cal("perezlum.cal", "skybright", skies, |a, d| {
        PerezLum::from_args(a).unwrap().radiance(d)
    });
}
