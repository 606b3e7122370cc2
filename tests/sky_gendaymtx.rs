//! gendaymtx against the Radiance reference matrices (fixtures) and, for
//! generated cases, against the oracle's gendaymtx.

mod common;

use std::path::Path;
use std::process::Command;

/// Header lines after the command line, then the data, as text.
fn body(text: &str) -> Vec<&str> {
    text.lines().skip(2).collect()
}

/// Ascii matrices are printed with `%.3g`; the model runs in double and is
/// rounded once to float, so the printed digits must be identical.
fn assert_same_ascii(ours: &[u8], theirs: &[u8], what: &str) {
    let a = String::from_utf8_lossy(ours);
    let b = String::from_utf8_lossy(theirs);
    let (a, b) = (body(&a), body(&b));
    assert_eq!(a.len(), b.len(), "{what}: line count");
    let bad: Vec<_> = a
        .iter()
        .zip(&b)
        .enumerate()
        .filter(|(_, (x, y))| x != y)
        .take(5)
        .collect();
    assert!(bad.is_empty(), "{what}: differing lines {bad:?}");
}

/// Splits a Radiance matrix file into header text and data bytes.
fn split_header(b: &[u8]) -> (&[u8], &[u8]) {
    let end = b.windows(2).position(|w| w == b"\n\n").expect("header end") + 2;
    (&b[..end], &b[end..])
}

/// Binary float matrices: within 2 ulp (the model runs in double, each value is
/// rounded once to float; libm differences may move the last bit).
fn assert_floats_close(ours: &[u8], theirs: &[u8], what: &str) {
    let (_, a) = split_header(ours);
    let (_, b) = split_header(theirs);
    assert_eq!(a.len(), b.len(), "{what}: data size");
    for (k, (x, y)) in a.chunks(4).zip(b.chunks(4)).enumerate() {
        let x = i32::from_le_bytes(x.try_into().unwrap());
        let y = i32::from_le_bytes(y.try_into().unwrap());
        assert!(
            (x - y).abs() <= 2,
            "{what}: float {k} differs by {} ulp",
            (x - y).abs()
        );
    }
}

fn ours(args: &[&str], dir: &Path) -> Vec<u8> {
    common::run_ok(common::fenestra("gendaymtx").args(args).current_dir(dir))
}

#[test]
fn reference_matrices() {
    let dir = common::fixture("sky");
    for (args, file) in [
        (&["-m", "1", "test.wea"][..], "test.m1.smx"),
        (&["-m", "1", "-d", "test.wea"], "test.m1.d.smx"),
        (&["-m", "1", "-s", "test.wea"], "test.m1.s.smx"),
        (&["-m", "1", "two_days.wea"], "two_days.m1.smx"),
        (&["-m", "1", "-d", "two_days.wea"], "two_days.m1.d.smx"),
        (&["-m", "1", "-s", "two_days.wea"], "two_days.m1.s.smx"),
        (
            &[
                "-r", "90", "-m", "1", "-g", ".3", ".2", ".1", "-c", ".9", ".9", "1.2", "test.wea",
            ],
            "test.r90_g_c.m1.smx",
        ),
    ] {
        let want = std::fs::read(dir.join(file)).unwrap();
        assert_same_ascii(&ours(args, &dir), &want, file);
    }
    let want = std::fs::read(dir.join("two_days.m2.float.smx")).unwrap();
    let got = ours(&["-m", "2", "-of", "two_days.wea"], &dir);
    assert_floats_close(&got, &want, "two_days.m2.float.smx");
}

#[test]
fn malformed_line_is_reported_with_its_number() {
    let d = common::scratch("gendaymtx-bad");
    let text = std::fs::read_to_string(common::fixture("sky/test.wea")).unwrap();
    let mut lines: Vec<&str> = text.lines().collect();
    lines[9] = "3 21 8.500 abc 247";
    std::fs::write(d.join("bad.wea"), lines.join("\n")).unwrap();
    let out = common::fenestra("gendaymtx")
        .arg("bad.wea")
        .current_dir(&d)
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("line 10"), "{err}");
}

/// For each of `cases`, when the oracle is present: the oracle's gendaymtx and ours, each with
/// the case's arguments in the sky fixtures, handed to `check` (arguments, theirs, ours).
fn oracle_cases(cases: &[&[&str]], check: impl Fn(&[&str], Command, Command)) {
    let Some(o) = common::oracle() else { return };
    let dir = common::fixture("sky");
    for &args in cases {
        let mut oracle_cmd = o.command("gendaymtx");
        oracle_cmd.args(args).current_dir(&dir);
        let mut our_cmd = common::fenestra("gendaymtx");
        our_cmd.args(args).current_dir(&dir);
        check(args, oracle_cmd, our_cmd);
    }
}

/// Options on the .wea fixtures.
const GENERATED_CASES: &[&[&str]] = &[
    &["-m", "2", "test.wea"],
    &["-m", "4", "-of", "test.wea"],
    &["-m", "1", "-O1", "two_days.wea"],
    &[
        "-m",
        "2",
        "-r",
        "30",
        "-g",
        ".1",
        ".2",
        ".3",
        "two_days.wea",
    ],
    &["-A", "-m", "1", "test.wea"],
    &["-u", "-m", "1", "two_days.wea"],
    &["-5", ".533", "-m", "1", "test.wea"],
    &["-h", "-od", "-m", "1", "test.wea"],
    &["-i", "60", "-m", "1", "test.wea"],
    &["-D", "-", "test.wea"],
];

