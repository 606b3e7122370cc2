//! pcomb from the command line and against the oracle's pcomb.

mod common;

use std::process::Command;

fn vimg(n: u32) -> String {
    common::fixture(&format!("picture/vimg/v{n:03}.hdr"))
        .display()
        .to_string()
}

/// The output with the CAPDATE/GMT lines (clock dependent) removed.
fn stable(out: &[u8]) -> Vec<u8> {
    let end = out
        .windows(2)
        .position(|w| w == b"\n\n")
        .map_or(0, |p| p + 1);
    let head = String::from_utf8_lossy(&out[..end]);
    let mut v: Vec<u8> = head
        .lines()
        .filter(|l| !l.starts_with("CAPDATE=") && !l.starts_with("GMT="))
        .flat_map(|l| format!("{l}\n").into_bytes())
        .collect();
    v.extend_from_slice(&out[end..]);
    v
}

fn both(o: &common::Oracle, args: &[String], dir: &std::path::Path) -> (Vec<u8>, Vec<u8>) {
    let run = |mut c: Command| {
        c.current_dir(dir);
        stable(&common::run_ok(c.args(args)))
    };
    (run(o.command("pcomb")), run(common::fenestra("pcomb")))
}

fn words(s: &str) -> Vec<String> {
    s.split_whitespace().map(str::to_string).collect()
}

