//! total from the command line and against the oracle's total.

mod common;

use common::Lcg;
use std::path::Path;
use std::process::{Command, Output};

fn words(s: &str) -> Vec<String> {
    s.split_whitespace().map(str::to_string).collect()
}

fn run(mut c: Command, dir: &Path, args: &[String], stdin: &[u8]) -> Output {
    c.current_dir(dir).args(args);
    common::run_stdin(c, stdin)
}

/// A number of any magnitude and sign from `g`.
fn real(g: &mut Lcg) -> f64 {
    let m = (g.bits() % 1_000_000) as f64 / 1000.0;
    let e = [1e-30, 1e-6, 1e-3, 1.0, 1.0, 1.0, 1e3, 1e12][(g.bits() % 8) as usize];
    let s = if g.bits() % 4 == 0 { -1.0 } else { 1.0 };
    s * m * e
}

/// Random text tables: numbers of every magnitude and sign written in several styles,
/// ragged rows, blank lines (set ends), a header line; every option combination:
/// output byte-identical with the oracle's (`%.9g`, same order of operations).
#[test]
fn oracle_random_text_inputs_are_identical() {
    let Some(o) = common::oracle() else { return };
    let dir = common::scratch("total-rand");
    let mut g = Lcg(12345);
    let mut inputs = Vec::new();
    for case in 0..6 {
        let mut s = String::new();
        if case == 5 {
            s.push_str("#?RADIANCE\nNCOLS=3\n\n");
        }
        let rows = 1 + g.bits() % 40;
        for r in 0..rows {
            let ncol = if case >= 3 { 1 + g.bits() % 5 } else { 3 };
            for c in 0..ncol {
                let v = real(&mut g);
                let w = match (r + c) % 4 {
                    0 => format!("{v}"),
                    1 => format!("{v:e}"),
                    2 => format!("{v:.3}"),
                    _ => format!("{:.6e}", v),
                };
                s.push_str(&w);
                s.push(if c % 2 == 0 { ' ' } else { '\t' });
            }
            s.push('\n');
            if case == 4 && r % 7 == 6 {
                s.push('\n');
            }
        }
        inputs.push(s);
    }
    let opts = [
        "", "-m", "-u", "-l", "-p", "-p -m", "-s2", "-s2 -m", "-s0.5", "-s-1", "-2", "-3 -m",
        "-4 -r", "-3 -m -r", "-2 -p -r", "-1", "-5 -u", "-of", "-od -m",
    ];
    let mut n = 0;
    for inp in &inputs {
        for opt in opts {
            let a = words(opt);
            let theirs = run(o.command("total"), &dir, &a, inp.as_bytes());
            let ours = run(common::fenestra("total"), &dir, &a, inp.as_bytes());
            assert!(ours.status.success(), "total {opt}: {:?}", ours.stderr);
            assert!(theirs.status.success(), "oracle total {opt} failed");
            assert!(
                theirs.stdout == ours.stdout,
                "total {opt} on\n{inp}\noracle:\n{}\nours:\n{}",
                String::from_utf8_lossy(&theirs.stdout),
                String::from_utf8_lossy(&ours.stdout)
            );
            n += 1;
        }
    }
    eprintln!("{n} random cases identical");
}

/// Binary records (`-if3`, `-id2`, counts, running, binary output), identical with the oracle.
#[test]
fn oracle_binary_inputs_are_identical() {
    let Some(o) = common::oracle() else { return };
    let dir = common::scratch("total-bin");
    let mut g = Lcg(777);
    let vals: Vec<f64> = (0..60).map(|_| real(&mut g)).collect();
    let f: Vec<u8> = vals
        .iter()
        .flat_map(|v| (*v as f32).to_ne_bytes())
        .collect();
    let d: Vec<u8> = vals.iter().flat_map(|v| v.to_ne_bytes()).collect();
    for (data, opt) in [
        (&f, "-if3"),
        (&f, "-if3 -m"),
        (&f, "-if4 -3"),
        (&f, "-if -7 -r"),
        (&f, "-if3 -u -of"),
        (&d, "-id2"),
        (&d, "-id2 -p -m"),
        (&d, "-id6 -4 -m -od"),
    ] {
        let a = words(opt);
        let theirs = run(o.command("total"), &dir, &a, data);
        let ours = run(common::fenestra("total"), &dir, &a, data);
        assert!(theirs.status.success(), "oracle total {opt} failed");
        assert!(ours.status.success(), "total {opt}: {:?}", ours.stderr);
        assert!(!ours.stdout.is_empty(), "total {opt} wrote nothing");
        assert!(theirs.stdout == ours.stdout, "total {opt} differs");
    }
}