#[test]
fn oracle_gendaymtx_generated_cases() {
    oracle_cases(GENERATED_CASES, |args, mut oracle_cmd, mut our_cmd| {
        let want = common::run_ok(&mut oracle_cmd);
        let got = common::run_ok(&mut our_cmd);
        let what = args.join(" ");
        if args.contains(&"-of") || args.contains(&"-od") {
            if args.contains(&"-od") {
                assert_eq!(got, want, "{what}");
            } else {
                assert_floats_close(&got, &want, &what);
            }
        } else if args.contains(&"-D") {
            assert_eq!(
                String::from_utf8_lossy(&got),
                String::from_utf8_lossy(&want),
                "{what}"
            );
        } else {
            assert_same_ascii(&got, &want, &what);
        }
    });
}

/// EPW tapes (fixed and varying dew point) and hard .wea tapes (tropic, polar).
const EPW_AND_HARD_CASES: &[&[&str]] = &[
    &["-m", "1", "two_days_dew11.epw"],
    &["-m", "2", "-of", "two_days_dewvar.epw"],
    &["-m", "1", "-O1", "two_days_dewvar.epw"],
    &["-m", "1", "hard_tropic.wea"],
    &["-m", "2", "-of", "hard_tropic.wea"],
    &["-m", "1", "-u", "hard_tropic.wea"],
    &["-m", "1", "-A", "hard_tropic.wea"],
    &["-m", "1", "hard_polar.wea"],
    &["-m", "2", "-of", "hard_polar.wea"],
    &["-m", "1", "-u", "-d", "hard_polar.wea"],
];

#[test]
fn oracle_gendaymtx_epw_and_hard_cases() {
    oracle_cases(EPW_AND_HARD_CASES, |args, mut oracle_cmd, mut our_cmd| {
        let want = oracle_cmd.output().unwrap();
        let got = our_cmd.output().unwrap();
        let what = args.join(" ");
        assert!(got.status.success(), "{what}");
        if args.contains(&"-of") {
            assert_floats_close(&got.stdout, &want.stdout, &what);
        } else {
            assert_same_ascii(&got.stdout, &want.stdout, &what);
        }
        // the same warnings (after the program name)
        let strip = |b: &[u8]| -> Vec<String> {
            String::from_utf8_lossy(b)
                .lines()
                .map(|l| l.split_once(": ").map(|x| x.1).unwrap_or(l).to_string())
                .collect()
        };
        assert_eq!(strip(&got.stderr), strip(&want.stderr), "{what}: warnings");
    });
}

/// An EPW whose dew point is 11 °C (the .wea's fixed value) gives the .wea's matrix.
#[test]
fn epw_equals_equivalent_wea() {
    let dir = common::fixture("sky");
    let a = ours(&["-m", "1", "two_days_dew11.epw"], &dir);
    let b = std::fs::read(dir.join("two_days.m1.smx")).unwrap();
    let (a, b) = (String::from_utf8_lossy(&a), String::from_utf8_lossy(&b));
    // skip the command line; LATLONG and data must agree to the printed digits
    assert_eq!(
        a.lines().skip(2).collect::<Vec<_>>(),
        b.lines().skip(2).collect::<Vec<_>>()
    );
}

/// With -O1 (solar radiance), sky colour 1 and no sun, Σ patch radiance × solid
/// angle × sin(altitude) over the sky patches is the diffuse horizontal irradiance
/// of the tape: that is how the sky is normalised (patch centres, the model's own
/// single-precision patch tables), so only float rounding remains (1e-5 allowed).
#[test]
fn irradiance_property() {
    let dir = common::fixture("sky");
    let tape = std::fs::read_to_string(dir.join("two_days.wea")).unwrap();
    let difs: Vec<f64> = tape
        .lines()
        .skip(6)
        .map(|l| l.split_whitespace().nth(4).unwrap().parse().unwrap())
        .collect();
    for mf in [1usize, 2] {
        let out = ours(
            &[
                "-m",
                &mf.to_string(),
                "-O1",
                "-s",
                "-c",
                "1",
                "1",
                "1",
                "-of",
                "-h",
                "two_days.wea",
            ],
            &dir,
        );
        let vals: Vec<f32> = out
            .chunks(4)
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            .collect();
        let b = fenestra_sky::patches::Reinhart::new(mf);
        let n = b.len();
        let steps = difs.len();
        assert_eq!(vals.len(), 3 * n * steps);
        for (j, dif) in difs.iter().enumerate() {
            if *dif <= 0.0 {
                continue;
            }
            let mut sum = 0.0;
            for p in 1..n {
                let (alt, _) = b.centre(p);
                sum += f64::from(vals[3 * (p * steps + j) + 1]) * b.solid_angle(p) * alt.sin();
            }
            assert!(
                (sum - dif).abs() <= 1e-5 * dif,
                "MF {mf} step {j}: {sum} vs {dif}"
            );
        }
    }
}
