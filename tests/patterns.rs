//! Patterns through the .cal engine: rtrace with brightfunc/colorfunc patterns defined in
//! a user's .cal file, against the reference rtrace.

mod common;

use std::process::Command;

fn run(cmd: Command, input: &str) -> std::process::Output {
    common::run_stdin(cmd, input.as_bytes())
}

const CAL: &str = "{ test patterns }
grad = 1 + Dz*Dz + A1*Dx;
band(x) = if(sin(x*A2), 1, .25);
rr = .5 + .5*band(Px);  gg = .5 + .5*band(Py);  bb = and(Pz + 1, 1 - Pz);
";

const SCENE: &str = "
void brightfunc skypat 2 grad pats.cal 0 1 .5
skypat glow skyglow 0 0 4 2 2 2 0
skyglow source sky 0 0 4 0 0 1 180

void colorfunc stripes 4 rr gg bb pats.cal 0 2 0 7
stripes plastic floor_mat 0 0 5 .6 .5 .4 0 0
floor_mat polygon floor 0 0 12  -5 -5 0  5 -5 0  5 5 0  -5 5 0

void light sunlit 0 0 3 1e5 1e5 1e5
sunlit source sun 0 0 4 .3 .2 1 .5
";

/// The records `rays(k, a)` for k = 0, 1, … n − 1 at angles a = k × `step`.
fn fan(n: u32, step: f64, rays: impl Fn(f64, f64) -> String) -> String {
    (0..n).map(|k| rays(k as f64, k as f64 * step)).collect()
}

/// Rays: some straight at the (patterned) sky, some down at the (patterned) floor.
fn rays() -> String {
    fan(24, 0.26, |_, a| {
        let sky = format!("0 0 1 {} {} {}\n", a.cos() * 0.6, a.sin() * 0.6, 0.8);
        let floor = format!(
            "{} {} 2 {} {} -1\n",
            a.cos() * 0.3,
            a.sin(),
            a.sin() * 0.4,
            a.cos() * 0.2
        );
        sky + &floor
    })
}

#[test]
fn oracle_cal_patterns_match_rtrace() {
    let Some((oracle, dir)) = common::probe::oracle_scene("patterns", SCENE) else {
        return;
    };
    std::fs::write(dir.join("pats.cal"), CAL).unwrap();
    // -ab 0 and no jitter (-dj 0, -ds 0): direct light and sky values are deterministic.
    let opts = ["-h", "-ab", "0", "-dj", "0", "-ds", "0", "-u-"];
    let (t, o) = common::both_rtrace(&oracle, &dir, &opts, &rays());
    assert!(t.iter().any(|v| *v > 0.0));
    // rtrace prints 6 significant digits and keeps colours in single precision.
    common::probe::agree_6_digits(&t, &o, |k| format!("value {k}: "));
}

#[test]
fn pattern_errors_are_clear() {
    let dir = common::scratch("patterns_bad");
    std::fs::write(dir.join("p.cal"), "f = nosuchname * 2;\n").unwrap();
    let cases = [
        ("void brightfunc b 2 f p.cal 0 0\nb glow g 0 0 4 1 1 1 0\ng source s 0 0 4 0 0 1 180\n", "nosuchname"),
        ("void brightfunc b 2 f missing.cal 0 0\nb glow g 0 0 4 1 1 1 0\ng source s 0 0 4 0 0 1 180\n", "missing.cal"),
        // Radiance ignores words after a pattern's transform that are not transform options;
        // fenestra reports them.
        ("void brightfunc b 4 f p.cal -bogus 90 0 0\nb glow g 0 0 4 1 1 1 0\ng source s 0 0 4 0 0 1 180\n", "-bogus"),
        ("void brightfunc b 4 f p.cal -s 0 0 0\nb glow g 0 0 4 1 1 1 0\ng source s 0 0 4 0 0 1 180\n", "singular"),
    ];
    for (k, (text, what)) in cases.iter().enumerate() {
        std::fs::write(dir.join("s.rad"), text).unwrap();
        let mut c = common::fenestra("rtrace");
        c.args(["-h", "s.rad"]).current_dir(&dir);
        let o = run(c, "0 0 0 0 0 1\n");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "case {k}");
        assert!(o.stdout.is_empty(), "case {k}");
        assert!(
            err.contains(what) && err.contains("s.rad:1"),
            "case {k}: {err}"
        );
    }
}

