//! A shadow ray is aimed at one source object: against the reference rtrace and rcontrib,
//! another emitter in its way stops it even when both share a material (Radiance compares
//! the object hit with the source's object), and an illum met from its front stops a ray
//! aimed at another illum or glow.

mod common;

/// Lamps sharing the material `lm` (a small square under a large one, a small sphere under
/// another), two suns and a square lamp sharing `sunm` (the lamp shades one sun from part of
/// the floor), and a glass pane out of the way (so shadow rays to the suns are traced through
/// surfaces rather than tested for any hit).
const SAME: &str = "
void light lm 0 0 3 10 10 10
lm polygon big 0 0 12 -1 -1 3 -1 1 3 1 1 3 1 -1 3
lm polygon small 0 0 12 -.25 -.25 2 -.25 .25 2 .25 .25 2 .25 -.25 2
lm sphere ball 0 0 4 -2 1.5 1.5 0.02
lm sphere ball2 0 0 4 -2 1.5 2.5 0.03
void light sunm 0 0 3 100 100 100
sunm source s1 0 0 4 0.3 0 1 1
sunm source s2 0 0 4 -0.3 0.2 1 1
sunm polygon sl 0 0 12 1.5 -1 4 1.5 1 4 3 1 4 3 -1 4
void glass gl 0 0 3 .9 .9 .9
gl polygon pane 0 0 12 6 -1 0.1 6 1 0.1 6 1 1 6 -1 1
void plastic w 0 0 5 .5 .5 .5 0 0
w polygon floor 0 0 12 -5 -5 0 5 -5 0 5 5 0 -5 5 0
";

/// Two illums of one material (a small one under a large one), and an illum under a glow.
const ILLUM: &str = "
void illum im 0 0 3 10 10 10
im polygon ibig 0 0 12 -1 -1 3 -1 1 3 1 1 3 1 -1 3
im polygon ismall 0 0 12 -.25 -.25 2 -.25 .25 2 .25 .25 2 .25 -.25 2
void glow gm 0 0 4 5 5 5 10
void illum im2 0 0 3 7 7 7
gm polygon gup 0 0 12 3 -1 3 3 1 3 4 1 3 4 -1 3
im2 polygon iup 0 0 12 3 -1 2 3 1 2 4 1 2 4 -1 2
void plastic w 0 0 5 .5 .5 .5 0 0
w polygon floor 0 0 12 -5 -5 0 5 -5 0 5 5 0 -5 5 0
";

/// View rays onto the floor from 0.3 above it.
fn rays(xs: &[f64], ys: &[f64]) -> String {
    let mut s = String::new();
    for x in xs {
        for y in ys {
            s.push_str(&format!("{x} {y} 0.3 0 0 -1\n"));
        }
    }
    s
}

/// Relative tolerance: the lamps are polygons sampled at their centres (`-ds 0`, as
/// Radiance) and spheres, whose solid angle fenestra takes as the exact cone
/// 2π(1 − cos θ) and Radiance as πr²/d², a ratio of 1 + r²/4d²: at most 4.5e-5 here (the
/// 0.02 sphere seen from 1.5 m below it; the 0.03 one from 2.5 m: 3.6e-5); plus 5e-7 for
/// the 7 printed digits. Measured: 4.2e-7 (rtrace), 5.1e-7 (rcontrib), 2.1e-7 (illums).
const TOL: f64 = 5e-5;

/// Compares the oracle's values with ours and asks for at least `min_lit` of the oracle's
/// values to be positive, so that two tools printing only zeros do not pass.
fn check(what: &str, theirs: &[f64], ours: &[f64], min_lit: usize) -> f64 {
    let lit = theirs.iter().filter(|v| **v > 0.0).count();
    assert!(
        lit >= min_lit,
        "{what}: only {lit} lit values (at least {min_lit} expected)"
    );
    let worst = common::agree(what, theirs, ours, TOL, 1e-9);
    eprintln!("{what}: largest relative difference {worst:.2e}");
    worst
}

#[test]
fn oracle_same_material_sources_block_each_other() {
    let Some((oracle, dir)) = common::cli::oracle_scratch("source_objects") else {
        return;
    };
    std::fs::write(dir.join("scene.rad"), SAME).unwrap();
    let input = rays(
        &[-2.5, -2.0, -1.5, -0.5, 0.0, 0.4, 1.0, 2.0, 2.5, 2.8],
        &[-0.5, 0.0, 1.5],
    );
    let opts = ["-h", "-ab", "0", "-ds", "0", "-dt", "0"];
    let (t, o) = common::both_rtrace(&oracle, &dir, &opts, &input);
    // first column of each record
    let t: Vec<f64> = t.chunks(3).map(|c| c[0]).collect();
    let o: Vec<f64> = o.chunks(3).map(|c| c[0]).collect();
    // every point sees at least one lamp (measured: 30 of 30)
    check("rtrace", &t, &o, 30);
    // rcontrib: contributions of each material (-V+), no jitter so that both sample the
    // same points
    common::oracle_octree(&oracle, &dir, &["scene.rad"]);
    let ropts = [
        "-h", "-V+", "-ab", "0", "-ds", "0", "-dj", "0", "-m", "lm", "-m", "sunm",
    ];
    let (tt, oo) = common::cli::both_numbers(&oracle, "rcontrib", &dir, &ropts, input.as_bytes());
    // both materials light every point (measured: 180 of 180)
    check("rcontrib -m lm -m sunm", &tt, &oo, 180);
    // Under the small square the lamps' light is the small lamp's: 10 x its solid angle
    // 0.25 / 2^2, times the floor's 0.5 / pi, plus 0.38% from the two small spheres; before,
    // fenestra also counted the large lamp behind it (4 / 3^2: 7.1 times the small one's).
    let under_small = (4 * 3 + 1) * 6; // x = 0, y = 0: first of the record's six numbers
    let small_only = 0.5 / std::f64::consts::PI * 10.0 * (0.25 / 4.0);
    assert!(
        (oo[under_small] - small_only).abs() <= 0.01 * small_only,
        "under both lamps: {} (the small lamp alone gives {small_only})",
        oo[under_small]
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn oracle_illum_in_front_of_illum_or_glow_blocks() {
    let Some((oracle, dir)) = common::cli::oracle_scratch("source_objects_illum") else {
        return;
    };
    std::fs::write(dir.join("scene.rad"), ILLUM).unwrap();
    let input = rays(&[-1.5, -0.5, 0.0, 0.2, 1.2, 3.5, 4.2], &[0.0, 0.7]);
    let opts = ["-h", "-ab", "0", "-ds", "0", "-dt", "0"];
    let (t, o) = common::both_rtrace(&oracle, &dir, &opts, &input);
    // every point sees an illum or the glow (measured: 42 of 42)
    check("rtrace illums", &t, &o, 42);
    let _ = std::fs::remove_dir_all(&dir);
}