/// The reference workflow `rmtxop -fa -c … -t res | getinfo - | total` (sums of lux over
/// time steps per sensor), all three tools ours vs all three the oracle's.
#[test]
fn oracle_workflow_pipe_is_identical() {
    let Some(o) = common::oracle() else { return };
    let dir = common::fixture("threephase");
    let pipe = |bin: &dyn Fn(&str) -> String, total_opts: &str| {
        let cmd = format!(
            "{} -fa -c 47.435 119.93 11.635 -t annual_res.dat | {} - | {} {total_opts}",
            bin("rmtxop"),
            bin("getinfo"),
            bin("total"),
        );
        let out = Command::new("bash")
            .args(["-o", "pipefail", "-c"])
            .arg(&cmd)
            .current_dir(&dir)
            .output()
            .unwrap();
        (out.status.success(), out.stdout)
    };
    let exe = std::env::current_exe().unwrap();
    let bin_dir = exe.parent().unwrap().parent().unwrap().to_path_buf();
    let oracle_bin = |t: &str| o.bin(t).display().to_string();
    let our_bin = |t: &str| bin_dir.join(t).display().to_string();
    for opts in ["", "-m", "-u"] {
        let theirs = pipe(&oracle_bin, opts);
        let ours = pipe(&our_bin, opts);
        assert!(theirs.0, "oracle pipe with total {opts} failed");
        assert!(ours.0, "our pipe with total {opts} failed");
        assert!(
            !ours.1.is_empty(),
            "our pipe with total {opts} wrote nothing"
        );
        assert!(theirs.1 == ours.1, "workflow sums with total {opts} differ");
    }
    // The oracle rejects -m -u ("average maximum?!"), and so do we.
    let theirs = pipe(&oracle_bin, "-m -u");
    let ours = pipe(&our_bin, "-m -u");
    assert!(!theirs.0 && !ours.0, "total -m -u must fail on both sides");
    assert!(ours.1.is_empty(), "a rejected total wrote output");
}

/// Bad options and a partial binary record: a clear message and exit status 1.
#[test]
fn bad_input_is_reported() {
    let dir = common::scratch("total-bad");
    for (args, stdin, want) in [
        ("-m -u", &b"1\n"[..], "average maximum"),
        ("-x", b"1\n", "bad option"),
        ("-if3", &[0u8; 16][..], "whole record"),
        ("missing.txt", b"", "missing.txt"),
    ] {
        let out = run(common::fenestra("total"), &dir, &words(args), stdin);
        assert!(!out.status.success(), "total {args} succeeded");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(want), "total {args}: '{err}' lacks '{want}'");
    }
}

/// The reference's annual workflow: the oracle's gendaymtx and dctimestep make `year_res.fmx`
/// (45 sensors × 8760 hours) as the reference run did; our `rmtxop -fa -c … -t | getinfo - | total`
/// reproduces the stored `year_ill_sum.dat` byte for byte.
#[test]
fn oracle_year_sums_reproduce_stored_reference() {
    let Some(o) = common::oracle() else { return };
    let dir = common::scratch("total-year");
    let tp = common::fixture("threephase");
    let wea = Command::new("python3")
        .arg(common::fixture("matrices/gen_year_wea.py"))
        .output()
        .expect("python3 runs the reference's .wea generator");
    assert!(wea.status.success());
    std::fs::write(dir.join("year.wea"), &wea.stdout).unwrap();
    let smx = run(
        o.command("gendaymtx"),
        &dir,
        &words("-m 1 -of year.wea"),
        b"",
    );
    assert!(smx.status.success());
    std::fs::write(dir.join("year.smx"), &smx.stdout).unwrap();
    let args: Vec<String> = vec![
        "-of".into(),
        tp.join("V.vmx").display().to_string(),
        tp.join("blinds_kf.xml").display().to_string(),
        tp.join("D.dmx").display().to_string(),
        "year.smx".into(),
    ];
    let res = run(o.command("dctimestep"), &dir, &args, b"");
    assert!(res.status.success());
    std::fs::write(dir.join("year_res.fmx"), &res.stdout).unwrap();
    let exe = std::env::current_exe().unwrap();
    let bin = exe.parent().unwrap().parent().unwrap().to_path_buf();
    let b = |t: &str| bin.join(t).display().to_string();
    let out = Command::new("bash")
        .args(["-o", "pipefail", "-c"])
        .arg(format!(
            "{} -fa -c 47.435 119.93 11.635 -t year_res.fmx | {} - | {}",
            b("rmtxop"),
            b("getinfo"),
            b("total")
        ))
        .current_dir(&dir)
        .output()
        .unwrap();
    assert!(out.status.success());
    let want = std::fs::read(common::fixture("matrices/year_ill_sum.dat")).unwrap();
    assert!(
        out.stdout == want,
        "year sums differ from the stored reference"
    );
}
