//! Hostile and careless input (issue 15): every case gives a clear message or a correct
//! result — never a panic, an abort, a NaN written without a word, a half-written or
//! hidden file, or a special file replaced. Each test names the item of the issue it keeps
//! fixed; the parsers are also fuzzed (tests/fuzz_parsers.rs).

mod common;

use std::io::{BufRead, BufReader, Read, Write};
use std::path::Path;
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

use common::{fenestra, fixture, run_stdin, scratch};

/// Runs one of our tools in `dir` with `input` on stdin.
fn run(tool: &str, args: &[&str], dir: &Path, input: &[u8]) -> Output {
    let mut c = fenestra(tool);
    c.args(args).current_dir(dir);
    run_stdin(c, input)
}

/// Starts one of our tools in `dir` with `io` as its stdin, stdout and stderr.
fn spawn(tool: &str, args: &[&str], dir: &Path, io: [Stdio; 3]) -> Child {
    let [input, output, errors] = io;
    let mut c = fenestra(tool);
    c.args(args)
        .current_dir(dir)
        .stdin(input)
        .stdout(output)
        .stderr(errors);
    c.spawn().unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A clean failure: exit status 1 (not a signal, not a panic's 101), a short message
/// holding every word of `want`.
fn clean_fail(o: &Output, want: &[&str]) {
    let e = stderr(o);
    assert_eq!(o.status.code(), Some(1), "status {}: {e}", o.status);
    assert!(!e.contains("panicked"), "{e}");
    assert!(e.len() < 4000, "message of {} bytes", e.len());
    for w in want {
        assert!(e.contains(w), "missing '{w}' in: {e}");
    }
}

/// A success with no panic.
fn clean_ok(o: &Output) -> String {
    let e = stderr(o);
    assert!(o.status.success(), "status {}: {e}", o.status);
    assert!(!e.contains("panicked"), "{e}");
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn no_nan(text: &str) {
    let t = text.to_ascii_lowercase();
    assert!(
        !t.contains("nan") && !t.contains("inf"),
        "non-finite value in: {text}"
    );
}

/// Files in `dir` other than `keep`.
fn others(dir: &Path, keep: &[&str]) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| !keep.contains(&n.as_str()))
        .collect();
    v.sort();
    v
}

const SKY23: &str =
    "#?RADIANCE\nNROWS=2\nNCOLS=3\nNCOMP=3\nFORMAT=ascii\n\n1 1 1 2 2 2 3 3 3\n4 4 4 5 5 5 6 6 6\n";
const V12: &str = "#?RADIANCE\nNROWS=1\nNCOLS=2\nNCOMP=3\nFORMAT=ascii\n\n1 1 1 0.5 0.5 0.5\n";
/// A lit box: a glow source above a floor.
const ROOM: &str = "void light bright\n0\n0\n3 10 10 10\nbright source sky\n0\n0\n4 0 0 1 180\nvoid plastic grey\n0\n0\n5 .5 .5 .5 0 0\ngrey polygon floor\n0\n0\n12 -5 -5 0 5 -5 0 5 5 0 -5 5 0\n";

/// The files [`dc_dir`] writes.
const DC_FILES: [&str; 3] = ["sky.mtx", "v.mtx", "room.rad"];

/// Asserts that `dir` holds nothing but the files of [`dc_dir`].
#[track_caller]
fn assert_only_dc_files(dir: &Path) {
    assert_eq!(others(dir, &DC_FILES), Vec::<String>::new());
}

fn dc_dir(name: &str) -> std::path::PathBuf {
    let d = scratch(name);
    std::fs::write(d.join("sky.mtx"), SKY23).unwrap();
    std::fs::write(d.join("v.mtx"), V12).unwrap();
    std::fs::write(d.join("room.rad"), ROOM).unwrap();
    d
}

/// Item 1: an output that is a symbolic link, a named pipe or a device is written
/// through (the link, pipe and device stay); a regular file is replaced whole.
#[cfg(unix)]
#[test]
fn special_outputs_are_written_through() {
    let d = dc_dir("hostile-special");
    let want = clean_ok(&run("dctimestep", &["v.mtx", "sky.mtx"], &d, b""));
    std::fs::write(d.join("real.dat"), b"old").unwrap();
    std::os::unix::fs::symlink("real.dat", d.join("link.dat")).unwrap();
    clean_ok(&run(
        "dctimestep",
        &["-o", "link.dat", "v.mtx", "sky.mtx"],
        &d,
        b"",
    ));
    let meta = std::fs::symlink_metadata(d.join("link.dat")).unwrap();
    assert!(meta.file_type().is_symlink(), "the link was replaced");
    let got = std::fs::read_to_string(d.join("real.dat")).unwrap();
    let body = |s: &str| s.split("\n\n").nth(1).unwrap_or("").to_string();
    assert_eq!(body(&got), body(&want));
    // a named pipe: its reader gets the data, the pipe stays a pipe
    let fifo = d.join("pipe.dat");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read_to_string(fifo).unwrap())
    };
    clean_ok(&run(
        "dctimestep",
        &["-o", "pipe.dat", "v.mtx", "sky.mtx"],
        &d,
        b"",
    ));
    assert_eq!(body(&reader.join().unwrap()), body(&want));
    use std::os::unix::fs::FileTypeExt;
    assert!(std::fs::symlink_metadata(&fifo)
        .unwrap()
        .file_type()
        .is_fifo());
    // /dev/null stays a device (as root the old code replaced it with a regular file)
    clean_ok(&run(
        "dctimestep",
        &["-o", "/dev/null", "v.mtx", "sky.mtx"],
        &d,
        b"",
    ));
    assert!(std::fs::metadata("/dev/null")
        .unwrap()
        .file_type()
        .is_char_device());
    // rcontrib -fo -o through a link
    std::fs::write(d.join("rc_real.dat"), b"old").unwrap();
    std::os::unix::fs::symlink("rc_real.dat", d.join("rc_link.dat")).unwrap();
    let o = run(
        "rcontrib",
        &["-h", "-fo", "-o", "rc_link.dat", "-m", "bright", "room.rad"],
        &d,
        b"0 0 1 0 0 1\n",
    );
    clean_ok(&o);
    assert!(std::fs::symlink_metadata(d.join("rc_link.dat"))
        .unwrap()
        .file_type()
        .is_symlink());
    // rcontrib reports coefficients (1 for a ray that reaches the source)
    let v: Vec<f64> = common::numbers(&std::fs::read(d.join("rc_real.dat")).unwrap());
    assert_eq!(v, [1.0, 1.0, 1.0]);
    assert_eq!(
        others(&d, &[])
            .iter()
            .filter(|n| n.starts_with('.'))
            .count(),
        0
    );
}