/// Transform arguments after a pattern's strings: every ray variable in the pattern's
/// frame (`D N P T Ts Rdot S Tx Ty Tz I J K`) for a rotated, translated and scaled frame,
/// a negative scale, and a mirror with a repeated group, plus a brightdata pattern with a
/// transform, against the reference rtrace.
#[test]
fn oracle_pattern_transforms_match_rtrace() {
    let Some((oracle, dir)) = common::cli::oracle_scratch("patterns_xf") else {
        return;
    };
    std::fs::write(dir.join("ramp.dat"), "1\n-3 3 5\n1 2 4 3 2.5\n").unwrap();
    let vars = [
        "Dx", "Dy", "Dz", "Nx", "Ny", "Nz", "Px", "Py", "Pz", "T", "Ts", "Rdot", "S", "Tx", "Ty",
        "Tz", "Ix", "Iy", "Iz", "Jx", "Jy", "Jz", "Kx", "Ky", "Kz",
    ];
    let rays = "0.3 0.2 2 0.1 0.2 -1\n-1 0.5 3 0.3 -0.1 -1\n2 -1 1 -0.4 0.3 -1\n";
    for xf in ["-rz 30 -t 1 2 3 -s 2 -rx 20", "-s -2", "-mx -i 2 -rz 10"] {
        let nxf = xf.split_whitespace().count();
        for chunk in vars.chunks(3) {
            let mut cal = String::new();
            for c in 0..3 {
                // offset 10 keeps every value positive (rtrace prints colours, not signs)
                cal.push_str(&format!("v{c} = {} + 10;\n", chunk.get(c).unwrap_or(&"0")));
            }
            std::fs::write(dir.join("xf.cal"), &cal).unwrap();
            let scene = format!(
                "void colorfunc pat {} v0 v1 v2 xf.cal {xf} 0 0\n\
                 pat glow g 0 0 4 1 1 1 0\n\
                 g polygon floor 0 0 12  -5 -5 0  5 -5 0  5 5 0  -5 5 0\n",
                4 + nxf
            );
            std::fs::write(dir.join("scene.rad"), scene).unwrap();
            let (t, o) = common::both_rtrace(&oracle, &dir, &["-h", "-ab", "0", "-u-"], rays);
            assert_eq!(t.len(), 9);
            // 6 printed digits; single-precision colours in Radiance.
            common::probe::agree_6_digits(&t, &o, |j| {
                format!(
                    "{xf}: {} on ray {}: ",
                    chunk.get(j % 3).unwrap_or(&"0"),
                    j / 3
                )
            });
        }
    }
    let scene = "void brightdata ramp 10 noneg ramp.dat . Px -rz 30 -t 1 0 0\n0\n0\n\
                 ramp glow g 0 0 4 1 1 1 0\ng polygon floor 0 0 12  -5 -5 0  5 -5 0  5 5 0  -5 5 0\n";
    std::fs::write(dir.join("scene.rad"), scene).unwrap();
    let mut rays = String::new();
    for k in 0..20 {
        rays.push_str(&format!(
            "{} {} 1 0 0 -1\n",
            k as f64 * 0.4 - 4.0,
            k as f64 * 0.2 - 2.0
        ));
    }
    let (t, o) = common::both_rtrace(&oracle, &dir, &["-h", "-ab", "0", "-u-"], &rays);
    assert_eq!(t.len(), 60);
    common::probe::agree_6_digits(&t, &o, |k| format!("brightdata, value {k}: "));
}

#[test]
fn oracle_data_patterns_match_rtrace() {
    let scene = "
void colordata illum_mat.dist
9 red green blue ill_glassR.dat ill_glassG.dat ill_glassB.dat illum.cal il_alth il_azih
0
9 -1 0 0  0 0 1  0 1 0
illum_mat.dist glow panel 0 0 4 1 1 1 0
panel polygon win 0 0 12  3 0 .9  3 0 2.4  1 0 2.4  1 0 .9

void brightdata ramp 4 noneg ramp.dat . 2*Dx
0
0
ramp glow wall 0 0 4 .5 .5 .5 0
wall polygon back 0 0 12  -2 5 3  2 5 3  2 5 0  -2 5 0
";
    let Some((oracle, dir)) = common::probe::oracle_scene("datapatterns", scene) else {
        return;
    };
    for c in ["R", "G", "B"] {
        let f = format!("ill_glass{c}.dat");
        std::fs::copy(common::fixture("datapattern").join(&f), dir.join(&f)).unwrap();
    }
    // A 1-D file for brightdata, with coordinates beyond its ends (linear extension).
    std::fs::write(dir.join("ramp.dat"), "1\n-.5 .5 5\n1 2 4 3 2.5\n").unwrap();
    let rays = fan(40, 0.157, |k, a| {
        // from inside the room (y < 0) toward the window panel at y = 0
        let window = format!("2 -1.5 1.6 {} 1 {}\n", a.cos() * 0.6, a.sin() * 0.4);
        // toward the far wall at y = 5, Dx spanning beyond [-.5, .5]
        window + &format!("0 0 1.5 {} 1 0\n", (k - 20.0) / 50.0)
    });
    let opts = ["-h", "-ab", "0", "-u-"];
    let (t, o) = common::both_rtrace(&oracle, &dir, &opts, &rays);
    assert_eq!(t.len(), o.len());
    assert!(t.iter().filter(|v| **v > 0.0).count() > 100);
    // 6 printed digits; single-precision colours in Radiance.
    common::probe::agree_6_digits(&t, &o, |k| format!("value {k} (ray {}): ", k / 3));
}

/// `-e` and `-f` definitions are visible to every pattern (Radiance's global context).
#[test]
fn oracle_e_and_f_reach_patterns() {
    let scene = "void brightfunc sp 2 skyv . 0 0\nsp glow g 0 0 4 1 .8 .6 0\n\
                 g source s 0 0 4 0 0 1 180\n";
    let Some((oracle, dir)) = common::probe::oracle_scene("patterns_ef", scene) else {
        return;
    };
    std::fs::write(dir.join("defs.cal"), "shape(z) = 1 + gain*z*z;\n").unwrap();
    let opts = [
        "-h",
        "-ab",
        "0",
        "-u-",
        "-f",
        "defs.cal",
        "-e",
        "gain=3;skyv=shape(Dz)",
    ];
    let rays: String = (0..10)
        .map(|k| format!("0 0 0 {} 0 1\n", k as f64 * 0.3))
        .collect();
    let (t, o) = common::both_rtrace(&oracle, &dir, &opts, &rays);
    assert_eq!(t.len(), 30);
    common::probe::agree_6_digits(&t, &o, |_| String::new());
}
