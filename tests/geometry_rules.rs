//! Radiance's rules for odd but valid geometry and rtrace's first-hit outputs, found by a
//! differential sweep: a ring whose radii come in the wrong order is kept (the larger is
//! the outer), negative radii turn a cylinder, tube, cone or cup inside out (with a
//! warning) instead of dropping it, `-oN` is the surface's own normal while `-on` faces
//! the ray, both are zero where nothing is hit, and the header's NCOMP counts the numbers
//! of a record.

mod common;

const SCENE: &str = "void plastic m 0 0 5 .5 .5 .5 0 0
void glow g 0 0 4 1 1 1 0
g source s 0 0 4 0 0 1 180
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
/// the sphere, and one ray that hits nothing. Deterministic (`-ab 0`, first hits): the same
/// printed digits as the oracle's, a zero's sign aside.
const RAYS: &str = "5 0 .5 -1 0 0\n0 0 .5 1 0 0\n15 0 .5 -1 0 0\n10 0 .5 1 0 0\n\
25 0 .5 -1 0 0\n20 0 .5 1 0 0\n35 0 .5 -1 0 0\n45 0 .5 -1 0 0\n40 0 .5 1 0 0\n\
51.5 0 5 0 0 -1\n61 0 1 0 0 -1\n61 0 -1 0 0 1\n68 0 0 1 0 0\n5 5 5 0 0 1\n";

#[test]
fn oracle_odd_radii_and_first_hit_normals() {
    let Some(oracle) = common::oracle() else {
        return;
    };
    let dir = common::scratch("geometry_rules");
    std::fs::write(dir.join("scene.rad"), SCENE).unwrap();
    let (t, o) = common::both_rtrace(&oracle, &dir, &["-h", "-ab", "0", "-odLNn"], RAYS);
    common::agree("-odLNn", &t, &o, 1e-6, 1e-9);
    // NCOMP counts the record's numbers (d 3, L 1, N 3, n 3)
    let mut c = common::fenestra("rtrace");
    c.args(["-ab", "0", "-odLNn", "scene.rad"])
        .current_dir(&dir);
    let out = common::run_stdin_ok(c, b"");
    let head = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(head.contains("NCOMP=10\n"), "{head}");
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    for w in [
        "cylinder 'c1': negative radius",
        "cone 'k1': negative radii",
    ] {
        assert!(err.contains(w), "{err}");
    }
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
    assert!(pic.starts_with(b"#?RADIANCE"));
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