/// Item 2: a huge printf width in an output name is refused with a short message.
#[test]
fn huge_output_field_width() {
    let d = dc_dir("hostile-width");
    let o = run(
        "dctimestep",
        &["-o", "o_%65536d.dat", "v.mtx", "sky.mtx"],
        &d,
        b"",
    );
    clean_fail(&o, &["too large"]);
    let o = run(
        "rcontrib",
        &["-o", "r_%100000000d.dat", "-m", "bright", "room.rad"],
        &d,
        b"0 0 1 0 0 1\n",
    );
    clean_fail(&o, &["too large"]);
    assert_only_dc_files(&d);
}

/// Item 3: sizes in headers and scene files are checked against what can follow before
/// anything is allocated.
#[test]
fn sizes_are_checked_before_allocating() {
    let d = dc_dir("hostile-alloc");
    // a row of 3·10^6 values: the file's size cannot hold it
    let sky = "#?RADIANCE\nNROWS=2\nNCOLS=1000000\nNCOMP=3\nFORMAT=ascii\n\n1 1 1 2 2 2\n";
    std::fs::write(d.join("big.mtx"), sky).unwrap();
    clean_fail(
        &run("dctimestep", &["v.mtx", "big.mtx"], &d, b""),
        &["big.mtx", "truncated ascii"],
    );
    // a row of 3·10^8 values (the case) is past any row fenestra reads
    let sky = sky.replace("1000000", "100000000");
    std::fs::write(d.join("big.mtx"), &sky).unwrap();
    clean_fail(
        &run("dctimestep", &["v.mtx", "big.mtx"], &d, b""),
        &["big.mtx", "too large"],
    );
    // the same sky from a pipe: no size to check, so the rows are gathered as they come
    let o = run("dctimestep", &["v.mtx", "-"], &d, sky.as_bytes());
    clean_fail(&o, &[]);
    let bad = "void plastic m\n0\n0\n99999999999 1 2 3\n";
    std::fs::write(d.join("big.rad"), bad).unwrap();
    for (tool, args) in [
        ("rtrace", vec!["big.rad"]),
        ("oconv", vec!["big.rad"]),
        ("xform", vec!["-rz", "10", "big.rad"]),
    ] {
        let o = run(tool, &args, &d, b"0 0 0 0 0 1\n");
        clean_fail(&o, &["big.rad:1", "end of input"]);
    }
}

