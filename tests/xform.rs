//! xform: command-line behaviour and byte-identical output against the oracle's xform.

mod common;

use std::process::Command;

fn body(out: &[u8]) -> String {
    // Header lines ("# /path/to/xform args", one per array copy) and the commands -c keeps
    // ("!cmd | /path/to/xform args") name the program by its path, which differs between
    // the tools: the program's name only.
    String::from_utf8_lossy(out)
        .lines()
        .map(|l| {
            let words: Vec<&str> = l
                .split(' ')
                .map(|w| if w.ends_with("/xform") { "xform" } else { w })
                .collect();
            format!("{}\n", words.join(" "))
        })
        .collect()
}

const TRANSFORMS: &[&str] = &[
    "",
    "-rz 30 -t 1 2 3",
    "-s 2 -mx -rz 90 -t 1 0 0",
    "-I -s 3 -rx 30",
    "-mx -s 2",
    "-t 1 0 0 -i 3 -rz 10",
    "-n nm -m red -a 2 -t 1 0 0",
    "-a 2 -t 1 0 0 -a 3 -t 0 1 0",
    "-ry 33.3 -s .7 -my -t .1 .2 .3",
    "-rx -20 -ry 45.5 -rz 181 -s 1e-3 -t 1000 -2000 .5",
    // the tool options go into the header as given (order, repeats, -e), a second -n
    // extends the name prefix, an array element's name takes the -n values' place
    "-e -rz 90",
    "-I -n pre -c -rz 90",
    "-m mat -e -c -n a -n b -t 1 2 3",
    "-c -e -I -I -s 2",
    "-c -n pre -I -a 2 -t 1 0 0",
    // the first -m counts; with an array every -n value becomes the element's name (from
    // the last -n), each extending the prefix: q.0.q.0.x (Radiance's, reproduced)
    "-m a -m b -rz 1",
    "-n p -n q -a 2 -t 1 0 0",
];

fn files() -> Vec<std::path::PathBuf> {
    let mut v = vec![common::fixture("scene/types.rad")];
    for f in [
        "room",
        "materials",
        "sky",
        "window_bsdf",
        "window_glass",
        "illum_bsdf",
        "exterior",
    ] {
        v.push(common::fixture(&format!("scene/mkillum/{f}.rad")));
    }
    v
}

#[test]
fn oracle_xform_is_byte_identical() {
    let Some(o) = common::oracle() else { return };
    let mut n = 0;
    for t in TRANSFORMS {
        for f in files() {
            let args: Vec<&str> = t.split_whitespace().collect();
            let ours = common::run_ok(common::fenestra("xform").args(&args).arg(&f));
            let theirs = common::run_ok(o.command("xform").args(&args).arg(&f));
            assert_eq!(body(&ours), body(&theirs), "xform {t} {}", f.display());
            n += 1;
        }
    }
    assert!(n >= 80);
}

#[test]
fn header_names_the_command_and_stdin_works() {
    let out = common::run_ok(
        common::fenestra("xform")
            .args(["-rz", "90"])
            .stdin(std::fs::File::open(common::fixture("scene/types.rad")).unwrap()),
    );
    let s = String::from_utf8(out).unwrap();
    let first = s.lines().next().unwrap();
    assert!(
        first.starts_with("# ") && first.ends_with("xform -rz 90"),
        "{first}"
    );
    assert!(s.contains("\np polygon p1\n0\n0\n12\n"), "{s}");
}

#[test]
fn bad_input_is_one_clear_error() {
    let f = common::cli::scratch_file(
        "xform-bad",
        "bad.rad",
        "void plastic m 0 0 5 1 1 1 0 0\n\nm polygon p 0 0 7 0 0 0 1 0 0 1\n",
    );
    let out = Command::new(common::fenestra("xform").get_program())
        .arg("-t")
        .arg("1")
        .arg("0")
        .arg("0")
        .arg(&f)
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(out.stdout.is_empty(), "no partial output");
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("bad.rad:3") && e.contains("polygon"), "{e}");
    assert_eq!(e.lines().count(), 1, "{e}");
}