/// Header (except the clock lines) and pixels byte-identical: sums are formed in the
/// same precision and order as Radiance's (float coefficients, double sum).
#[test]
fn oracle_pcomb_sums_are_byte_identical() {
    let Some(o) = common::oracle() else { return };
    let dir = common::scratch("pcomb-oracle");
    // A picture with a view and an exposure, and a rotated one, made by the oracle.
    std::fs::copy(vimg(3), dir.join("a.hdr")).unwrap();
    let exp = common::run_ok(o.command("pfilt").args(["-1", "-e", "2"]).arg(vimg(7)));
    std::fs::write(dir.join("e.hdr"), exp).unwrap();
    let rot = common::run_ok(o.command("protate").arg(vimg(9)));
    std::fs::write(dir.join("r.hdr"), rot).unwrap();
    let mat = common::run_ok(o.command("pcomb").args(["-ff", "-s", "-1"]).arg(vimg(11)));
    std::fs::write(dir.join("m.f"), mat).unwrap();
    let (v0, v1, v2) = (vimg(0), vimg(1), vimg(2));
    let cases = [
        v0.to_string(),
        format!("-s 2 {v0} -c 1 2 3 {v1}"),
        format!("-s 0.3 {v0} -s -0.7 {v1} -c 0.1 5 100 {v2}"),
        format!("-ff -s 0.3 {v0} -s -0.7 {v1}"),
        format!("-h {v0} a.hdr"),
        "e.hdr".to_string(),
        "-o e.hdr -s 3 e.hdr".to_string(),
        "-ff -o e.hdr".to_string(),
        format!("-x 16 -y 13 {v0}"),
        format!("-x 47 -y 31 {v2}"),
        "-c 1 2 3 r.hdr".to_string(),
        "-x 3 -y 2".to_string(),
        "-ff -x 3 -y 2".to_string(),
        "m.f".to_string(),
        "-s 2 m.f -s -1 m.f".to_string(),
        "!cat a.hdr".to_string(),
    ];
    for c in &cases {
        let args = if c.starts_with('!') {
            vec![c.clone()]
        } else {
            words(c)
        };
        let (want, got) = both(&o, &args, &dir);
        assert!(want == got, "pcomb {c}: output differs");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn size_mismatch_and_bad_input_are_clear_errors() {
    let dir = common::scratch("pcomb-errors");
    let small = common::run_ok(common::fenestra("pcomb").args(["-x", "3", "-y", "2"]));
    std::fs::write(dir.join("small.hdr"), small).unwrap();
    for (args, want) in [
        (vec![vimg(0), "small.hdr".into()], "resolution mismatch"),
        (vec![], "illegal output resolution"),
        (vec!["missing.hdr".into()], "missing.hdr"),
        (vec!["-e".into(), "ro=nosuch".into(), vimg(0)], "nosuch"),
        (
            vec!["-x".into(), "0".into(), "-y".into(), "2".into()],
            "-x 0",
        ),
    ] {
        let mut c = common::fenestra("pcomb");
        c.current_dir(&dir).args(&args);
        let (stdout, err) = common::output_err(&mut c, &format!("{args:?}"));
        assert!(stdout.is_empty(), "{args:?}: no partial output");
        assert!(
            err.starts_with("pcomb: fatal - ") && err.contains(want),
            "{args:?}: {err}"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn scaled_sum_has_expected_values() {
    use fenestra_formats::picture::Picture;
    let out = common::run_ok(common::fenestra("pcomb").args([
        "-s",
        "0.5",
        &vimg(4),
        "-s",
        "0.5",
        &vimg(4),
    ]));
    let p = Picture::read(&mut out.as_slice(), "t").unwrap();
    let f = std::fs::File::open(vimg(4)).unwrap();
    let q = Picture::read(&mut std::io::BufReader::new(f), "t").unwrap();
    assert_eq!(
        p.pixels, q.pixels,
        "halves of the same picture sum back exactly"
    );
}

/// Expressions (`-e`, `-f`): channels, luminance, offsets, positions, sizes, input
/// count, -s/-c/-o seen by ri(n), expression resolutions; byte-identical with Radiance's
/// (expressions in double, pixels stored in single precision as in Radiance).
#[test]
fn oracle_pcomb_expressions_are_byte_identical() {
    let Some(o) = common::oracle() else { return };
    let dir = common::scratch("pcomb-expr");
    std::fs::write(
        dir.join("e.cal"),
        "sat(v) = if(v - 1, 1, v);\nro = sat(ri(1)*3);\n",
    )
    .unwrap();
    let exp = common::run_ok(o.command("pfilt").args(["-1", "-e", "2"]).arg(vimg(7)));
    std::fs::write(dir.join("e.hdr"), exp).unwrap();
    let (v0, v1) = (vimg(0), vimg(1));
    let cases: Vec<Vec<String>> = vec![
        vec![
            "-e".into(),
            "ro=ri(1)*2;go=gi(2);bo=bi(1)+bi(2)".into(),
            v0.clone(),
            v1.clone(),
        ],
        vec!["-e".into(), "lo=li(1)".into(), v0.clone()],
        vec![
            "-e".into(),
            "ro=ri(1,1,0);go=gi(1,0,-1);bo=ri(0)".into(),
            v0.clone(),
        ],
        vec![
            "-e".into(),
            "ro=x/xres;go=y/yres;bo=xmax/ymax".into(),
            "-s".into(),
            "2".into(),
            v0.clone(),
        ],
        vec![
            "-e".into(),
            "go=WE*PI".into(),
            "-c".into(),
            "1".into(),
            "2".into(),
            "3".into(),
            v1.clone(),
        ],
        vec!["-f".into(), "e.cal".into(), v0.clone()],
        vec![
            "-e".into(),
            "ro=le(1);go=pa(1);bo=ri(1)".into(),
            "-o".into(),
            "e.hdr".into(),
        ],
        vec![
            "-x".into(),
            "xmax/2".into(),
            "-y".into(),
            "ymax/2".into(),
            "-e".into(),
            "lo=li(1)".into(),
            v0.clone(),
        ],
        vec![
            "-ff".into(),
            "-e".into(),
            "ro=-ri(1);go=0;bo=1/3".into(),
            v0.clone(),
        ],
        vec![
            "-x".into(),
            "5".into(),
            "-y".into(),
            "4".into(),
            "-e".into(),
            "ro=x;go=y;bo=1".into(),
        ],
    ];
    for args in &cases {
        let (want, got) = both(&o, args, &dir);
        assert!(want == got, "pcomb {args:?}: output differs");
    }
    std::fs::remove_dir_all(&dir).ok();
}