/// Item 4: deep expressions evaluate or give a syntax error, never a stack overflow.
#[test]
fn deep_expressions() {
    let d = scratch("hostile-deep");
    let paren = format!("$1={}1{};", "(".repeat(7000), ")".repeat(7000));
    let sum = format!("$1={};", vec!["$1"; 15000].join("+"));
    std::fs::write(d.join("paren.cal"), paren).unwrap();
    std::fs::write(d.join("sum.cal"), sum).unwrap();
    assert_eq!(
        clean_ok(&run("rcalc", &["-f", "paren.cal"], &d, b"2\n")).trim(),
        "1"
    );
    assert_eq!(
        clean_ok(&run("rcalc", &["-f", "sum.cal"], &d, b"2\n")).trim(),
        "30000"
    );
    let too = format!("$1={};", vec!["$1"; 60000].join("+"));
    std::fs::write(d.join("too.cal"), too).unwrap();
    clean_fail(
        &run("rcalc", &["-f", "too.cal"], &d, b"2\n"),
        &["too deep", "line 1"],
    );
    // a 15 000-term pattern in a scene
    let pat = format!("bright = {};", vec!["Dz"; 15000].join("+"));
    std::fs::write(d.join("pat.cal"), pat).unwrap();
    let scene = "void brightfunc pf\n2 bright pat.cal\n0\n0\npf glow g\n0\n0\n4 1 1 1 0\ng source s\n0\n0\n4 0 0 1 180\n";
    std::fs::write(d.join("pat.rad"), scene).unwrap();
    let out = clean_ok(&run("rtrace", &["-h", "pat.rad"], &d, b"0 0 0 0 0 1\n"));
    assert_eq!(common::numbers(out.as_bytes()), [15000.0; 3]);
}

/// Item 5: a word that is not a number ends the input with a warning naming its line;
/// nan and inf are numbers, and such rays are answered with zeros and a warning.
#[test]
fn bad_ray_words() {
    let d = dc_dir("hostile-words");
    for tool in ["rtrace", "rcontrib"] {
        let mut args = vec!["-h"];
        if tool == "rcontrib" {
            args.extend(["-m", "bright"]);
        }
        args.push("room.rad");
        let o = run(tool, &args, &d, b"0 0 1 0 0 1\n0 0 1 0 0 x\n0 0 1 0 0 1\n");
        let out = clean_ok(&o);
        assert_eq!(out.lines().count(), 1, "{tool}: {out}");
        let e = stderr(&o);
        assert!(e.contains("line 2") && e.contains("'x'"), "{tool}: {e}");
        let o = run(
            tool,
            &args,
            &d,
            b"nan 0 1 0 0 1\n0 0 1 inf 0 1\n0 0 1 0 0 1\n",
        );
        let out = clean_ok(&o);
        no_nan(&out);
        let v = common::numbers(out.as_bytes());
        assert_eq!(v.len(), 9, "{tool}: {out}");
        assert_eq!(&v[..6], &[0.0; 6]);
        assert!(v[6] > 0.0);
        assert!(stderr(&o).contains("not finite"), "{tool}: {}", stderr(&o));
    }
}

/// Reads lines from a child's stdout on a thread; `next` waits at most 20 s for one.
struct LineReader(std::sync::mpsc::Receiver<String>);

