//! A resumable genBSDF run (`-checkpoint file`): every incident direction's sums are
//! appended to the file as soon as they are traced (exact f64 bits, one line each), and a
//! run given the same file continues where a killed one stopped, skipping what is there.
//! The first line is a key of everything that fixes the numbers (options, bounding box,
//! sample grid, scene); a file made by another run is refused. Every direction's random
//! numbers depend only on the seed and its index, so a resumed run writes the same bytes
//! as an uninterrupted one. A last line cut short by the kill is ignored (traced again).

use std::collections::HashMap;
use std::io::{BufRead, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use anyhow::{bail, Context, Result};

/// Sums of one incident direction, as the characterisation keeps them.
pub(crate) type Sums = [Vec<f64>; 4];

/// An open checkpoint: what earlier runs finished, and the file to append to.
pub(crate) struct Checkpoint {
    path: PathBuf,
    done: HashMap<(usize, usize), Sums>,
    file: Mutex<std::fs::File>,
}

fn encode(v: &[f64]) -> String {
    let words: Vec<String> = v.iter().map(|x| format!("{:x}", x.to_bits())).collect();
    words.join(",")
}

fn decode(s: &str) -> Option<Vec<f64>> {
    if s.is_empty() {
        return Some(Vec::new());
    }
    s.split(',')
        .map(|w| u64::from_str_radix(w, 16).ok().map(f64::from_bits))
        .collect()
}

impl Checkpoint {
    /// Opens (or starts) the checkpoint `path` for a run whose numbers are fixed by `key`.
    pub(crate) fn open(path: &Path, key: &str) -> Result<Checkpoint> {
        let mut done = HashMap::new();
        // version 2: the Sobol sampler (a version-1 file holds another sampler's sums)
        let key_line = format!("fenestra genBSDF checkpoint 2 {key}");
        let exists = path.exists();
        if exists {
            let f = std::fs::File::open(path)
                .with_context(|| format!("cannot read checkpoint '{}'", path.display()))?;
            let mut lines = std::io::BufReader::new(f).lines();
            match lines.next() {
                Some(Ok(l)) if l == key_line => {}
                Some(Ok(_)) => bail!(
                    "{}: a checkpoint of another run (other options, samples or scene); remove it or name another file",
                    path.display()
                ),
                _ => bail!("{}: not a genBSDF checkpoint", path.display()),
            }
            for line in lines {
                let Ok(line) = line else { break };
                let f: Vec<&str> = line.split(' ').collect();
                if f.len() != 6 {
                    continue; // cut short by the kill
                }
                let (Ok(side), Ok(i)) = (f[0].parse(), f[1].parse()) else {
                    continue;
                };
                let parts: Option<Vec<Vec<f64>>> = f[2..].iter().map(|s| decode(s)).collect();
                if let Some(p) = parts {
                    let [a, b, c, d]: [Vec<f64>; 4] = p.try_into().expect("four parts");
                    done.insert((side, i), [a, b, c, d]);
                }
            }
        }
        let mut file = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(path)
            .with_context(|| format!("cannot write checkpoint '{}'", path.display()))?;
        if !exists {
            writeln!(file, "{key_line}")?;
        }
        Ok(Checkpoint {
            path: path.to_path_buf(),
            done,
            file: Mutex::new(file),
        })
    }

    /// The sums an earlier run stored for direction `i` of side `side`.
    pub(crate) fn get(&self, side: usize, i: usize) -> Option<&Sums> {
        self.done.get(&(side, i))
    }

    /// Directions already done.
    pub(crate) fn len(&self) -> usize {
        self.done.len()
    }

    /// Appends a finished direction (one write, flushed, so a kill loses at most it).
    pub(crate) fn put(&self, side: usize, i: usize, s: &Sums) -> Result<()> {
        let line = format!(
            "{side} {i} {} {} {} {}\n",
            encode(&s[0]),
            encode(&s[1]),
            encode(&s[2]),
            encode(&s[3])
        );
        let mut f = self.file.lock().unwrap_or_else(|e| e.into_inner());
        f.write_all(line.as_bytes())?;
        f.flush()?;
        Ok(())
    }

    /// The run finished: the checkpoint is removed.
    pub(crate) fn finish(self) -> Result<()> {
        drop(self.file);
        std::fs::remove_file(&self.path)
            .with_context(|| format!("cannot remove checkpoint '{}'", self.path.display()))
    }
}

/// A key of the values that fix a run's numbers.
pub(crate) fn key(parts: &str) -> String {
    // FNV-1a, 64 bits: stable across Rust versions (std's hasher is not promised to be)
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in parts.as_bytes() {
        h ^= u64::from(*b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    format!("{h:016x}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_resume_and_refusal() {
        let dir = std::env::temp_dir().join(format!("fenestra-ckpt-{}", std::process::id()));
        let _ = std::fs::create_dir_all(&dir);
        let p = dir.join("c.ckpt");
        let _ = std::fs::remove_file(&p);
        let s: Sums = [vec![0.1, 1.0 / 3.0], vec![], vec![2.5], vec![-0.0]];
        let c = Checkpoint::open(&p, "k1").unwrap();
        assert_eq!(c.len(), 0);
        c.put(0, 7, &s).unwrap();
        drop(c);
        // a kill in the middle of a line
        let mut f = std::fs::OpenOptions::new().append(true).open(&p).unwrap();
        f.write_all(b"0 8 3fb999").unwrap();
        drop(f);
        let c = Checkpoint::open(&p, "k1").unwrap();
        assert_eq!(c.len(), 1);
        assert_eq!(c.get(0, 7).unwrap(), &s);
        assert!(c.get(0, 8).is_none());
        drop(c);
        assert!(Checkpoint::open(&p, "k2").is_err());
        let c = Checkpoint::open(&p, "k1").unwrap();
        c.finish().unwrap();
        assert!(!p.exists());
        assert_ne!(key("a"), key("b"));
    }
}
