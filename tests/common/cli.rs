//! Shared helpers for running command-line tools in tests (arguments, outputs, errors).

use std::fmt::Debug;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use super::Oracle;

/// The oracle and a fresh scratch folder `name` for a differential test; `None` (the test
/// is skipped) without the oracle.
pub fn oracle_scratch(name: &str) -> Option<(Oracle, PathBuf)> {
    let oracle = super::oracle()?;
    Some((oracle, super::scratch(name)))
}

/// Writes `contents` to the file `file` of a fresh scratch folder `name`; returns the file's
/// path.
pub fn scratch_file(name: &str, file: &str, contents: impl AsRef<[u8]>) -> PathBuf {
    let path = super::scratch(name).join(file);
    std::fs::write(&path, contents).unwrap();
    path
}

/// A fresh scratch folder `name` holding `files` (file name, text).
pub fn scratch_files(name: &str, files: &[(&str, &str)]) -> PathBuf {
    let dir = super::scratch(name);
    for (file, text) in files {
        std::fs::write(dir.join(file), text).unwrap();
    }
    dir
}

/// Runs our `tool` in `dir` with each of `cases` (argument lists), asserting that each
/// fails; returns the stdout and the error output of each.
pub fn failures(tool: &str, dir: &Path, cases: &[&[&str]]) -> Vec<(Vec<u8>, String)> {
    cases
        .iter()
        .map(|args| {
            let mut c = super::fenestra(tool);
            c.args(*args).current_dir(dir);
            super::output_err(&mut c, &format!("{tool} {args:?} succeeded"))
        })
        .collect()
}

/// Asserts that the run `out` failed with `want` in its error output; the failure message
/// names the case, `what`, and shows that output.
pub fn assert_refused(out: &Output, want: &str, what: impl Debug) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains(want),
        "{what:?}: {err}"
    );
}

/// Asserts that `text` contains each of `words`; the failure message shows `text`.
pub fn assert_contains(text: &str, words: &[&str]) {
    for w in words {
        assert!(text.contains(w), "{text}");
    }
}

/// Runs `cmd` in `dir` with `opts` and the scene file `scene`, `rays` on its stdin,
/// asserting success; returns the numbers it prints.
pub fn scene_numbers(
    mut cmd: Command,
    dir: &Path,
    opts: &[&str],
    scene: &str,
    rays: &[u8],
) -> Vec<f64> {
    cmd.args(opts).arg(scene).current_dir(dir);
    super::numbers(&super::pipe_ok(cmd, rays))
}

/// Runs the oracle's `tool` on `scene.oct` and ours on `scene.rad` in `dir` with the same
/// options and rays, asserting both succeed; returns their numbers (theirs, ours).
pub fn both_numbers(
    oracle: &Oracle,
    tool: &str,
    dir: &Path,
    opts: &[&str],
    rays: &[u8],
) -> (Vec<f64>, Vec<f64>) {
    let theirs = scene_numbers(oracle.command(tool), dir, opts, "scene.oct", rays);
    let ours = scene_numbers(super::fenestra(tool), dir, opts, "scene.rad", rays);
    (theirs, ours)
}