impl LineReader {
    fn new(out: impl Read + Send + 'static) -> Self {
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            for l in BufReader::new(out).lines() {
                let Ok(l) = l else { break };
                if tx.send(l).is_err() {
                    break;
                }
            }
        });
        LineReader(rx)
    }
    fn next(&self) -> Option<String> {
        self.0.recv_timeout(Duration::from_secs(20)).ok()
    }
}

/// Item 6: rtrace and rcontrib answer each ray at once with -x 1 (a program driving them
/// as a coprocess sends a ray and waits), and after a dummy (zero-direction) ray.
#[test]
fn coprocess_answers_at_once() {
    let d = dc_dir("hostile-copro");
    for (tool, args) in [
        ("rtrace", vec!["-h", "-x", "1", "room.rad"]),
        (
            "rcontrib",
            vec!["-h", "-x", "1", "-m", "bright", "room.rad"],
        ),
        ("rtrace", vec!["-h", "room.rad"]),
    ] {
        let flush_each = args.contains(&"-x");
        let io = [Stdio::piped(), Stdio::piped(), Stdio::null()];
        let mut child = spawn(tool, &args, &d, io);
        let mut stdin = child.stdin.take().unwrap();
        let lines = LineReader::new(child.stdout.take().unwrap());
        for _ in 0..3 {
            let ray: &[u8] = if flush_each {
                b"0 0 1 0 0 1\n"
            } else {
                // without -x, a dummy ray asks for the flush
                b"0 0 1 0 0 1\n0 0 0 0 0 0\n"
            };
            stdin.write_all(ray).unwrap();
            stdin.flush().unwrap();
            let l = lines.next();
            assert!(
                l.is_some(),
                "{tool} {args:?}: no answer while the input stays open"
            );
            let v = common::numbers(l.unwrap().as_bytes());
            // rtrace gives the source's radiance, rcontrib its coefficient
            let want = if tool == "rtrace" { 10.0 } else { 1.0 };
            assert_eq!(v, [want; 3], "{tool}");
            if !flush_each {
                assert_eq!(common::numbers(lines.next().unwrap().as_bytes()), [0.0; 3]);
            }
        }
        drop(stdin);
        assert!(child.wait().unwrap().success());
    }
}

/// Item 6: memory stays flat while 10^6 rays stream through rtrace (it held every ray
/// before: ~95 bytes each, 100 MB here).
#[cfg(target_os = "linux")]
#[test]
fn rtrace_memory_is_bounded() {
    let d = dc_dir("hostile-rss");
    let io = [Stdio::piped(), Stdio::piped(), Stdio::piped()];
    let mut child = spawn("rtrace", &["-h", "-ab", "0", "-ff", "room.rad"], &d, io);
    let pid = child.id();
    let mut stdin = child.stdin.take().unwrap();
    let mut out = child.stdout.take().unwrap();
    let counter = std::thread::spawn(move || {
        let mut buf = vec![0u8; 1 << 16];
        let mut n = 0usize;
        while let Ok(k) = out.read(&mut buf) {
            if k == 0 {
                break;
            }
            n += k;
        }
        n
    });
    let ray: Vec<u8> = [0.0f32, 0.0, 1.0, 0.0, 0.0, 1.0]
        .iter()
        .flat_map(|v| v.to_ne_bytes())
        .collect();
    let block: Vec<u8> = ray.repeat(10_000);
    for _ in 0..100 {
        stdin.write_all(&block).unwrap();
    }
    stdin.flush().unwrap();
    // the input stays open: read the peak resident size while the process lives
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap();
    let hwm_kb: u64 = status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.split_whitespace().next())
        .and_then(|v| v.parse().ok())
        .unwrap();
    drop(stdin);
    assert!(child.wait().unwrap().success());
    assert_eq!(counter.join().unwrap(), 1_000_000 * 12);
    assert!(hwm_kb < 60_000, "peak RSS {hwm_kb} kB for 10^6 rays");
}

