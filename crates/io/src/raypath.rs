//! Finding auxiliary files (.cal, data, XML) through `RAYPATH`, as Radiance does.
//!
//! Names containing a `/` (absolute, `./x`, `dir/x`) are used as given. Other names
//! are looked up in each folder of `RAYPATH` (colon separated; default `.`), then in
//! fenestra's own `lib/` folder, which is found next to the binaries (`bin/../lib`,
//! `bin/lib`, or installed under `share/fenestra/lib`), through `FENESTRA_LIB`, or in the
//! source tree when run with `cargo run`/`cargo test`.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, Result};

/// The file that marks a folder as fenestra's library.
const MARKER: &str = "fenestra-lib.txt";

/// fenestra's own library folder, if it can be found.
pub fn lib_dir() -> Option<PathBuf> {
    if let Some(d) = std::env::var_os("FENESTRA_LIB") {
        let d = PathBuf::from(d);
        if d.is_dir() {
            return Some(d);
        }
    }
    if let Ok(exe) = std::env::current_exe() {
        if let Some(bin) = exe.parent() {
            for cand in [
                bin.join("lib"),
                bin.join("../lib"),
                bin.join("../share/fenestra/lib"),
                // target/{debug,release}[/deps] inside the source tree
                bin.join("../../lib"),
                bin.join("../../../lib"),
            ] {
                if cand.join(MARKER).is_file() {
                    return Some(cand);
                }
            }
        }
    }
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../lib");
    src.join(MARKER).is_file().then_some(src)
}

/// The folders searched, in order.
pub fn search_dirs() -> Vec<PathBuf> {
    let mut dirs: Vec<PathBuf> = match std::env::var("RAYPATH") {
        Ok(p) if !p.is_empty() => p
            .split(':')
            .map(|d| PathBuf::from(if d.is_empty() { "." } else { d }))
            .collect(),
        _ => vec![PathBuf::from(".")],
    };
    if let Some(l) = lib_dir() {
        dirs.push(l);
    }
    dirs
}

/// Finds `name` on the search path.
pub fn find(name: &str) -> Option<PathBuf> {
    if name.contains('/') {
        let p = PathBuf::from(name);
        return p.is_file().then_some(p);
    }
    search_dirs()
        .into_iter()
        .map(|d| d.join(name))
        .find(|p| p.is_file())
}

/// Finds `name` or fails with a message listing where it looked.
pub fn find_or_err(name: &str) -> Result<PathBuf> {
    find(name).ok_or_else(|| {
        if name.contains('/') {
            anyhow!("cannot find file '{name}'")
        } else {
            let dirs: Vec<String> = search_dirs()
                .iter()
                .map(|d| d.display().to_string())
                .collect();
            anyhow!(
                "cannot find file '{name}' (searched RAYPATH: {})",
                dirs.join(":")
            )
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn missing_file_error_names_it() {
        let e = find_or_err("surely-missing-file.cal")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("surely-missing-file.cal") && e.contains("RAYPATH"),
            "{e}"
        );
    }

    #[test]
    fn own_lib_is_on_the_path() {
        // The source tree's lib/ is found when running from cargo.
        let dirs = search_dirs();
        assert!(dirs.iter().any(|d| d.join(MARKER).is_file()), "{dirs:?}");
    }
}
