//! Radiance's rules for odd but valid geometry and rtrace's first-hit outputs, found by a
//! differential sweep: a ring whose radii come in the wrong order is kept (the larger is
//! the outer), negative radii turn a cylinder, tube, cone or cup inside out (with a
//! warning) instead of dropping it, `-oN` is the surface's own normal while `-on` faces
//! the ray, both are zero where nothing is hit, and the header's NCOMP counts the numbers
//! of a record.

mod common;

const SCENE: &str = "void plastic m 0 0 5 .5 .5 .5 0 0
void glow g 0 0 4 1 1 1 0
g source s 0 0 4 0 0 1 90
m cylinder c1 0 0 7 0 0 0 0 0 1 -1
m tube t1 0 0 7 10 0 0 10 0 1 -1
m cone k1 0 0 8 20 0 0 20 0 1 -1 -2
m cone k2 0 0 8 30 0 0 30 0 1 2 1
m cup k3 0 0 8 40 0 0 40 0 1 -2 -1
m ring r1 0 0 8 50 0 0 0 0 1 2 1
m polygon p 0 0 12 60 -1 0 62 -1 0 62 1 0 60 1 0
m sphere sp 0 0 4 70 0 0 1
";

/// From outside and inside each shape, onto the ring and the polygon from both sides, into
/// the sphere, one ray onto the distant source (the upper hemisphere) and one down that hits
/// nothing. Deterministic (`-ab 0`, first hits): within 1e-6 relative (and 1e-9 absolute) of
/// the oracle's printed digits, which covers their last digit's rounding.
const RAYS: &str = "5 0 .5 -1 0 0\n0 0 .5 1 0 0\n15 0 .5 -1 0 0\n10 0 .5 1 0 0\n\
25 0 .5 -1 0 0\n20 0 .5 1 0 0\n35 0 .5 -1 0 0\n45 0 .5 -1 0 0\n40 0 .5 1 0 0\n\
51.5 0 5 0 0 -1\n61 0 1 0 0 -1\n61 0 -1 0 0 1\n68 0 0 1 0 0\n5 5 5 0 0 1\n5 5 5 0 0 -1\n";

/// Our rtrace alone: NCOMP counts the record's numbers (d 3, L 1, N 3, n 3), every inside-out
/// shape is warned about, and the ray that hits nothing gives zero normals (its distance is
/// Radiance's "infinite" 1e10).
#[test]
fn odd_radii_warnings_ncomp_and_a_miss() {
    let dir = common::scratch("geometry_rules_ours");
    std::fs::write(dir.join("scene.rad"), SCENE).unwrap();
    let mut c = common::fenestra("rtrace");
    c.args(["-ab", "0", "-odLNn", "scene.rad"])
        .current_dir(&dir);
    let out = common::run_stdin_ok(c, RAYS.as_bytes());
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(text.contains("NCOMP=10\n"), "{text}");
    let last = common::numbers(text.lines().last().unwrap().as_bytes());
    assert_eq!(last.len(), 10, "{text}");
    assert!(
        last[3] >= 1e10 && last[4..].iter().all(|v| *v == 0.0),
        "the miss: {last:?}"
    );
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    for w in [
        "cylinder 'c1': negative radius",
        "tube 't1': negative radius",
        "cone 'k1': negative radii",
        "cup 'k3': negative radii",
    ] {
        assert!(err.contains(w), "{err}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn oracle_odd_radii_and_first_hit_normals() {
    let Some(oracle) = common::oracle() else {
        return;
    };
    let dir = common::scratch("geometry_rules");
    std::fs::write(dir.join("scene.rad"), SCENE).unwrap();
    let (t, o) = common::both_rtrace(&oracle, &dir, &["-h", "-ab", "0", "-odLNn"], RAYS);
    common::agree("-odLNn", &t, &o, 1e-6, 1e-9);
    let _ = std::fs::remove_dir_all(&dir);
}

/// pcomb's `nfiles` is the number of inputs; xform refuses an array of 0 copies, as
/// Radiance's ("missing count for -a option").
#[test]
fn pcomb_nfiles_and_xform_zero_array() {
    let dir = common::scratch("geometry_rules_misc");
    let mut c = common::fenestra("pcomb");
    c.args(["-x", "2", "-y", "2", "-e", "lo=nfiles+1"]);
    let pic = common::run_ok(&mut c);
    let p = fenestra_formats::picture::Picture::read(&mut &pic[..], "pcomb").unwrap();
    // no input files: nfiles + 1 = 1 in every channel of the 4 pixels (to RGBE's 1/128)
    assert_eq!(p.pixels.len(), 4);
    assert!(
        p.pixels
            .iter()
            .flatten()
            .all(|v| (v - 1.0).abs() <= 1.0 / 128.0),
        "{:?}",
        p.pixels
    );
    std::fs::write(dir.join("x.rad"), "void plastic m 0 0 5 .5 .5 .5 0 0\n").unwrap();
    let mut x = common::fenestra("xform");
    x.args(["-a", "0", "-t", "1", "0", "0", "x.rad"])
        .current_dir(&dir);
    let out = x.output().unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("missing count for -a option"));
    assert!(out.stdout.is_empty());
    let _ = std::fs::remove_dir_all(&dir);
}

/// rtrace `-I`/`-i` with no value among the outputs fails, as Radiance's ("-I+ and -i+
/// options require some value output").
#[test]
fn irradiance_without_a_value_output_is_an_error() {
    let dir = common::scratch("geometry_rules_irr");
    std::fs::write(dir.join("scene.rad"), SCENE).unwrap();
    for opt in ["-i", "-I"] {
        let mut c = common::fenestra("rtrace");
        c.args(["-h", opt, "-oL", "scene.rad"]).current_dir(&dir);
        let out = common::run_stdin(c, b"1 0 5 0 0 -1\n");
        assert!(!out.status.success(), "{opt}");
        assert!(String::from_utf8_lossy(&out.stderr).contains("require some value output"));
        assert!(out.stdout.is_empty());
    }
    let _ = std::fs::remove_dir_all(&dir);
}