/// Item 7: weather files Radiance reads: a place without an underscore, time zone -180
/// (New Zealand, Fiji). (-195, 13 hours, is refused by Radiance too.)
#[test]
fn weather_radiance_accepts() {
    let d = scratch("hostile-wea");
    for (place, tz, ok) in [
        ("Berkeley", "-180", true),
        ("A_B", "180", true),
        ("A_B", "-195", false),
    ] {
        let wea = format!("place {place}\nlatitude -41.3\nlongitude -174.8\ntime_zone {tz}\nsite_elevation 10\nweather_data_file_units 1\n1 1 12.5 500 100\n1 1 13.5 400 100\n");
        std::fs::write(d.join("w.wea"), wea).unwrap();
        let o = run("gendaymtx", &["-h", "-m", "1", "w.wea"], &d, b"");
        if ok {
            let out = clean_ok(&o);
            no_nan(&out);
            assert_eq!(common::numbers(out.as_bytes()).len(), 146 * 2 * 3);
        } else {
            clean_fail(&o, &["time zone"]);
        }
    }
}

/// Item 8: -n below 1 is an error; more than the cores is capped with a warning (and runs
/// as fast as -n cores).
#[test]
fn process_counts() {
    let d = dc_dir("hostile-n");
    for n in ["0", "-1"] {
        clean_fail(
            &run("rtrace", &["-n", n, "room.rad"], &d, b"0 0 1 0 0 1\n"),
            &["-n"],
        );
    }
    let t = Instant::now();
    let o = run(
        "rtrace",
        &["-h", "-n", "10000", "room.rad"],
        &d,
        b"0 0 1 0 0 1\n",
    );
    assert_eq!(common::numbers(clean_ok(&o).as_bytes()), [10.0; 3]);
    assert!(stderr(&o).contains("core"), "{}", stderr(&o));
    assert!(t.elapsed() < Duration::from_secs(30));
}

/// Items 9 and 10: impossible bin counts and endless option files fail at once.
#[test]
fn unbounded_requests_fail_at_once() {
    let d = dc_dir("hostile-bn");
    let t = Instant::now();
    let o = run(
        "rcontrib",
        &["-bn", "1e12", "-m", "bright", "room.rad"],
        &d,
        b"0 0 1 0 0 1\n",
    );
    clean_fail(&o, &["-bn", "bins"]);
    clean_fail(
        &run("rtrace", &["@/dev/zero", "room.rad"], &d, b""),
        &["/dev/zero", "larger"],
    );
    assert!(t.elapsed() < Duration::from_secs(20));
}

/// Item 11: Latin-1 bytes in comments are read as Radiance reads bytes, and xform writes
/// them back unchanged.
#[test]
fn latin1_comments() {
    let d = scratch("hostile-latin1");
    let mut scene = b"# caf\xe9 cr\xe8me\n".to_vec();
    scene.extend_from_slice(ROOM.as_bytes());
    std::fs::write(d.join("l.rad"), &scene).unwrap();
    let out = clean_ok(&run("rtrace", &["-h", "l.rad"], &d, b"0 0 1 0 0 1\n"));
    assert_eq!(common::numbers(out.as_bytes()), [10.0; 3]);
    clean_ok(&run("oconv", &["l.rad"], &d, b""));
    let x = run("xform", &["-rz", "30", "l.rad"], &d, b"");
    assert!(x.status.success(), "{}", stderr(&x));
    assert!(
        x.stdout.windows(6).any(|w| w == b"caf\xe9 c"),
        "Latin-1 bytes not kept"
    );
    std::fs::write(d.join("l.cal"), b"{ caf\xe9 }\n$1=$1*2;\n").unwrap();
    assert_eq!(
        clean_ok(&run("rcalc", &["-f", "l.cal"], &d, b"3\n")).trim(),
        "6"
    );
}

/// Item 12: a zero-radius sphere is ignored with the same warning by oconv and rtrace.
#[test]
fn zero_radius_sphere_one_rule() {
    let d = dc_dir("hostile-sphere");
    let scene = format!("{ROOM}grey sphere s\n0\n0\n4 0 0 1 0\n");
    std::fs::write(d.join("s.rad"), scene).unwrap();
    let o = run("oconv", &["s.rad"], &d, b"");
    clean_ok(&o);
    assert!(stderr(&o).contains("zero radius"), "{}", stderr(&o));
    let o = run("rtrace", &["-h", "s.rad"], &d, b"0 0 0.5 0 0 1\n");
    assert_eq!(common::numbers(clean_ok(&o).as_bytes()), [10.0; 3]);
    assert!(stderr(&o).contains("zero radius"), "{}", stderr(&o));
}

