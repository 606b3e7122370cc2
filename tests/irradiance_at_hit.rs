//! rtrace and rcontrib `-i`: irradiance at the first surface along each ray that is not
//! passed, as Radiance's irradiance hack (one tracer function for both tools): rays follow
//! antimatter clip sets, pass trans, dielectric and glass surfaces, and take the
//! irradiance on the side facing them, also where they leave antimatter inside a wall.

mod common;

/// A wall at z = 1 with an antimatter sphere through it (centre z = 1, radius 0.8), a
/// glass pane at z = 0.1 and a trans square at z = 0.12 above the floor, and two small
/// lamps: one above the wall (seen through the hole), one below it.
const LAMPS: &str = "
void light lamp 0 0 3 50 50 50
lamp sphere l1 0 0 4 0.3 0.2 3 0.01
void light lamp2 0 0 3 20 20 20
lamp2 sphere l2 0 0 4 2.5 0.5 0.7 0.01
void plastic w 0 0 5 .5 .5 .5 0 0
void antimatter hole 1 w 0 0
w polygon wall 0 0 12 -5 -5 1 5 -5 1 5 5 1 -5 5 1
hole sphere h 0 0 4 0 0 1 0.8
void glass g 0 0 3 .9 .9 .9
g polygon pane 0 0 12 -5 -5 0.1 5 -5 0.1 5 5 0.1 -5 5 0.1
void trans t 0 0 7 .5 .5 .5 0 0 .4 .3
t polygon tp 0 0 12 1 -1 0.12 2 -1 0.12 2 1 0.12 1 1 0.12
w polygon floor 0 0 12 -5 -5 0 5 -5 0 5 5 0 -5 5 0
";

/// Rays from below, inside and above the antimatter sphere, beside it and far off, each
/// straight down and slanted.
fn lamp_rays() -> String {
    let origins = [
        (0.0, 0.0, 0.05),
        (0.0, 0.0, 0.15),
        (0.2, 0.1, 0.5),
        (-0.3, 0.2, 0.9),
        (0.1, -0.2, 1.3),
        (0.0, 0.0, 2.5),
        (0.3, 0.3, 2.2),
        (-0.2, 0.0, 3.5),
        (1.5, 0.0, 0.5),
        (1.5, 0.3, 2.0),
        (3.0, 0.0, 0.5),
        (-2.0, 1.0, 2.0),
    ];
    let mut s = String::new();
    for (x, y, z) in origins {
        for d in ["0 0 -1", "0.2 -0.1 -1"] {
            s.push_str(&format!("{x} {y} {z} {d}\n"));
        }
    }
    s
}

/// Relative tolerance with `-ab 0 -dt 0` (no sampling): the lamps are spheres, whose
/// solid angle fenestra takes as the exact cone, Radiance as πr²/d², a ratio of
/// 1 + r²/4d², at most 3.1e-5 here (r = 0.01 at 0.9 m); plus 5e-7 for the printed digits.
/// Measured: 2.5e-5 (rtrace and rcontrib). Before one function decided the -i hit, rtrace
/// treated the antimatter and trans surfaces as opaque: up to 20 times off here.
const TOL: f64 = 5e-5;

/// Checks agreement within [`TOL`]; at least `min_lit` of the reference values are
/// non-zero.
fn compare(what: &str, theirs: &[f64], ours: &[f64], min_lit: usize) {
    common::probe::agree_lit(what, theirs, ours, min_lit, TOL, 1e-12);
}

#[test]
fn oracle_irradiance_at_hit_through_antimatter_glass_and_trans() {
    let Some((oracle, dir)) = common::probe::oracle_scene("irradiance_at_hit", LAMPS) else {
        return;
    };
    let input = lamp_rays();
    let (t, o) = common::both_rtrace(&oracle, &dir, &["-h", "-i", "-ab", "0", "-dt", "0"], &input);
    compare("rtrace -i", &t, &o, 72);

    let ropts = [
        "-h", "-i", "-V+", "-ab", "0", "-dj", "0", "-m", "lamp", "-m", "lamp2",
    ];
    let (tt, oo) = common::probe::both(&oracle, &dir, "rcontrib", &ropts, &input);
    compare("rcontrib -i", &tt, &oo, 96);
    // the two lamps' contributions add up to rtrace's value (red channel)
    for (k, v) in o.chunks(3).enumerate() {
        let s = oo[6 * k] + oo[6 * k + 3];
        assert!(
            (s - v[0]).abs() <= 1e-6 * v[0] + 1e-12,
            "ray {k}: {s} vs {}",
            v[0]
        );
    }
    // The surfaces a ray reaches are reported too, as by Radiance: where the irradiance
    // is taken (floor, wall, or the antimatter sphere where a ray leaves it inside the
    // wall) with that value, surfaces passed on the way (glass, trans, antimatter, a wall
    // clipped by it) with what came through them. Before, fenestra reported none of them
    // for -i, and neither clipped nor antimatter surfaces for any ray.
    let sopts = [
        "-h", "-i", "-V+", "-ab", "0", "-dj", "0", "-m", "w", "-m", "g", "-m", "t", "-m", "hole",
    ];
    let (tt, oo) = common::probe::both(&oracle, &dir, "rcontrib", &sopts, &input);
    compare("rcontrib -i -m w -m g -m t -m hole", &tt, &oo, 120);
    let _ = std::fs::remove_dir_all(&dir);
}

