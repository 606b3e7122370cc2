//! Helpers shared by the integration tests: our binaries, the reference
//! implementation (oracle), fixtures and scratch folders.
#![allow(dead_code)]

pub mod cli;
pub mod probe;

use std::path::{Path, PathBuf};
use std::process::Command;

/// The reference Radiance binaries (PyPI pyradiance 1.3.1, Radiance 6.0a).
pub struct Oracle {
    bin: PathBuf,
    lib: PathBuf,
}

impl Oracle {
    /// Path of an oracle binary.
    pub fn bin(&self, name: &str) -> PathBuf {
        self.bin.join(name)
    }

    /// The oracle's library folder (its .cal files).
    pub fn lib(&self) -> &Path {
        &self.lib
    }

    /// A command running an oracle binary with PATH and RAYPATH pointing at the oracle.
    pub fn command(&self, name: &str) -> Command {
        let mut c = Command::new(self.bin(name));
        let path = std::env::var("PATH").unwrap_or_default();
        c.env("PATH", format!("{}:{}", self.bin.display(), path));
        c.env("RAYPATH", format!(".:{}", self.lib.display()));
        c
    }
}

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The oracle, found through FENESTRA_ORACLE_BIN/FENESTRA_ORACLE_LIB or the
/// `.oracle/env` file written by `scripts/oracle.sh`. Missing: `None` with a note,
/// except under CI (`CI=true`), where a missing oracle fails the test.
pub fn oracle() -> Option<Oracle> {
    let mut bin = std::env::var_os("FENESTRA_ORACLE_BIN").map(PathBuf::from);
    let mut lib = std::env::var_os("FENESTRA_ORACLE_LIB").map(PathBuf::from);
    if bin.is_none() {
        if let Ok(text) = std::fs::read_to_string(repo().join(".oracle/env")) {
            for line in text.lines() {
                if let Some(v) = line.strip_prefix("FENESTRA_ORACLE_BIN=") {
                    bin = Some(PathBuf::from(v));
                } else if let Some(v) = line.strip_prefix("FENESTRA_ORACLE_LIB=") {
                    lib = Some(PathBuf::from(v));
                }
            }
        }
    }
    match (bin, lib) {
        (Some(b), Some(l)) if b.join("rmtxop").is_file() => Some(Oracle { bin: b, lib: l }),
        _ => {
            if std::env::var("CI").is_ok_and(|v| v == "true") {
                panic!("the reference implementation is required under CI: run scripts/oracle.sh");
            }
            eprintln!("note: reference implementation not found (run scripts/oracle.sh); differential test skipped");
            // scripts/test.sh counts the skipped tests from this log (one line each)
            if let Some(log) = std::env::var_os("FENESTRA_SKIP_LOG") {
                use std::io::Write as _;
                if let Ok(mut f) = std::fs::OpenOptions::new().append(true).open(log) {
                    let _ = writeln!(f, "skipped");
                }
            }
            None
        }
    }
}

/// A command running one of our binaries (built by cargo for the integration tests).
pub fn fenestra(name: &str) -> Command {
    let exe = std::env::current_exe().expect("test executable path");
    // target/<profile>/deps/<test> → target/<profile>/<name>
    let dir = exe.parent().and_then(Path::parent).expect("target folder");
    let mut c = Command::new(dir.join(name));
    c.env("FENESTRA_LIB", repo().join("lib"));
    c.env("FENESTRA_NO_PROGRESS", "1");
    c
}

/// fenestra's library folder (`lib/`: its .cal files).
pub fn fenestra_lib() -> PathBuf {
    repo().join("lib")
}

/// A file or folder under `tests/fixtures/`.
pub fn fixture(rel: &str) -> PathBuf {
    repo().join("tests/fixtures").join(rel)
}

/// A fresh scratch folder for one test.
pub fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("fenestra-test-{}-{}", name, std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("scratch folder");
    d
}

