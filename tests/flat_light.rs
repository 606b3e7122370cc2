//! Flat light sources: light, illum, glow and spotlight materials on polygons (squares,
//! long rectangles, triangles, a concave polygon, a hexagon, a tilted quad) and rings,
//! against the reference rtrace and rcontrib; the errors and warning Radiance gives for
//! flat sources it cannot sample.
//!
//! All comparisons use `-u-`: Radiance's default `-u+` turns the sampling frame of a ring
//! or of a polygon with more than four vertices randomly at each run (fenestra uses the
//! `-u-` frame; see docs/tools/rtrace.md). Points are `-I` records at distances from 0.02
//! to 10 source sizes, some behind a wall that partly blocks the lamp.

mod common;

use std::path::PathBuf;

/// A wall (x = .5, y from -3 to .3, z up to 1.5) partly between the lamps and the points,
/// and a floor below the lowest point.
const ROOM: &str = "
void plastic w 0 0 5 .5 .5 .5 0 0
w polygon wall 0 0 12 .5 -3 -9  .5 -3 1.5  .5 .3 1.5  .5 .3 -9
w polygon floor 0 0 12 -20 -20 -9  20 -20 -9  20 20 -9  -20 20 -9
";

/// One lamp per scene, about 1 across, at z = 2 facing down (the tilted quad rises to 2.6;
/// the tilted disk crosses the plane of the nearest points).
const LAMPS: [(&str, &str); 8] = [
    (
        "square",
        "void light L 0 0 3 10 10 10\nL polygon lamp 0 0 12 0 0 2  0 1 2  1 1 2  1 0 2",
    ),
    (
        "rectangle",
        "void illum L 0 0 3 10 10 10\nL polygon lamp 0 0 12 0 0 2  0 .15 2  1.6 .15 2  1.6 0 2",
    ),
    (
        "triangle",
        "void glow L 0 0 4 10 10 10 5\nL polygon lamp 0 0 9 0 0 2  .3 1 2  1.2 .2 2",
    ),
    (
        "concave",
        "void spotlight L 0 0 7 10 10 10 120 0 0 -1\n\
         L polygon lamp 0 0 18 0 0 2  0 1 2  1 1 2  1 .6 2  .4 .5 2  1 .4 2",
    ),
    (
        "hexagon",
        "void light L 0 0 3 10 10 10\n\
         L polygon lamp 0 0 18 0 0 2  -.3 .5 2  0 1 2  1 1 2  1.3 .5 2  1 0 2",
    ),
    (
        "tilted",
        "void illum L 0 0 3 10 10 10\nL polygon lamp 0 0 12 0 0 2  0 1 2.3  1 1 2.6  1 0 2.3",
    ),
    (
        "disk",
        "void light L 0 0 3 10 10 10\nL ring lamp 0 0 8 .5 .5 2  0 0 -1  0 .5",
    ),
    (
        // its extent vectors tie in length: which is halved first depends on the last bit
        // of its normal (Radiance's normalisation, reproduced)
        "tilted disk",
        "void glow L 0 0 4 10 10 10 20\nL ring lamp 0 0 8 .5 .5 2  .3 .2 -1  0 .4",
    ),
];

/// 126 `-I` records: 7 positions at 9 distances below the lamp plane, two normals each.
fn points() -> String {
    let mut s = String::new();
    for d in [0.02, 0.05, 0.1, 0.3, 0.7, 1.5, 3.0, 6.0, 10.0] {
        for (x, y) in [
            (0.5, 0.5),
            (0.1, 0.2),
            (0.9, 0.05),
            (-0.4, 0.5),
            (1.3, 1.2),
            (0.2, 0.9),
            (2.5, -1.0),
        ] {
            let z = 2.0 - d;
            s.push_str(&format!("{x} {y} {z} 0 0 1\n{x} {y} {z} .3 -.2 .9\n"));
        }
    }
    s
}

/// Relative agreement of two values printed with 7 significant digits: half a unit in the
/// last digit is up to 5e-7, and Radiance sums colours in single precision (measured over
/// the runs below: at most 1.3e-6, on a ring).
const PRINTED: f64 = 3e-6;

