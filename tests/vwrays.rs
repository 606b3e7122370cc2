//! vwrays from the command line, and differential tests against the oracle's vwrays.

mod common;

use std::io::Write;
use std::process::{Command, Stdio};

fn vf() -> String {
    common::fixture("vwrays/view.vf").display().to_string()
}

fn ours(args: &[&str]) -> Vec<u8> {
    common::run_ok(common::fenestra("vwrays").args(args))
}

fn with_stdin(mut cmd: Command, input: &str) -> Vec<u8> {
    let mut child = cmd
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .expect("spawn");
    child
        .stdin
        .take()
        .unwrap()
        .write_all(input.as_bytes())
        .unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success(), "{cmd:?}");
    out.stdout
}

#[test]
fn documented_examples() {
    let out = String::from_utf8(ours(&[
        "-x", "2", "-y", "2", "-vtv", "-vp", "0", "0", "0", "-vd", "0", "1", "0", "-vu", "0", "0",
        "1", "-vh", "90", "-vv", "90",
    ]))
    .unwrap();
    assert_eq!(
        out.lines().next().unwrap(),
        "0.00000e+00 0.00000e+00 0.00000e+00 -4.08248e-01 8.16497e-01 4.08248e-01"
    );
    let d = ours(&[
        "-d", "-x", "100", "-y", "50", "-vtv", "-vh", "60", "-vv", "60", "-va", "10",
    ]);
    assert_eq!(String::from_utf8(d).unwrap(), "-x 50 -y 50 -ld+\n");
    let d = ours(&["-d", "-vf", &vf(), "-x", "32", "-y", "32"]);
    assert_eq!(String::from_utf8(d).unwrap(), "-x 32 -y 26\n");
    let one = ours(&["-x", "3", "-y", "1", "-vta", "-vh", "180", "-vv", "180"]);
    assert_eq!(String::from_utf8(one).unwrap().lines().count(), 1);
}

#[test]
fn formats_repeat_and_stdin() {
    let f = ours(&["-ff", "-x", "4", "-y", "3", "-pa", "0", "-c", "2"]);
    assert_eq!(f.len(), 4 * 3 * 2 * 6 * 4);
    let d = ours(&["-fd", "-x", "4", "-y", "3", "-pa", "0"]);
    assert_eq!(d.len(), 4 * 3 * 6 * 8);
    let mut c = common::fenestra("vwrays");
    c.args(["-i", "-x", "2", "-y", "2", "-vtv"]);
    let out = String::from_utf8(with_stdin(c, "0.5 0.5\n1 1\n")).unwrap();
    let first: Vec<&str> = out.lines().next().unwrap().split(' ').collect();
    assert_eq!(first[3..], ["0.00000e+00", "1.00000e+00", "0.00000e+00"]);
}

#[test]
fn jitter_is_reproducible() {
    let a = ours(&["-pj", "0.7", "-c", "3", "-x", "8", "-y", "8", "-ff"]);
    let b = ours(&["-pj", "0.7", "-c", "3", "-x", "8", "-y", "8", "-ff"]);
    assert_eq!(a, b);
    let p = ours(&["-pj", "0", "-x", "8", "-y", "8", "-ff"]);
    assert_ne!(a.len(), p.len());
}