/// A scratch copy (`name`) of the reference office (tests/fixtures/rtrace_threephase_bsdf):
/// materials, room, exterior, sky function and sensors, and the fixture folder's `extra` files.
pub fn office_scratch(name: &str, extra: &[&str]) -> PathBuf {
    let dir = scratch(name);
    let src = fixture("rtrace_threephase_bsdf");
    let base = [
        "materials.rad",
        "room.rad",
        "exterior.rad",
        "skyfunc_glow.rad",
        "sensors.pts",
    ];
    for f in base.iter().chain(extra) {
        std::fs::copy(src.join(f), dir.join(f)).unwrap();
    }
    dir
}

/// Runs a command, asserting success, and returns its stdout.
pub fn run_ok(cmd: &mut Command) -> Vec<u8> {
    output_ok(cmd).stdout
}

/// Runs a command, asserting success, and returns its whole output (stdout, and stderr
/// with its messages and `-v` lines).
pub fn output_ok(cmd: &mut Command) -> std::process::Output {
    let what = format!("{cmd:?}");
    output_named(cmd, &what)
}

/// Runs a command, asserting success (`what` names it in the messages); returns its output.
fn output_named(cmd: &mut Command, what: &str) -> std::process::Output {
    let out = cmd
        .output()
        .unwrap_or_else(|e| panic!("cannot run {what}: {e}"));
    check_status(&out, &format!("{what} failed"));
    out
}

