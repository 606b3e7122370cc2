//! `antimatter` against the reference rtrace: holes through and recesses into a thick wall,
//! antimatter in free space, a ray starting inside the wall, direct light through a recess.

mod common;

use std::fmt::Write as _;

/// An axis-aligned box of six outward-facing polygons (as genbox writes them), corner `lo`,
/// size `d`.
fn boxed(m: &str, name: &str, lo: [f64; 3], d: [f64; 3]) -> String {
    let faces: [[[u8; 3]; 4]; 6] = [
        [[1, 0, 0], [1, 0, 1], [0, 0, 1], [0, 0, 0]],
        [[0, 0, 1], [0, 1, 1], [0, 1, 0], [0, 0, 0]],
        [[0, 1, 0], [1, 1, 0], [1, 0, 0], [0, 0, 0]],
        [[1, 1, 0], [0, 1, 0], [0, 1, 1], [1, 1, 1]],
        [[1, 0, 1], [1, 0, 0], [1, 1, 0], [1, 1, 1]],
        [[0, 1, 1], [0, 0, 1], [1, 0, 1], [1, 1, 1]],
    ];
    let mut s = String::new();
    for (f, face) in faces.iter().enumerate() {
        write!(s, "{m} polygon {name}.{f} 0 0 12").unwrap();
        for c in face {
            for k in 0..3 {
                write!(s, " {}", lo[k] + c[k] as f64 * d[k]).unwrap();
            }
        }
        s.push('\n');
    }
    s
}

/// A 4 × 1 × 4 wall (y from 0 to 1) of modifier `wall`, a hole through it (x −1.5…−0.5),
/// recesses ending inside it (at y = .5), an antimatter box in free space and one starting
/// inside the wall, all of antimatter `hole` clipping `wall`.
fn walls(wall_mat: &str) -> String {
    let mut s = String::from(wall_mat);
    s += &boxed("wall", "w", [-2.0, 0.0, -2.0], [4.0, 1.0, 4.0]);
    s += "void antimatter hole 1 wall 0 0\n";
    s += &boxed("hole", "a", [-1.5, -0.5, -0.5], [1.0, 2.0, 1.0]);
    s += &boxed("hole", "b", [0.5, -0.5, -0.5], [1.0, 1.0, 1.0]);
    s += &boxed("hole", "c", [3.0, -2.0, -0.5], [1.0, 1.0, 1.0]);
    s += &boxed("hole", "d", [-1.5, 0.5, 1.0], [1.0, 1.0, 1.0]);
    s += &boxed("hole", "e", [0.5, -0.5, 1.0], [1.0, 1.0, 0.8]);
    s
}

/// Glowing surfaces only: each ray's value says which surface it ended on (red wall, green
/// plate embedded in the wall behind recess e, blue background), so the values must be equal.
#[test]
fn oracle_holes_and_recesses_are_seen_as_radiance_sees_them() {
    let mut s = walls("void glow wall 0 0 4 1 0 0 0\n");
    s += "void glow blue 0 0 4 0 0 1 0\n";
    s += "blue polygon bg 0 0 12  -10 5 -10  10 5 -10  10 5 10  -10 5 10\n";
    s += "void glow green 0 0 4 0 1 0 0\n";
    s += "green polygon emb 0 0 12  .5 .7 1  1.5 .7 1  1.5 .7 1.8  .5 .7 1.8\n";
    let Some((o, dir)) = common::probe::oracle_scene("antimatter", &s) else {
        return;
    };
    let rays = [
        "-1 -3 0 0 1 0",         // through the hole: background
        "-1 -3 0 0 1 0.1",       // through the hole, slanted
        "-1 -3 0.3 0.05 1 -0.1", // idem
        "1 -3 0 0 1 0",          // recess: its bottom, shaded as the wall
        "1 -3 0.2 0.1 1 0",      // recess, slanted
        "0 -3 0 0 1 0",          // plain wall
        "3.5 -3 0 0 1 0",        // antimatter in free space: background
        "-1 -3 1.5 0 1 0",       // wall in front of box d
        "-1 0.2 1.5 0 1 0",      // starts inside the wall, through box d: background
        "1 -3 1.4 0 1 0",        // recess e, green plate behind its bottom: the wall
    ]
    .join("\n")
        + "\n";
    let (t, f) = common::both_rtrace(&o, &dir, &["-h", "-ov"], &rays);
    assert_eq!(t.len(), 30);
    assert_eq!(t, f, "oracle vs ours, RGB per ray");
    // the cases are not all the same surface
    assert!(t.chunks(3).any(|c| c[2] == 1.0) && t.chunks(3).any(|c| c[0] == 1.0));
}

/// A plastic wall lit by a distant source in front: the bottom of a recess is lit (its
/// shadow rays pass the clipped wall face), with the reversed antimatter normal. `-ab 0`,
/// no jitter: both tools are deterministic; 6 printed digits and Radiance's single-precision
/// colours give the 2e-5 relative tolerance.
#[test]
fn oracle_recess_bottom_is_lit_through_the_antimatter() {
    let mut s = walls("void plastic wall 0 0 5 .5 .4 .3 0 0\n");
    s += "void light sun 0 0 3 1e4 1e4 1e4\nsun source s 0 0 4 .1 -1 .3 .5\n";
    let Some((o, dir)) = common::probe::oracle_scene("antimatter_lit", &s) else {
        return;
    };
    let rays = "1 -3 0 0 1 0\n0 -3 0 0 1 0\n1 -3 0.2 0.1 1 0\n-1 -3 0 0 1 0\n1 -3 1.4 0 1 0\n";
    for outs in [["-ov"], ["-oN"]] {
        let mut opts = vec!["-h", "-ab", "0", "-dj", "0"];
        opts.extend(outs);
        let (t, f) = common::both_rtrace(&o, &dir, &opts, rays);
        assert!(t.iter().any(|v| *v != 0.0));
        common::probe::agree_6_digits(&t, &f, |k| format!("{outs:?} value {k}: "));
    }
}

/// An antimatter naming an undefined modifier: a warning naming it, as Radiance's.
#[test]
fn unknown_antimatter_modifier_is_a_warning() {
    let s = "void glow red 0 0 4 1 0 0 0\nred polygon p 0 0 12 -1 1 -1 1 1 -1 1 1 1 -1 1 1\n\
             void antimatter hole 2 red nosuch 0 0\n"
        .to_string()
        + &boxed("hole", "a", [-0.5, 0.5, -0.5], [1.0, 1.0, 1.0]);
    let v = common::probe::rtrace_file(
        "antimatter_unknown",
        "scene.rad",
        &s,
        &["-h", "-ov"],
        b"0 0 0 0 1 0\n",
        &["nosuch", "scene.rad:3"],
    );
    // The ray passes the plate's front while blind to `red`, so it leaves the antimatter
    // "inside" red, and the exit face is shaded red (the reference rtrace gives 1 0 0 too).
    assert_eq!(v, vec![1.0, 0.0, 0.0]);
}
