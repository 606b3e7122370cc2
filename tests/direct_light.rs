//! Direct light from local sources against the reference rtrace (`-ab 0`, every sample
//! shadow-tested): spotlights' focal length.

mod common;

/// Spotlights whose light comes from a focus behind the source: Radiance scales a sample's
/// solid angle by d²/(d + f)², f = the length of the spotlight's direction vector.
const SCENE: &str = "
void plastic floor_m 0 0 5 .3 .3 .3 0 0
floor_m polygon floor 0 0 12 0 0 0 10 0 0 10 8 0 0 8 0
void plastic wall_m 0 0 5 .5 .5 .5 0 0
wall_m polygon w1 0 0 12 4.1 0 0 4.1 4.5 0 4.1 4.5 2.13 4.1 0 2.13
void spotlight unit 0 0 7 2000 2000 2000 90 0 0 -1
unit sphere s1 0 0 4 2 2 2.8 0.05
void spotlight long 0 0 7 1500 1400 1300 70 0.4 0 -2.5
long sphere s2 0 0 4 6 5 2.6 0.05
void spotlight short 0 0 7 900 900 900 120 0 0.1 -0.2
short sphere s3 0 0 4 8 2 2.9 0.04
";

#[test]
fn oracle_spotlight_focal_length() {
    let Some(oracle) = common::oracle() else {
        return;
    };
    let dir = common::scratch("spot_focus");
    std::fs::write(dir.join("scene.rad"), SCENE).unwrap();
    let mut rays = String::new();
    for p in 0..40 {
        let x = 0.35 + ((p * 7) % 19) as f64 * 0.5;
        let y = 0.3 + ((p * 11) % 15) as f64 * 0.5;
        rays.push_str(&format!("{x} {y} 0.7 0 0 1\n"));
    }
    let opts = ["-h", "-I+", "-ab", "0", "-dt", "0"];
    let (t, o) = common::both_rtrace(&oracle, &dir, &opts, &rays);
    let lit = t.iter().filter(|v| **v > 0.0).count();
    assert!(lit > 30, "only {lit} lit values");
    for (k, (a, b)) in t.iter().zip(&o).enumerate() {
        // Sphere sources: fenestra's solid angle is the exact cone 2π(1 − cos θ), sin θ = r/d,
        // Radiance's πr²/d²; their ratio is 1 + r²/4d² + O(r⁴/d⁴), so each lamp's light is
        // that much higher in fenestra and a point's value, a weighted mean over the lamps,
        // at most the largest of them: over these 40 points 1.40e-4 (s1, r = .05 at 2.1 m),
        // and 1.73e-4 anywhere on the plane z = .7 (under s2, r = .05 at 1.9 m). 2e-4 is
        // that bound plus room for the 7 printed digits (1e-6); measured here: 9.3e-6 to
        // 1.40e-4 (6e-5 to 9.4e-5 while fenestra's -I took the point itself, 1e-4 below
        // Radiance's, which partly offset the gap). Before the focus was modelled, a spotlight with a unit direction vector
        // gave 2.0 to 2.1 times Radiance's values.
        assert!(
            (a - b).abs() <= 2e-4 * a.abs() + 1e-9,
            "value {k}: oracle {a} ours {b}"
        );
    }
}