/// Asserts that a tool succeeded, else panics with `msg`, its exit status and its stderr.
#[track_caller]
fn check_status(out: &std::process::Output, msg: &str) {
    assert!(
        out.status.success(),
        "{msg} ({}): {}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Asserts that a tool succeeded, else panics with its stderr.
#[track_caller]
pub fn assert_ok(out: &std::process::Output) {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Runs a command that must fail (the failure message is `what`); returns its stdout and its
/// stderr as text.
pub fn output_err(cmd: &mut Command, what: &str) -> (Vec<u8>, String) {
    let out = cmd
        .output()
        .unwrap_or_else(|e| panic!("cannot run {cmd:?}: {e}"));
    assert!(!out.status.success(), "{what}");
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    (out.stdout, err)
}

/// Runs a command with `input` on its stdin and returns its whole output. A tool that
/// exits before reading its input (e.g. after rejecting a scene) is not an error here:
/// the broken pipe is ignored and the exit status tells the rest.
pub fn run_stdin(mut cmd: Command, input: &[u8]) -> std::process::Output {
    use std::io::Write;
    use std::process::Stdio;
    let mut child = cmd
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| panic!("cannot run {cmd:?}: {e}"));
    let mut stdin = child.stdin.take().expect("stdin");
    // Feed from a thread so a tool writing much output before reading all its input
    // cannot deadlock against us.
    let input = input.to_vec();
    let feeder = std::thread::spawn(move || {
        let _ = stdin.write_all(&input);
    });
    let out = child.wait_with_output().expect("wait");
    let _ = feeder.join();
    out
}

/// [`run_stdin`], asserting success (the failure shows the tool's stderr).
pub fn run_stdin_ok(cmd: Command, input: &[u8]) -> std::process::Output {
    let out = run_stdin(cmd, input);
    check_status(&out, "failed");
    out
}

/// [`run_stdin`], asserting success (the failure message is the tool's stderr); returns its
/// stdout.
#[track_caller]
pub fn pipe_ok(cmd: Command, input: &[u8]) -> Vec<u8> {
    let out = run_stdin(cmd, input);
    assert_ok(&out);
    out.stdout
}

/// Runs a repository script (`bash REPO/rel args…`) with the test build's binaries
/// (`FENESTRA_BIN`), no progress bars and `env`, asserting success; returns its stdout.
pub fn run_script(rel: &str, args: &[&std::ffi::OsStr], env: &[(&str, &Path)]) -> String {
    let exe = std::env::current_exe().unwrap();
    let bin = exe.parent().and_then(Path::parent).unwrap().to_path_buf();
    let mut c = Command::new("bash");
    c.arg(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(rel))
        .args(args)
        .env("FENESTRA_BIN", &bin)
        .env("FENESTRA_NO_PROGRESS", "1");
    for (k, v) in env {
        c.env(k, v);
    }
    let out = output_named(&mut c, rel);
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The whitespace-separated numbers of a tool's text output.
pub fn numbers(out: &[u8]) -> Vec<f64> {
    String::from_utf8_lossy(out)
        .split_whitespace()
        .map(|w| {
            w.parse()
                .unwrap_or_else(|_| panic!("not a number in the output: '{w}'"))
        })
        .collect()
}

/// Runs `scene.rad` in `dir` through the reference rtrace (after its oconv) and ours with
/// the same options and rays; returns (theirs, ours), having checked both succeeded and
/// gave as many numbers.
pub fn both_rtrace(oracle: &Oracle, dir: &Path, opts: &[&str], rays: &str) -> (Vec<f64>, Vec<f64>) {
    oracle_octree(oracle, dir, &["scene.rad"]);
    let mut theirs = oracle.command("rtrace");
    theirs.args(opts).arg("scene.oct").current_dir(dir);
    let t = pipe_ok(theirs, rays.as_bytes());
    let mut ours = fenestra("rtrace");
    ours.args(opts).arg("scene.rad").current_dir(dir);
    let o = pipe_ok(ours, rays.as_bytes());
    let (t, o) = (numbers(&t), numbers(&o));
    assert_eq!(t.len(), o.len());
    (t, o)
}

/// Compiles the scene files `scene` of `dir` with the oracle's oconv into `dir/scene.oct`.
pub fn oracle_octree(oracle: &Oracle, dir: &Path, scene: &[&str]) {
    let mut c = oracle.command("oconv");
    c.args(scene).current_dir(dir);
    std::fs::write(dir.join("scene.oct"), run_ok(&mut c)).unwrap();
}

/// Direct light without jitter (`-ab 0 -ss 0`, the oracle also `-aa 0`: deterministic in both
/// tools) along `rays` in the scene files `scene` of `dir`: the oracle's rtrace (on the octree
/// of its oconv) and ours (RAYPATH `dir`); returns (theirs, ours), as many numbers each.
pub fn direct_both(
    oracle: &Oracle,
    dir: &Path,
    scene: &[&str],
    rays: &str,
) -> (Vec<f64>, Vec<f64>) {
    oracle_octree(oracle, dir, scene);
    let mut c = oracle.command("rtrace");
    c.args(["-h", "-aa", "0", "-ab", "0", "-ss", "0", "scene.oct"])
        .current_dir(dir);
    let theirs = numbers(&pipe_ok(c, rays.as_bytes()));
    let mut c = fenestra("rtrace");
    c.args(["-h", "-ab", "0", "-ss", "0"])
        .args(scene)
        .current_dir(dir);
    c.env("RAYPATH", dir);
    let ours = numbers(&pipe_ok(c, rays.as_bytes()));
    assert_eq!(theirs.len(), ours.len());
    (theirs, ours)
}

/// A tool's output without its first line (the command, which names the program path).
pub fn tail(b: &[u8]) -> String {
    let s = String::from_utf8_lossy(b);
    s.split_once('\n').map(|x| x.1).unwrap_or("").to_string()
}

/// Runs the oracle's `tool` and ours on each of `cases` (when the oracle is present), hands
/// `check` the case and both outputs (theirs, ours), and asserts that the outputs' [`tail`]s
/// are identical; the cases that differ are printed with both texts.
pub fn tails_match_oracle(
    tool: &str,
    cases: &[Vec<String>],
    check: impl Fn(&[String], &std::process::Output, &std::process::Output),
) {
    let Some(o) = oracle() else { return };
    let mut bad = Vec::new();
    for a in cases {
        let want = o.command(tool).args(a).output().unwrap();
        let got = fenestra(tool).args(a).output().unwrap();
        check(a, &want, &got);
        let (w, g) = (tail(&want.stdout), tail(&got.stdout));
        if w != g {
            bad.push(format!("{}\n--- oracle\n{w}--- ours\n{g}", a.join(" ")));
        }
    }
    for b in &bad {
        eprintln!("{b}");
    }
    assert!(bad.is_empty(), "{} of {} differ", bad.len(), cases.len());
}

/// A xorshift64 generator of numbers in [0, 1) from `seed` (test data that is the same
/// on every run and machine).
pub fn xorshift(mut seed: u64) -> impl FnMut() -> f64 {
    move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A 64-bit linear congruential generator (Knuth's MMIX constants): test cases that are the
/// same on every run and machine, without external crates.
pub struct Lcg(pub u64);

impl Lcg {
    /// Advances the state and returns it.
    pub fn step(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        self.0
    }

    /// The top 31 bits of the next state.
    pub fn bits(&mut self) -> u64 {
        self.step() >> 33
    }

    /// A number in [0, 1): the top 53 bits of the next state.
    pub fn unit(&mut self) -> f64 {
        (self.step() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A number from `lo` (included) to `hi` (excluded).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    /// One of the words `v`, each as likely.
    pub fn pick<'a>(&mut self, v: &[&'a str]) -> &'a str {
        v[(self.unit() * v.len() as f64) as usize % v.len()]
    }
}

/// Asserts |a − b| ≤ `rel`·|a| + `abs` for each pair of the oracle's values `theirs` and
/// fenestra's `ours` (lists of equal length); returns the largest relative difference over
/// the oracle's positive values, for the tests to print.
pub fn agree(what: &str, theirs: &[f64], ours: &[f64], rel: f64, abs: f64) -> f64 {
    assert_eq!(theirs.len(), ours.len(), "{what}");
    let mut worst = 0.0f64;
    for (k, (a, b)) in theirs.iter().zip(ours).enumerate() {
        assert!(
            (a - b).abs() <= rel * a.abs() + abs,
            "{what} value {k}: oracle {a} ours {b}"
        );
        if *a > 0.0 {
            worst = worst.max((a - b).abs() / a);
        }
    }
    worst
}

/// Mean of `v` and the standard error of that mean.
pub fn mean_sem(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (n - 1.0);
    (m, (var / n).sqrt())
}

/// Runs fenestra's rtrace on `scene` (written to a scratch directory named `scratch`) and
/// asserts that it fails with every string of `want` in its error output.
pub fn fails_with(scratch_name: &str, scene: &str, want: &[&str]) {
    let dir = scratch(scratch_name);
    std::fs::write(dir.join("bad.rad"), scene).unwrap();
    let mut c = fenestra("rtrace");
    c.args(["-h", "bad.rad"]).current_dir(&dir);
    let out = run_stdin(c, b"0 0 0 0 0 1\n");
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    for w in want {
        assert!(err.contains(w), "missing '{w}' in: {err}");
    }
}

/// Red plastic slats (6, tilted 30°) over a 0.3 m square sample, in genBSDF's frame.
pub fn red_slats() -> String {
    let mut s = String::from("void plastic redslat 0 0 5 0.7 0.25 0.1 0 0\n");
    for k in 0..6 {
        let (yc, a) = (0.025 + 0.05 * k as f64, 30f64.to_radians());
        let (dy, dz) = (0.0225 * a.sin(), 0.0225 * a.cos());
        s.push_str(&format!(
            "redslat polygon slat{k} 0 0 12 0 {:.5} {:.5} 0.3 {:.5} {:.5} 0.3 {:.5} {:.5} 0 {:.5} {:.5}\n",
            yc - dy,
            -0.02 - dz,
            yc - dy,
            -0.02 - dz,
            yc + dy,
            -0.02 + dz,
            yc + dy,
            -0.02 + dz
        ));
    }
    s
}
