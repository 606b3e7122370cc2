//! Planar mirrors relay distant sources (Radiance's virtual sources, `-dr`): sunlight
//! reflected by a mirror reaches the floor in front of it.

mod common;

const SCENE: &str = "
void light solar 0 0 3 1e6 1e6 1e6
solar source sun 0 0 4 0.5 0 0.866 0.5
void plastic floor_m 0 0 5 .3 .3 .3 0 0
floor_m polygon floor 0 0 12  -10 -10 0  10 -10 0  10 10 0  -10 10 0
void mirror mir 0 0 3 .9 .8 .7
mir polygon m1 0 0 12  -1 -1 1  -1 1 1  -1 1 3  -1 -1 3
void plastic wall_m 0 0 5 .5 .5 .5 0 0
wall_m polygon wall 0 0 12  -4 -3 0  -4 3 0  -4 3 4  -4 -3 4
void glass pane 0 0 3 .8 .8 .8
pane polygon shield 0 0 12  2 -0.2 0.5  2 0.2 0.5  2 0.2 0.9  2 -0.2 0.9
";

/// Floor points in and out of the reflected patch (incl. one whose relayed path crosses a
/// glass pane), behind the mirror, and on its edge.
fn points() -> String {
    let mut s = String::new();
    for k in 0..24 {
        let x = -0.8 + k as f64 * 0.2;
        s.push_str(&format!(
            "{x} 0 0.01 0 0 1\n{x} 0.9 0.01 0 0 1\n{x} 1.3 0.01 0 0 1\n"
        ));
    }
    s.push_str("-3.9 0 1.5 1 0 0\n3.5 0 0.01 0 0 1\n");
    s
}

#[test]
fn oracle_mirror_relays_the_sun() {
    let Some((oracle, dir)) = common::probe::oracle_scene("mirror", SCENE) else {
        return;
    };
    // -ab 0, no jitter: direct light only, deterministic in both tools.
    for dr in ["2", "0"] {
        let opts = ["-h", "-I+", "-ab", "0", "-dj", "0", "-u-", "-dr", dr];
        let (t, o) = common::both_rtrace(&oracle, &dir, &opts, &points());
        let direct = 1e6 * 2.0 * std::f64::consts::PI * (1.0 - 0.25f64.to_radians().cos()) * 0.866;
        let lit = t.iter().filter(|v| **v > 1.2 * direct).count();
        if dr == "2" {
            assert!(lit > 10, "the reflected patch lights some points ({lit})");
        } else {
            assert_eq!(lit, 0, "-dr 0: no relayed light");
        }
        // Six printed digits and float colours.
        common::probe::agree_6_digits(&t, &o, |k| format!("-dr {dr}: value {k}: "));
    }
}
