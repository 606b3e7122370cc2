//! getinfo from the command line and against the oracle's getinfo.

mod common;

use std::io::Write;
use std::path::Path;
use std::process::{Command, Output, Stdio};

fn run(mut c: Command, dir: &Path, args: &[&str], stdin: Option<&[u8]>) -> Output {
    c.current_dir(dir).args(args);
    c.stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let mut child = c
        .spawn()
        .unwrap_or_else(|e| panic!("cannot run {c:?}: {e}"));
    let mut input = child.stdin.take().unwrap();
    let data = stdin.map(<[u8]>::to_vec).unwrap_or_default();
    let writer = std::thread::spawn(move || {
        let _ = input.write_all(&data);
    });
    let out = child.wait_with_output().unwrap();
    writer.join().unwrap();
    out
}

fn files() -> Vec<(&'static str, String)> {
    vec![
        ("threephase", "T.mtx".into()),
        ("threephase", "res_t1_mar21_1000_clear.dat".into()),
        ("threephase", "img_t1_mar21_1000_clear.hdr".into()),
        ("threephase", "V.vmx".into()),
        ("sky", "test.m1.smx".into()),
        ("matrices", "m23h.txt".into()),
    ]
}

/// Header listings of files, header stripping (`-`), added lines (`-a`; the FORMAT line
/// goes last, unpadded), picture dimensions (`-d`) and `-d -`: byte-identical with the
/// oracle's output.
#[test]
fn oracle_getinfo_outputs_are_identical() {
    let Some(o) = common::oracle() else { return };
    let base = common::fixture("");
    let names: Vec<String> = files().iter().map(|(d, f)| format!("{d}/{f}")).collect();
    let all: Vec<&str> = names.iter().map(String::as_str).collect();
    let cmp = |args: &[&str], stdin: Option<&[u8]>| {
        let a = run(o.command("getinfo"), &base, args, stdin);
        let b = run(common::fenestra("getinfo"), &base, args, stdin);
        assert!(b.status.success(), "getinfo {args:?} failed");
        assert!(a.stdout == b.stdout, "getinfo {args:?}: output differs");
    };
    cmp(&all, None);
    for n in &names {
        let data = std::fs::read(base.join(n)).unwrap();
        cmp(&[], Some(&data));
        cmp(&["-"], Some(&data));
        cmp(&["-a", "added line", "x=1"], Some(&data));
    }
    let pic = "threephase/img_t1_mar21_1000_clear.hdr";
    cmp(&["-d", pic], None);
    let data = std::fs::read(base.join(pic)).unwrap();
    cmp(&["-d"], Some(&data));
    cmp(&["-d", "-"], Some(&data));
}

/// `getinfo [+d|-d] -c command ..`: the header with the command line added (quoted as
/// Radiance quotes words), the resolution string kept or dropped, then the command's output
/// on the data: byte-identical with the oracle's (each side's own rcalc on its PATH).
#[test]
fn oracle_getinfo_c_runs_the_command_on_the_data() {
    let Some(o) = common::oracle() else { return };
    let base = common::fixture("threephase");
    let ours_dir = common::fenestra("getinfo").get_program().to_owned();
    let ours_dir = Path::new(&ours_dir).parent().unwrap().to_owned();
    let path = format!(
        "{}:{}",
        ours_dir.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let pic = std::fs::read(base.join("img_t1_mar21_1000_clear.hdr")).unwrap();
    let text = b"#?RADIANCE\nA=1\nFORMAT=ascii\n\n1 2\n3 4\n".to_vec();
    let cases: [(&[&str], &[u8]); 5] = [
        (&["-c", "cat"], &pic),
        (&["+d", "-c", "head", "-c", "100"], &pic),
        (&["-d", "-c", "head", "-c", "100"], &pic),
        (&["-c", "rcalc", "-e", "$1=$1*2"], &text),
        (&["-c", "echo", "a b", "it's", "say \"hi\"", ""], &text),
    ];
    // the command's exit status is getinfo's (ours: command_status_is_getinfo_s)
    let status = run(
        o.command("getinfo"),
        &base,
        &["-c", "sh", "-c", "exit 3"],
        Some(&text),
    );
    assert_eq!(status.status.code(), Some(3));
    for (args, input) in cases {
        let a = run(o.command("getinfo"), &base, args, Some(input));
        let mut c = common::fenestra("getinfo");
        c.env("PATH", &path);
        let b = run(c, &base, args, Some(input));
        assert!(a.status.success() && b.status.success(), "getinfo {args:?}");
        assert!(
            a.stdout == b.stdout,
            "getinfo {args:?}:\n{}\n---\n{}",
            String::from_utf8_lossy(&a.stdout),
            String::from_utf8_lossy(&b.stdout)
        );
    }
}

/// `getinfo -c`: the command's exit status is getinfo's (as the oracle's, checked in
/// oracle_getinfo_c_runs_the_command_on_the_data); a command that cannot start is an error
/// naming it.
#[test]
fn command_status_is_getinfo_s() {
    let base = common::fixture("threephase");
    let text = b"#?RADIANCE\nA=1\nFORMAT=ascii\n\n1 2\n3 4\n";
    let status = run(
        common::fenestra("getinfo"),
        &base,
        &["-c", "sh", "-c", "exit 3"],
        Some(text),
    );
    assert_eq!(status.status.code(), Some(3));
    let missing = run(
        common::fenestra("getinfo"),
        &base,
        &["-c", "no-such-command-here"],
        Some(text),
    );
    assert_eq!(missing.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&missing.stderr).contains("cannot run 'no-such-command-here'"));
}

