//! Shared helpers for the light-source and irradiance tests (scenes probed with rtrace).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use super::Oracle;

/// A fresh scratch folder `name` holding `scene` as `scene.rad`.
pub fn scene_dir(name: &str, scene: &str) -> PathBuf {
    let dir = super::scratch(name);
    std::fs::write(dir.join("scene.rad"), scene).unwrap();
    dir
}

/// The oracle and [`scene_dir`]`(name, scene)`; `None`, with nothing written, where the
/// oracle is missing (see [`super::oracle`]).
pub fn oracle_scene(name: &str, scene: &str) -> Option<(Oracle, PathBuf)> {
    let oracle = super::oracle()?;
    Some((oracle, scene_dir(name, scene)))
}

/// Runs `cmd` in `dir` with `args`, then `scene`, and `input` on its stdin; asserts success
/// (see [`super::run_stdin_ok`]) and returns its output.
fn run_in(mut cmd: Command, dir: &Path, args: &[&str], scene: &str, input: &[u8]) -> Output {
    cmd.args(args).arg(scene).current_dir(dir);
    super::run_stdin_ok(cmd, input)
}

/// Runs our `tool` in `dir` with `args`, then `scene`, and `input` on its stdin; asserts
/// success and returns its output.
pub fn ours(tool: &str, dir: &Path, args: &[&str], scene: &str, input: &[u8]) -> Output {
    run_in(super::fenestra(tool), dir, args, scene, input)
}

/// Runs the reference `tool` on the octree of `scene.rad` in `dir` (made by its oconv) and
/// ours on `scene.rad`, with the same `args` and `rays`; returns the numbers each printed,
/// (theirs, ours), having checked that both succeeded.
pub fn both(
    oracle: &Oracle,
    dir: &Path,
    tool: &str,
    args: &[&str],
    rays: &str,
) -> (Vec<f64>, Vec<f64>) {
    let mut oconv = oracle.command("oconv");
    oconv.arg("scene.rad").current_dir(dir);
    std::fs::write(dir.join("scene.oct"), super::run_ok(&mut oconv)).unwrap();
    let input = rays.as_bytes();
    let theirs = run_in(oracle.command(tool), dir, args, "scene.oct", input);
    let mine = ours(tool, dir, args, "scene.rad", input);
    (super::numbers(&theirs.stdout), super::numbers(&mine.stdout))
}

/// Writes `scene` as `file` in a fresh scratch folder `name` and runs our rtrace there with
/// `args`, then `file`, on `rays`; asserts success and that its stderr holds every string of
/// `want`; returns the numbers it printed.
pub fn rtrace_file(
    name: &str,
    file: &str,
    scene: &str,
    args: &[&str],
    rays: &[u8],
    want: &[&str],
) -> Vec<f64> {
    let dir = super::scratch(name);
    std::fs::write(dir.join(file), scene).unwrap();
    let out = ours("rtrace", &dir, args, file, rays);
    let err = String::from_utf8_lossy(&out.stderr);
    for w in want {
        assert!(err.contains(w), "{err}");
    }
    super::numbers(&out.stdout)
}

/// [`super::agree`], then prints the largest relative difference after `what`.
pub fn agree_noted(what: &str, theirs: &[f64], ours: &[f64], rel: f64, abs: f64) {
    let worst = super::agree(what, theirs, ours, rel, abs);
    eprintln!("{what}: largest relative difference {worst:.3e}");
}

/// Asserts that at least `min_lit` of the oracle's values `theirs` are positive, then
/// [`super::agree`]; prints the largest relative difference (2 digits) after `what`.
pub fn agree_lit(what: &str, theirs: &[f64], ours: &[f64], min_lit: usize, rel: f64, abs: f64) {
    let lit = theirs.iter().filter(|v| **v > 0.0).count();
    assert!(lit >= min_lit, "{what}: only {lit} lit values");
    let worst = super::agree(what, theirs, ours, rel, abs);
    eprintln!("{what}: largest relative difference {worst:.2e}");
}

/// The mean and standard error of the red channel over records `k·reps` to `(k + 1)·reps − 1`
/// (RGB records), of the oracle's values `theirs` and of ours.
pub fn red_means(theirs: &[f64], ours: &[f64], k: usize, reps: usize) -> [(f64, f64); 2] {
    [theirs, ours].map(|v| {
        let reds: Vec<f64> = v[k * reps * 3..(k + 1) * reps * 3]
            .iter()
            .step_by(3)
            .copied()
            .collect();
        super::mean_sem(&reds)
    })
}

/// Asserts that the oracle's mean `mt` (standard error `st`) and ours `mo` (`so`) are at
/// most 5 combined standard errors apart; a failure starts with `what`.
pub fn means_agree(what: &str, [(mt, st), (mo, so)]: [(f64, f64); 2]) {
    let tol = 5.0 * (st * st + so * so).sqrt();
    assert!(
        (mt - mo).abs() <= tol,
        "{what}: oracle {mt} ± {st}, ours {mo} ± {so}"
    );
}

/// Asserts |a − b| ≤ 2e-5·max(|a|, 1e-3) for each pair of the oracle's values `theirs` and
/// ours (values printed with 6 digits, colours in single precision); the failure for value
/// `k` starts with `at(k)`, then "oracle a ours b".
pub fn agree_6_digits(theirs: &[f64], ours: &[f64], at: impl Fn(usize) -> String) {
    for (k, (a, b)) in theirs.iter().zip(ours).enumerate() {
        assert!(
            (a - b).abs() <= 2e-5 * a.abs().max(1e-3),
            "{}oracle {a} ours {b}",
            at(k)
        );
    }
}