/// The scene of issue 6: a wall at z = 1 with an antimatter sphere cut through it, under
/// a uniform sky (glow 1, seen by ambient rays only).
const SKY: &str = "
void glow sky 0 0 4 1 1 1 0
sky source s 0 0 4 0 0 1 180
void plastic w 0 0 5 .5 .5 .5 0 0
void antimatter hole 1 w 0 0
w polygon wall 0 0 12 -5 -5 1 5 -5 1 5 5 1 -5 5 1
hole sphere h 0 0 4 0 0 1 0.8
w polygon floor 0 0 12 -5 -5 0 5 -5 0 5 5 0 -5 5 0
";

/// Rays down the sphere's axis: from below it (the floor's irradiance), from inside it
/// (Radiance does not know the ray starts inside: nothing is clipped, the sphere's lower
/// surface is passed, the floor's irradiance again) and from above the wall (the ray
/// enters the sphere, passes the wall, and leaves the sphere inside the wall: the
/// irradiance on the sphere's lowest point, facing up, with the wall clipped for the
/// sky through the hole and solid for every ambient ray that leaves the sphere below
/// the wall).
#[test]
fn oracle_irradiance_at_hit_inside_antimatter_under_a_sky() {
    let Some((oracle, dir)) = common::probe::oracle_scene("irradiance_at_hit_sky", SKY) else {
        return;
    };
    let input = "0 0 0.1 0 0 -1\n0 0 0.5 0 0 -1\n0 0 2.5 0 0 -1\n";
    let opts = [
        "-h", "-i", "-ab", "1", "-ad", "4000", "-aa", "0", "-lw", "1e-4",
    ];
    let (t, o) = common::both_rtrace(&oracle, &dir, &opts, input);
    let ropts = [
        "-h", "-i", "-V+", "-ab", "1", "-ad", "4000", "-lw", "1e-4", "-m", "sky",
    ];
    let rc = common::probe::ours("rcontrib", &dir, &ropts, "scene.rad", input.as_bytes());
    let rc = common::numbers(&rc.stdout);
    // Exact values: on the floor, the sky through the hole (tan = 0.8: pi sin^2 =
    // 1.22599) and beyond the wall's edges (0.09947, by quadrature); on the sphere's
    // lowest point, the sky within 45 degrees of the zenith (pi / 2).
    let floor = 1.225987 + 0.09947;
    let exact = [floor, floor, std::f64::consts::FRAC_PI_2];
    // Tolerances for fenestra: 4 standard deviations of its values over 8 seeds (floor:
    // sd 0.0045 and 0.0076; the point in the sphere: 0.0013). The reference seeds its
    // sampling from the clock (one seed per second): over 120 runs a second apart its
    // values left the exact ones by −0.0085 ± 0.0067 and −0.0089 ± 0.0073 (mean ± sd) on
    // the floor, +0.0015 ± 0.0032 in the sphere, so it is held to its mean offset plus 5
    // sd: 0.045 and 0.018. (0.01 in the sphere, set from 6 runs, was 2.7 sd from the mean
    // and failed once in CI at +0.0108.) Before this was fixed, fenestra gave 0.0571 for
    // the ray from inside and pi for the one from above.
    let tol = [0.03, 0.03, 0.006];
    let tol_oracle = [0.045, 0.045, 0.018];
    for k in 0..3 {
        let v = t[3 * k];
        assert!(
            (v - exact[k]).abs() <= tol_oracle[k],
            "ray {k}: oracle {v}, exact {}",
            exact[k]
        );
        for (who, v) in [("rtrace", o[3 * k]), ("rcontrib", rc[3 * k])] {
            assert!(
                (v - exact[k]).abs() <= tol[k],
                "ray {k}: {who} {v}, exact {}",
                exact[k]
            );
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn irradiance_at_hit_is_the_same_for_any_thread_count() {
    let dir = common::probe::scene_dir("irradiance_at_hit_threads", LAMPS);
    let input = lamp_rays().repeat(4);
    let mut outs = Vec::new();
    for n in ["1", "2"] {
        for tool in ["rtrace", "rcontrib"] {
            let mut args = vec!["-h", "-i", "-ab", "1", "-ad", "64", "-n", n];
            if tool == "rcontrib" {
                args.extend(["-m", "lamp", "-m", "w"]);
            }
            let out = common::probe::ours(tool, &dir, &args, "scene.rad", input.as_bytes());
            outs.push(out.stdout);
        }
    }
    assert!(!outs[0].is_empty() && !outs[1].is_empty());
    assert_eq!(outs[0], outs[2], "rtrace -i: -n 1 and -n 2 differ");
    assert_eq!(outs[1], outs[3], "rcontrib -i: -n 1 and -n 2 differ");
    let _ = std::fs::remove_dir_all(&dir);
}