/// Item 13: an interrupted dctimestep leaves no hidden temporary file.
#[cfg(unix)]
#[test]
fn interrupted_output_leaves_nothing() {
    let d = dc_dir("hostile-kill");
    let io = [Stdio::piped(), Stdio::null(), Stdio::null()];
    let mut child = spawn("dctimestep", &["-o", "ill.dat", "-", "sky.mtx"], &d, io);
    let mut stdin = child.stdin.take().unwrap();
    // a V matrix streamed slowly: the output is being written when the signal comes
    stdin
        .write_all(b"#?RADIANCE\nNROWS=3\nNCOLS=2\nNCOMP=3\nFORMAT=ascii\n\n1 1 1 2 2 2\n")
        .unwrap();
    stdin.flush().unwrap();
    let t = Instant::now();
    while others(&d, &DC_FILES).is_empty() {
        assert!(
            t.elapsed() < Duration::from_secs(20),
            "no temporary output appeared"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    assert!(Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap()
        .success());
    let st = child.wait().unwrap();
    assert!(!st.success());
    drop(stdin);
    assert_only_dc_files(&d);
}

/// Item 14: xform arrays stream and are linear in their size.
#[test]
fn xform_array_streams() {
    let d = dc_dir("hostile-xform");
    let t = Instant::now();
    let out = clean_ok(&run(
        "xform",
        &["-a", "20000", "-rz", "0.3", "-t", "1", "0", "0", "room.rad"],
        &d,
        b"",
    ));
    assert_eq!(out.matches("polygon").count(), 20000);
    assert!(t.elapsed() < Duration::from_secs(20));
    // -a 10^8 | head: the first copies come at once
    let io = [Stdio::inherit(), Stdio::piped(), Stdio::null()];
    let mut child = spawn(
        "xform",
        &["-a", "100000000", "-rz", "1", "room.rad"],
        &d,
        io,
    );
    let lines = LineReader::new(child.stdout.take().unwrap());
    for _ in 0..50 {
        assert!(lines.next().is_some(), "no output from a huge array");
    }
    let _ = child.kill();
    let _ = child.wait();
}

/// Item 15: an output command that stops reading is named in a message.
#[test]
fn failing_output_command_is_reported() {
    let d = dc_dir("hostile-cmd");
    let rays = b"0 0 1 0 0 1\n".repeat(20000);
    let o = run(
        "rcontrib",
        &["-o", "!false", "-m", "bright", "room.rad"],
        &d,
        &rays,
    );
    clean_fail(&o, &["false"]);
}

/// Item 16: messages name things once and show no raw binary bytes; no warning on a
/// default rtrace run.
#[test]
fn messages_are_clean() {
    let d = dc_dir("hostile-msg");
    std::fs::write(
        d.join("garb.mtx"),
        b"#?RADIANCE\nNROWS=1\x01\x02\xff\x1b[31m\nNCOLS=1\n\n",
    )
    .unwrap();
    let o = run("rmtxop", &["garb.mtx"], &d, b"");
    clean_fail(&o, &["garb.mtx", "NROWS"]);
    assert!(
        !o.stderr.contains(&0x1b) && !o.stderr.contains(&0x01),
        "{}",
        stderr(&o)
    );
    std::fs::write(
        d.join("bad.hdr"),
        b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 10 +X 10\n\x02\x02\x00",
    )
    .unwrap();
    let o = run("rmtxop", &["bad.hdr"], &d, b"");
    clean_fail(&o, &["bad.hdr"]);
    assert_eq!(stderr(&o).matches("bad.hdr").count(), 1, "{}", stderr(&o));
    std::fs::create_dir_all(d.join("adir")).unwrap();
    let o = run("pcomb", &["adir"], &d, b"");
    clean_fail(&o, &["adir", "directory"]);
    assert_eq!(stderr(&o).matches("directory").count(), 1, "{}", stderr(&o));
    let o = run("rtrace", &["-h", "room.rad"], &d, b"0 0 1 0 0 1\n");
    clean_ok(&o);
    assert_eq!(stderr(&o), "", "a default rtrace run warned");
    let o = run(
        "rtrace",
        &["-h", "-w", "-aa", ".2", "room.rad"],
        &d,
        b"0 0 1 0 0 1\n",
    );
    assert_eq!(stderr(&o), "", "-w did not silence warnings");
}

/// Cases that held before issue 15, kept: truncated and lying matrices, size and basis
/// mismatches, broken BSDF XML, scenes and .cal files, NaN in data.
#[test]
fn broken_inputs_fail_clearly() {
    let d = dc_dir("hostile-held");
    // truncated binary matrix, and one whose header lies about its rows
    let mut bin = b"#?RADIANCE\nNROWS=4\nNCOLS=2\nNCOMP=3\nFORMAT=float\n\n".to_vec();
    bin.extend(std::iter::repeat_n(0u8, 4 * 6 * 3));
    std::fs::write(d.join("trunc.mtx"), &bin).unwrap();
    clean_fail(
        &run("rmtxop", &["trunc.mtx"], &d, b""),
        &["trunc.mtx", "truncated"],
    );
    let lying = "#?RADIANCE\nNROWS=3\nNCOLS=2\nNCOMP=3\nFORMAT=ascii\n\n1 1 1 2 2 2\n";
    clean_fail(
        &run("rmtxop", &["-"], &d, lying.as_bytes()),
        &["end of data"],
    );
    // V with 2 columns against a 145-patch BSDF, and a BSDF XML cut in half
    let xml = fixture("threephase/blinds_kf.xml");
    let text = std::fs::read(&xml).unwrap();
    std::fs::write(d.join("half.xml"), &text[..text.len() / 2]).unwrap();
    for (bsdf, want) in [(xml.to_str().unwrap(), "145"), ("half.xml", "half.xml")] {
        clean_fail(
            &run("dctimestep", &["v.mtx", bsdf, "v.mtx", "sky.mtx"], &d, b""),
            &[want],
        );
    }
    // scene and .cal syntax errors name file and line
    std::fs::write(d.join("bad.rad"), "void plastic m\n0\n0\n5 .5 .5 x 0 0\n").unwrap();
    clean_fail(&run("rtrace", &["bad.rad"], &d, b""), &["bad.rad:1", "'x'"]);
    std::fs::write(d.join("bad.cal"), "a = 1;\n$1 = (a + ;\n").unwrap();
    clean_fail(
        &run("rcalc", &["-f", "bad.cal"], &d, b"1\n"),
        &["bad.cal", "line 2"],
    );
    // NaN in a sky is carried through as Radiance does, with a warning
    let nan = "#?RADIANCE\nNROWS=2\nNCOLS=1\nNCOMP=3\nFORMAT=ascii\n\n1 1 1\nnan 2 2\n";
    std::fs::write(d.join("nan.mtx"), nan).unwrap();
    let o = run("dctimestep", &["v.mtx", "nan.mtx"], &d, b"");
    clean_ok(&o);
    assert!(stderr(&o).contains("not a finite number"), "{}", stderr(&o));
}

/// Hard geometry: grazing, vertex and edge rays, a 1 mm slat 1 km away, coplanar
/// overlapping polygons, polar and date-line skies: finite values, no panic.
#[test]
fn hard_geometry_and_skies() {
    let d = scratch("hostile-geom");
    let scene = "void glow a\n0\n0\n4 1 1 1 0\nvoid glow b\n0\n0\n4 2 2 2 0\n\
                 a polygon p1\n0\n0\n12 0 0 0 1 0 0 1 1 0 0 1 0\n\
                 b polygon p2\n0\n0\n12 0 0 0 1 0 0 1 1 0 0 1 0\n\
                 b polygon slat\n0\n0\n12 1000 -0.0005 0.05 1000 0.0005 0.05 1000 0.0005 -0.05 1000 -0.0005 -0.05\n";
    std::fs::write(d.join("g.rad"), scene).unwrap();
    let rays = "0.5 0.5 1 0 0 -1\n\
                -1 0.5 0 1 0 0\n\
                0 0 1 0 0 -1\n\
                0.5 0 1 0 0 -1\n\
                1 1 1 0 0 -1\n\
                0 0 5 1000 0 -5\n\
                0.5 0.5 0 0 0 1\n";
    let out = clean_ok(&run(
        "rtrace",
        &["-h", "-ab", "1", "g.rad"],
        &d,
        rays.as_bytes(),
    ));
    no_nan(&out);
    let v = common::numbers(out.as_bytes());
    assert_eq!(v.len(), 21);
    assert!(v.iter().all(|x| *x >= 0.0));
    // the coplanar pair shows one of its two values, and the slat 1 km out is hit
    assert!(v[0] == 1.0 || v[0] == 2.0, "{}", v[0]);
    assert_eq!(&v[15..18], &[2.0; 3], "the 1 mm slat at 1 km was missed");
    for args in [
        vec!["6", "21", "12", "-a", "89.9", "-o", "180", "-m", "180"],
        vec![
            "12", "21", "12", "-a", "-89.9", "-o", "-180", "-m", "-180", "+s",
        ],
        vec!["3", "21", "6:05", "-a", "0", "-o", "0", "-m", "0", "+s"],
    ] {
        let sky = clean_ok(&run("gensky", &args, &d, b""));
        no_nan(&sky);
        let v = clean_ok(&run("genskyvec", &["-m", "2"], &d, sky.as_bytes()));
        no_nan(&v);
    }
}

/// Items 7, 11 and 14 against the oracle: the weather files Radiance accepts give its
/// matrix digit for digit; xform keeps Latin-1 bytes and gives Radiance's array output
/// byte for byte (its repeated products are continued in Radiance's order).
#[test]
fn oracle_weather_and_xform_bytes() {
    let Some(oracle) = common::oracle() else {
        return;
    };
    let d = scratch("hostile-oracle");
    for (place, tz) in [("Berkeley", "-180"), ("Suva_Fiji", "180")] {
        let wea = format!("place {place}\nlatitude -18.1\nlongitude -178.4\ntime_zone {tz}\nsite_elevation 10\nweather_data_file_units 1\n1 1 12.5 500 100\n7 1 9.5 400 100\n");
        std::fs::write(d.join("w.wea"), wea).unwrap();
        let mut c = oracle.command("gendaymtx");
        c.args(["-h", "-m", "1", "w.wea"]).current_dir(&d);
        let theirs = common::run_ok(&mut c);
        let ours = clean_ok(&run("gendaymtx", &["-h", "-m", "1", "w.wea"], &d, b""));
        assert_eq!(String::from_utf8_lossy(&theirs), ours, "{place} {tz}");
    }
    let mut scene = b"# caf\xe9 cr\xe8me\n".to_vec();
    scene.extend_from_slice(ROOM.as_bytes());
    std::fs::write(d.join("l.rad"), &scene).unwrap();
    // both programs write their argv[0] into the output: run both as ./xform
    for (who, exe) in [
        ("theirs", oracle.bin("xform")),
        ("ours", fenestra("xform").get_program().into()),
    ] {
        std::fs::create_dir_all(d.join(who)).unwrap();
        std::fs::copy(exe, d.join(who).join("xform")).unwrap();
    }
    for args in [
        vec!["-rz", "30", "../l.rad"],
        vec!["-a", "3000", "-rz", "0.3", "-t", "1", "0", "0", "../l.rad"],
        vec![
            "-a", "7", "-rz", "10", "-a", "5", "-t", "1", "0", "0", "-s", "1.1", "../l.rad",
        ],
    ] {
        let out = |who: &str| {
            let mut c = Command::new("./xform");
            c.args(&args).current_dir(d.join(who));
            c.env(
                "FENESTRA_LIB",
                Path::new(env!("CARGO_MANIFEST_DIR")).join("lib"),
            );
            common::run_ok(&mut c)
        };
        let (theirs, ours) = (out("theirs"), out("ours"));
        assert!(theirs.windows(6).any(|w| w == b"caf\xe9 c"));
        assert!(theirs == ours, "xform {args:?}");
    }
}