fn scene(lamp: &str) -> String {
    format!("{lamp}\n{ROOM}")
}

/// Each of [`LAMPS`] by name, with the scratch folder `dir_name` made afresh to hold its
/// scene as the loop reaches it.
fn lamp_dirs(dir_name: &str) -> impl Iterator<Item = (&'static str, PathBuf)> + '_ {
    LAMPS
        .into_iter()
        .map(move |(name, lamp)| (name, common::probe::scene_dir(dir_name, &scene(lamp))))
}

#[test]
fn oracle_flat_sources_with_no_jitter_equal_radiance() {
    let Some(oracle) = common::oracle() else {
        return;
    };
    let pts = points();
    for (name, dir) in lamp_dirs("flat_dj0") {
        for extra in [&["-ds", "0"][..], &[], &["-ds", ".05"], &["-ds", ".5"]] {
            let mut opts = vec!["-h", "-I", "-ab", "0", "-u-", "-dj", "0", "-dt", "0"];
            opts.extend_from_slice(extra);
            let (t, o) = common::both_rtrace(&oracle, &dir, &opts, &pts);
            let lit = t.iter().filter(|v| **v > 0.0).count();
            assert!(lit > 150, "{name} {extra:?}: only {lit} lit values");
            common::probe::agree_noted(&format!("{name} {extra:?}"), &t, &o, PRINTED, 1e-12);
        }
    }
}

/// A lamp polygon: `n` vertices on a circle of radius `r` about (.5, .5, 2), turned by
/// `turn` degrees about z, then tilted by `tilt` radians about the x direction through its
/// centre; vertices in the order that makes it face down.
fn turned_polygon(mat: &str, n: usize, r: f64, turn: f64, tilt: f64) -> String {
    let mut s = format!("{mat}\nL polygon lamp 0 0 {}", 3 * n);
    for k in 0..n {
        let a = turn.to_radians() - (k as f64) * std::f64::consts::TAU / n as f64;
        let (x, y) = (r * a.cos(), r * a.sin());
        let (y, z) = (y * tilt.cos(), y * tilt.sin());
        s.push_str(&format!("  {:.9} {:.9} {:.9}", 0.5 + x, 0.5 + y, 2.0 + z));
    }
    s
}

#[test]
fn oracle_turned_and_tilted_squares_and_hexagons_equal_radiance() {
    // A polygon's normal is fenestra's own (not rebuilt with Radiance's arithmetic), so the
    // split of a lamp whose extent vectors tie could differ in principle: these lamps
    // check that it does not here.
    let Some(oracle) = common::oracle() else {
        return;
    };
    let pts = points();
    let light = "void light L 0 0 3 10 10 10";
    let illum = "void illum L 0 0 3 10 10 10";
    let glow = "void glow L 0 0 4 10 10 10 5";
    let lamps = [
        turned_polygon(light, 4, std::f64::consts::FRAC_1_SQRT_2, 30.0, 0.2),
        turned_polygon(illum, 4, std::f64::consts::FRAC_1_SQRT_2, 75.0, -0.3),
        turned_polygon(glow, 4, std::f64::consts::FRAC_1_SQRT_2, 115.0, 0.4),
        turned_polygon(light, 6, 0.55, 40.0, -0.2),
        turned_polygon(illum, 6, 0.55, 65.0, 0.3),
        turned_polygon(glow, 6, 0.55, 100.0, -0.4),
    ];
    // measured: 231 to 333 of the 378 values lit, all within 1.0e-6 (9.86e-7 the largest,
    // the first hexagon at the default -ds and at .05)
    for (k, lamp) in lamps.iter().enumerate() {
        let dir = common::probe::scene_dir("flat_turned", &scene(lamp));
        for extra in [&[][..], &["-ds", ".5"], &["-ds", ".05"]] {
            let mut opts = vec!["-h", "-I", "-ab", "0", "-u-", "-dj", "0", "-dt", "0"];
            opts.extend_from_slice(extra);
            let (t, o) = common::both_rtrace(&oracle, &dir, &opts, &pts);
            let lit = t.iter().filter(|v| **v > 0.0).count();
            assert!(
                lit > 150,
                "lamp {k} {extra:?}: only {lit} lit values\n{lamp}"
            );
            let worst = common::agree(&format!("lamp {k} {extra:?}"), &t, &o, PRINTED, 1e-12);
            eprintln!("lamp {k} {extra:?}: {lit} lit, largest relative difference {worst:.3e}");
        }
    }
}

#[test]
fn oracle_thresholded_flat_sources_equal_radiance_over_32_records() {
    // with -dt > 0 the first 32 records follow a single Radiance process exactly
    let Some(oracle) = common::oracle() else {
        return;
    };
    let pts: String = points()
        .lines()
        .skip(28)
        .take(32)
        .map(|l| format!("{l}\n"))
        .collect();
    for (name, dir) in lamp_dirs("flat_dt") {
        for extra in [&[][..], &["-ds", ".05", "-dt", ".2"]] {
            let mut opts = vec!["-h", "-I", "-ab", "0", "-u-", "-dj", "0"];
            opts.extend_from_slice(extra);
            let (t, o) = common::both_rtrace(&oracle, &dir, &opts, &pts);
            common::probe::agree_noted(&format!("{name} {extra:?}"), &t, &o, PRINTED, 1e-12);
        }
    }
}

#[test]
fn oracle_rcontrib_flat_contributions() {
    let Some(oracle) = common::oracle() else {
        return;
    };
    for (name, dir) in lamp_dirs("flat_rcontrib") {
        // rcontrib's -dj default is .9 and -u+: -dj 0 -u- for a deterministic comparison
        for extra in [&["-ds", "0"][..], &[], &["-ds", ".05"]] {
            let mut args = vec!["-h", "-I", "-ab", "0", "-u-", "-dj", "0"];
            args.extend_from_slice(extra);
            args.extend_from_slice(&["-m", "L"]);
            let (t, o) = common::probe::both(&oracle, &dir, "rcontrib", &args, &points());
            assert_eq!(t.len(), 126 * 3);
            assert!(t.iter().filter(|v| **v > 0.0).count() > 150);
            let what = format!("rcontrib {name} {extra:?}");
            common::probe::agree_noted(&what, &t, &o, PRINTED, 1e-12);
        }
    }
}

#[test]
fn oracle_jittered_flat_sources_agree_within_monte_carlo_error() {
    let Some(oracle) = common::oracle() else {
        return;
    };
    // each point repeated: both draw new jitter for every record
    let reps = 1000;
    let points = [
        "0.5 0.5 1.9 0 0 1\n",
        "0.9 0.05 1.7 .3 -.2 .9\n",
        "-0.4 0.5 1.95 0 0 1\n",
    ];
    let mut rays = String::new();
    for p in points {
        rays.push_str(&p.repeat(reps));
    }
    // -u+ (Radiance's default) for the quad and triangle, whose frames do not depend on
    // it: Radiance's jitter is then plain pseudo-random, as fenestra's, and the spreads
    // per record are compared too. With -u- Radiance draws the jitter from an
    // anticorrelated table (per record and part), which lowers the spread per record
    // (measured: 1.5x at 64 parts) but not the mean; the disk needs -u- (with -u+ its
    // frame turns at random and the mean with it: 4.22 to 4.46 at the second point).
    for (name, lamp, u) in [
        (LAMPS[0].0, LAMPS[0].1, "-u+"),
        (LAMPS[2].0, LAMPS[2].1, "-u+"),
        (LAMPS[6].0, LAMPS[6].1, "-u-"),
        (LAMPS[4].0, LAMPS[4].1, "-u-"),
    ] {
        let dir = common::probe::scene_dir("flat_dj", &scene(lamp));
        // -dj .9 maps a disk's single sample onto the disk too (above .7)
        for extra in [
            &["-ds", "0", "-dj", ".7"][..],
            &["-dj", ".7"],
            &["-ds", ".05", "-dj", ".7"],
            &["-ds", "0", "-dj", ".9"],
        ] {
            // -dt 0: every sample shadow-tested (the comparison is of the sampling alone)
            let mut opts = vec!["-h", "-I", "-ab", "0", u, "-dt", "0"];
            opts.extend_from_slice(extra);
            let (t, o) = common::both_rtrace(&oracle, &dir, &opts, &rays);
            for (k, p) in points.iter().enumerate() {
                let [(mt, st), (mo, so)] = common::probe::red_means(&t, &o, k, reps);
                eprintln!(
                    "{name} {extra:?} point {}: oracle {mt:.6} ± {st:.2e}, ours {mo:.6} ± {so:.2e}, {:.2} s.e.",
                    p.trim(),
                    (mt - mo).abs() / (st * st + so * so).sqrt().max(1e-300)
                );
                // 5 combined standard errors. The oracle's 1000-record means vary between
                // its clock-seeded runs by 1.02 to 1.20 of their standard errors (skewed
                // values; 60 runs a second apart): at 4 s.e. the 24 checks would fail
                // about once in 300 runs, at 5 about once in 20000.
                let what = format!("{name} {extra:?} point {}", p.trim());
                common::probe::means_agree(&what, [(mt, st), (mo, so)]);
                // spreads per record within a factor 2: with 1000 skewed records a
                // spread is known less well than its normal-theory 2-3%; the oracle's own
                // spread at the square's first point with -ds 0 -dj .9 varied by 9.7%
                // (sd of its log over 360 runs), so two runs differ by a log-ratio of sd
                // 0.137, and 1.5 (2.96 sd) failed 0.28% of oracle pairs; 2 is 5 sd.
                assert!(
                    u == "-u-" || (st == 0.0 && so == 0.0) || (so < 2.0 * st && st < 2.0 * so),
                    "{name} {extra:?} point {}: spreads {st} {so}",
                    p.trim()
                );
            }
        }
    }
}

#[test]
fn jittered_flat_sources_do_not_depend_on_threads() {
    let pts = points();
    for (name, dir) in lamp_dirs("flat_threads") {
        let run = |n: &str, opts: &[&str]| {
            let args = [&["-h", "-I", "-ab", "0", "-n", n][..], opts].concat();
            common::probe::ours("rtrace", &dir, &args, "scene.rad", pts.as_bytes()).stdout
        };
        for opts in [
            &["-dj", ".7"][..],
            &["-dj", ".9", "-ds", ".05", "-dt", ".1"],
        ] {
            let one = run("1", opts);
            assert!(common::numbers(&one).iter().any(|v| *v > 0.0), "{name}");
            assert_eq!(one, run("2", opts), "{name} {opts:?}");
        }
    }
}

#[test]
fn flat_sources_radiance_cannot_aim_at_are_errors() {
    // Radiance: "cannot hit source center" for both
    common::fails_with(
        "flat_err",
        "void light l 0 0 3 1 1 1\n\nl ring r 0 0 8 0 0 2 0 0 -1 .2 .5\n",
        &["bad.rad:3", "ring 'r'", "cannot hit source center"],
    );
    common::fails_with(
        "flat_err",
        "void illum l 0 0 3 1 1 1\nl polygon p 0 0 18 0 0 2 0 1 2 1 1 2 .1 .9 2 .1 .1 2 1 0 2\n",
        &["bad.rad:2", "polygon 'p'", "cannot hit source center"],
    );
    // a ring with an inner radius is fine as an ordinary surface
    let scene = "void plastic p 0 0 5 .5 .5 .5 0 0\np ring r 0 0 8 0 0 2 0 0 -1 .2 .5\n";
    common::probe::rtrace_file(
        "flat_ring_ok",
        "ok.rad",
        scene,
        &["-h", "-ab", "0"],
        b"0 .3 0 0 0 1\n",
        &[],
    );
}

#[test]
fn thin_triangle_source_warns_like_radiance() {
    // Radiance: "triangular source with poor aspect" when the centre is within
    // sqrt(.08 x area) of an edge
    let scene = "void light l 0 0 3 1 1 1\nl polygon thin 0 0 9 0 0 2 0 1 2 .05 .5 2\n";
    let v = common::probe::rtrace_file(
        "flat_thin",
        "thin.rad",
        scene,
        &["-h", "-I", "-ab", "0"],
        b"0 0 0 0 0 1\n",
        &["thin.rad:2", "poor aspect"],
    );
    assert!(v[0] > 0.0);
}
