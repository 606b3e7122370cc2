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

/// Where auxiliary files are looked up: the folders of `RAYPATH` and fenestra's library,
/// read once ([`Resolver::from_env`]) or given ([`Resolver::new`]). Libraries take one from
/// their caller instead of reading the environment themselves.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Resolver {
    dirs: Vec<PathBuf>,
}

impl Default for Resolver {
    fn default() -> Self {
        Self::from_env()
    }
}

impl Resolver {
    /// The folders of `RAYPATH` (default `.`), then fenestra's library folder.
    pub fn from_env() -> Self {
        Resolver {
            dirs: search_dirs(),
        }
    }

    /// Exactly these folders, in order.
    pub fn new(dirs: Vec<PathBuf>) -> Self {
        Resolver { dirs }
    }

    /// The folders searched, in order.
    pub fn dirs(&self) -> &[PathBuf] {
        &self.dirs
    }

    /// Finds `name` (used as given when it contains a `/`).
    pub fn find(&self, name: &str) -> Option<PathBuf> {
        if name.contains('/') {
            let p = PathBuf::from(name);
            return p.is_file().then_some(p);
        }
        self.dirs.iter().map(|d| d.join(name)).find(|p| p.is_file())
    }

    /// Finds `name` or fails with a message listing where it looked.
    pub fn find_or_err(&self, name: &str) -> Result<PathBuf> {
        self.find(name).ok_or_else(|| {
            if name.contains('/') {
                anyhow!("cannot find file '{name}'")
            } else {
                let dirs: Vec<String> = self.dirs.iter().map(|d| d.display().to_string()).collect();
                anyhow!(
                    "cannot find file '{name}' (searched RAYPATH: {})",
                    dirs.join(":")
                )
            }
        })
    }
}

/// Finds `name` on the search path of the environment ([`Resolver::from_env`]).
pub fn find(name: &str) -> Option<PathBuf> {
    Resolver::from_env().find(name)
}

/// Finds `name` on the environment's search path or fails with a message listing where
/// it looked.
pub fn find_or_err(name: &str) -> Result<PathBuf> {
    Resolver::from_env().find_or_err(name)
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
    fn given_folders_are_searched_in_order() {
        let dir = std::env::temp_dir().join(format!("fenestra-resolver-{}", std::process::id()));
        let (a, b) = (dir.join("a"), dir.join("b"));
        std::fs::create_dir_all(&a).unwrap();
        std::fs::create_dir_all(&b).unwrap();
        std::fs::write(b.join("x.cal"), "x=1;").unwrap();
        std::fs::write(a.join("y.cal"), "y=1;").unwrap();
        std::fs::write(b.join("y.cal"), "y=2;").unwrap();
        let r = Resolver::new(vec![a.clone(), b.clone()]);
        assert_eq!(r.find("x.cal"), Some(b.join("x.cal")));
        assert_eq!(r.find("y.cal"), Some(a.join("y.cal")));
        let e = r.find_or_err("z.cal").unwrap_err().to_string();
        assert!(
            e.contains("z.cal") && e.contains(&a.display().to_string()),
            "{e}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn own_lib_is_on_the_path() {
        // The source tree's lib/ is found when running from cargo.
        let dirs = search_dirs();
        assert!(dirs.iter().any(|d| d.join(MARKER).is_file()), "{dirs:?}");
    }
}