/// The reference workflow `rmtxop … | getinfo - | total` needs the data bytes unchanged.
#[test]
fn strip_keeps_binary_data_exactly() {
    let base = common::fixture("threephase");
    let data = std::fs::read(base.join("T.mtx")).unwrap();
    let out = run(common::fenestra("getinfo"), &base, &["-"], Some(&data));
    assert!(out.status.success());
    let hlen = data.windows(2).position(|w| w == b"\n\n").unwrap() + 2;
    assert!(out.stdout == data[hlen..]);
}

/// Matrix shapes with `-d` (a fenestra addition: Radiance 6.0a says "unknown file type").
#[test]
fn dimensions_of_a_matrix() {
    let base = common::fixture("threephase");
    let out = run(common::fenestra("getinfo"), &base, &["-d", "T.mtx"], None);
    assert_eq!(
        String::from_utf8_lossy(&out.stdout),
        "T.mtx: NROWS=145 NCOLS=145 NCOMP=3\n"
    );
    // rcontrib's own matrices have no NROWS (it is written only with -y): the rows are
    // counted from the data, ASCII (D.dmx) and float (V_rflux.vmx)
    let out = run(
        common::fenestra("getinfo"),
        &base,
        &["-d", "D.dmx", "V_rflux.vmx"],
        None,
    );
    assert_eq!(
        String::from_utf8_lossy(&out.stdout),
        "D.dmx: NROWS=145 NCOLS=146 NCOMP=3\nV_rflux.vmx: NROWS=45 NCOLS=145 NCOMP=3\n"
    );
    // a truncated one is reported
    let dir = common::scratch("getinfo-truncated");
    let mut d = std::fs::read(base.join("D.dmx")).unwrap();
    d.truncate(d.len() - 40);
    std::fs::write(dir.join("cut.dmx"), d).unwrap();
    let out = run(common::fenestra("getinfo"), &dir, &["-d", "cut.dmx"], None);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("not whole rows"));
}

/// Missing files and data without a header: a message naming the file, exit status 1.
#[test]
fn bad_input_is_reported() {
    let dir = common::cli::scratch_files("getinfo-bad", &[("noheader.txt", "1 2 3\n4 5 6\n")]);
    let cases: [&[&str]; 3] = [&["missing.hdr"], &["noheader.txt"], &["-d", "noheader.txt"]];
    let outs = common::cli::failures("getinfo", &dir, &cases);
    for (args, (_, err)) in cases.iter().zip(outs) {
        assert!(err.contains(args[args.len() - 1]), "{err}");
    }
    let out = run(common::fenestra("getinfo"), &dir, &["-"], Some(b"1 2 3\n"));
    assert!(!out.status.success());
    assert!(out.stdout.is_empty());
}