#[test]
fn bad_input_gives_clear_errors() {
    for (args, want) in [
        (&["-x", "0", "-vtv"][..], "bad x resolution"),
        (&["-vtq"][..], "unknown view type"),
        (
            &["-vu", "0", "1", "0"][..],
            "view up parallel to view direction",
        ),
        (&["-vf", "no/such.vf"][..], "no/such.vf"),
        (&["-fz"][..], "-fz"),
    ] {
        let out = common::fenestra("vwrays").args(args).output().unwrap();
        assert!(!out.status.success(), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("vwrays: fatal - ") && err.contains(want),
            "{args:?}: {err}"
        );
    }
    let mut c = common::fenestra("vwrays");
    c.args(["-i", "-vtv"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let mut child = c.spawn().unwrap();
    child.stdin.take().unwrap().write_all(b"1 x\n").unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(!out.status.success());
}

/// Every view type, with shift/lift, clipping, odd sizes and aspect handling.
fn cases() -> Vec<Vec<String>> {
    let vf = vf();
    let mut all = Vec::new();
    let mut push = |s: String| all.push(s.split_whitespace().map(str::to_string).collect());
    for t in ["v", "l", "a", "h", "s", "c"] {
        push(format!("-vt{t} -vp 1 2 3 -vd 0.3 -1 0.2 -vu 0 0 1 -vh 100 -vv 80 -vs 0.1 -vl -0.2 -x 37 -y 29 -pa 0"));
        push(format!(
            "-vt{t} -vf {vf} -vh 170 -vv 150 -x 40 -y 40 -vo 0.5 -va 7"
        ));
        push(format!("-vt{t} -vh 120 -vv 60 -x 17 -y 33 -d"));
    }
    push(format!("-vf {vf} -x 32 -y 32"));
    push("-vts -vp 100 50 -75 -vo 10 -va 1000 -vh 160 -vv 130 -x 20 -y 20 -vu 0 -1 0 -vd .358 -.8851 1.152".into());
    push("-vtc -vh 360 -vv 90 -x 64 -y 32".into());
    push("-vta -vh 360 -vv 360 -x 16 -y 16".into());
    push("-vth -vh 180 -vv 180 -x 4 -y 4".into());
    push("-x 5 -y 5 -c 3".into());
    push("-x 1 -y 1".into());
    all
}

#[test]
fn oracle_vwrays_ascii_is_byte_identical() {
    let Some(o) = common::oracle() else { return };
    for args in cases() {
        let want = common::run_ok(o.command("vwrays").args(&args));
        let got = common::run_ok(common::fenestra("vwrays").args(&args));
        assert!(want == got, "vwrays {}: output differs", args.join(" "));
    }
}

/// Binary output: perspective, parallel, cylindrical and angular views agree to the bit
/// (sums grouped as the reference build evaluates them). Hemispherical and planisphere
/// views may differ by one unit in the last place in -fd: the reference computes their
/// image-plane scale with glibc's vector sin/cos (libmvec), which rounds differently
/// from the scalar functions; float32 output absorbs that.
#[test]
fn oracle_vwrays_binary() {
    let Some(o) = common::oracle() else { return };
    let vf = vf();
    for t in ["v", "l", "a", "h", "s", "c"] {
        for fmt in ["-ff", "-fd"] {
            let args: Vec<String> =
                format!("{fmt} -vt{t} -vf {vf} -vh 100 -vv 100 -x 32 -y 32 -vo 1 -va 9 -vs 0.05")
                    .split_whitespace()
                    .map(str::to_string)
                    .collect();
            let want = common::run_ok(o.command("vwrays").args(&args));
            let got = common::run_ok(common::fenestra("vwrays").args(&args));
            assert_eq!(want.len(), got.len(), "{args:?}");
            if fmt == "-ff" || !matches!(t, "h" | "s") {
                assert!(want == got, "vwrays {}: output differs", args.join(" "));
                continue;
            }
            for (a, b) in want.chunks_exact(8).zip(got.chunks_exact(8)) {
                let a = i64::from_ne_bytes(a.try_into().unwrap());
                let b = i64::from_ne_bytes(b.try_into().unwrap());
                assert!((a - b).abs() <= 2, "{args:?}: more than 2 ulp apart");
            }
        }
    }
}

#[test]
fn oracle_vwrays_stdin_positions() {
    let Some(o) = common::oracle() else { return };
    let input = "0.5 0.5\n1 1\n3.25 7.75\n-1 2\n19 9\n";
    let args = ["-i", "-x", "20", "-y", "10", "-vf", &vf()];
    let mut c = o.command("vwrays");
    c.args(args);
    let want = with_stdin(c, input);
    let mut c = common::fenestra("vwrays");
    c.args(args);
    assert_eq!(with_stdin(c, input), want);
}

/// A view so wide that the aspect adjustment leaves no row (or column): Radiance prints
/// the empty resolution with -d (with -ld+ for a view with an aft plane, and also with -i),
/// no rays otherwise, and succeeds; so do we (with a warning). Pixel positions read with -i
/// would give NaN rays there: that stays an error (empty_resolution_with_positions_fails).
#[test]
fn oracle_vwrays_resolution_reduced_to_nothing() {
    let Some(o) = common::oracle() else { return };
    for args in [
        &["-x", "100", "-y", "1", "-vtv", "-vh", "90", "-vv", "0.1"][..],
        &[
            "-x", "100", "-y", "1", "-vtv", "-vh", "90", "-vv", "0.1", "-d",
        ],
        &[
            "-x", "1", "-y", "100", "-vtv", "-vh", "0.1", "-vv", "90", "-d",
        ],
        &[
            "-x", "100", "-y", "1", "-vtv", "-vh", "90", "-vv", "0.1", "-d", "-i",
        ],
        &[
            "-x", "100", "-y", "1", "-vtv", "-vh", "90", "-vv", "0.1", "-va", "3", "-d",
        ],
    ] {
        let theirs = common::run_ok(o.command("vwrays").args(args));
        assert_eq!(ours(args), theirs, "vwrays {args:?}");
    }
}

/// Pixel positions read (-i) for a view whose aspect leaves no row: an error naming the
/// resolution, and no rays (Radiance writes NaN rays).
#[test]
fn empty_resolution_with_positions_fails() {
    let mut c = common::fenestra("vwrays");
    c.args([
        "-i", "-x", "100", "-y", "1", "-vtv", "-vh", "90", "-vv", "0.1",
    ]);
    let out = common::run_stdin(c, b"5 0\n");
    assert!(!out.status.success() && out.stdout.is_empty());
    assert!(String::from_utf8_lossy(&out.stderr).contains("100 x 0"));
}
