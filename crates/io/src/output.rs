//! Output files that appear whole or not at all. A new or regular file is written under a
//! temporary name in the same folder and renamed over the target on
//! [`AtomicFile::commit`]; dropped uncommitted (an error, a panic) or interrupted by
//! SIGINT/SIGTERM/SIGHUP, the temporary file is removed. A target that exists and is
//! not a regular file (a symbolic link, a named pipe, a device such as `/dev/null`) is
//! written through, as Radiance does: renaming over it would replace the link, pipe or
//! device node.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

/// How an output path is to be written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// Missing or a regular file: written aside and renamed into place.
    Replace,
    /// A symbolic link, named pipe, device or socket: opened and written through.
    Through,
}

/// Decides how `path` is written (a directory is an error).
pub fn target_kind(path: &Path) -> Result<Target> {
    match std::fs::symlink_metadata(path) {
        Err(_) => Ok(Target::Replace),
        Ok(m) if m.file_type().is_file() => Ok(Target::Replace),
        Ok(m) if m.is_dir() => bail!(
            "cannot write output '{}': it is a directory",
            path.display()
        ),
        Ok(_) => Ok(Target::Through),
    }
}

/// A file written under a temporary name and renamed into place on commit (or written
/// straight through when the target is a link, pipe or device).
pub struct AtomicFile {
    target: PathBuf,
    tmp: Option<PathBuf>,
    w: Option<BufWriter<File>>,
}

impl AtomicFile {
    /// Starts writing `path` (nothing appears at a regular `path` until [`commit`](Self::commit)).
    pub fn create(path: impl AsRef<Path>) -> Result<Self> {
        let target = path.as_ref().to_path_buf();
        if target_kind(&target)? == Target::Through {
            let f = std::fs::OpenOptions::new()
                .write(true)
                .truncate(true)
                .open(&target)
                .with_context(|| format!("cannot open output '{}'", target.display()))?;
            return Ok(AtomicFile {
                target,
                tmp: None,
                w: Some(BufWriter::with_capacity(1 << 16, f)),
            });
        }
        let name = target
            .file_name()
            .with_context(|| format!("output '{}' is not a file name", target.display()))?;
        let tmp = target.with_file_name(format!(
            ".{}.{}.tmp",
            name.to_string_lossy(),
            std::process::id()
        ));
        let f = File::create(&tmp)
            .with_context(|| format!("cannot create output file '{}'", target.display()))?;
        crate::cleanup::register(&tmp);
        Ok(AtomicFile {
            target,
            tmp: Some(tmp),
            w: Some(BufWriter::with_capacity(1 << 16, f)),
        })
    }

    /// The final path.
    pub fn path(&self) -> &Path {
        &self.target
    }

    /// Flushes, syncs and renames the data into place (a written-through target is flushed).
    pub fn commit(mut self) -> Result<()> {
        let w = self.w.take().expect("writer present until commit");
        let f = w
            .into_inner()
            .map_err(|e| e.into_error())
            .with_context(|| format!("cannot write output file '{}'", self.target.display()))?;
        let Some(tmp) = self.tmp.take() else {
            return Ok(());
        };
        f.sync_all().ok();
        drop(f);
        let moved = std::fs::rename(&tmp, &self.target);
        crate::cleanup::unregister(&tmp);
        if moved.is_err() {
            let _ = std::fs::remove_file(&tmp);
        }
        moved.with_context(|| {
            format!(
                "cannot move output into place at '{}'",
                self.target.display()
            )
        })
    }
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.w.as_mut().map_or(Ok(0), |w| w.write(buf))
    }
    fn write_all(&mut self, buf: &[u8]) -> std::io::Result<()> {
        match self.w.as_mut() {
            Some(w) => w.write_all(buf),
            None => Ok(()),
        }
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.w.as_mut().map_or(Ok(()), |w| w.flush())
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if self.w.take().is_some() {
            if let Some(tmp) = self.tmp.take() {
                let _ = std::fs::remove_file(&tmp);
                crate::cleanup::unregister(&tmp);
            }
        }
    }
}

/// Where standard output stands when it is a regular file (Radiance pads binary headers
/// so the data start aligned in files, not in pipes); `None` for pipes and terminals.
pub fn stdout_file_offset() -> Option<u64> {
    #[cfg(unix)]
    {
        use std::io::Seek;
        use std::os::fd::AsFd;
        let fd = std::io::stdout().as_fd().try_clone_to_owned().ok()?;
        let mut f = std::fs::File::from(fd);
        if !f.metadata().ok()?.is_file() {
            return None;
        }
        f.stream_position().ok()
    }
    #[cfg(not(unix))]
    {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("fen-atomic-{tag}-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn uncommitted_file_leaves_nothing() {
        let dir = dir("plain");
        let p = dir.join("out.dat");
        {
            let mut f = AtomicFile::create(&p).unwrap();
            f.write_all(b"partial").unwrap();
        }
        assert!(!p.exists());
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0);
        let mut f = AtomicFile::create(&p).unwrap();
        f.write_all(b"whole").unwrap();
        f.commit().unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"whole");
        std::fs::remove_dir_all(&dir).ok();
    }

    #[cfg(unix)]
    #[test]
    fn symlink_is_written_through() {
        let dir = dir("link");
        let real = dir.join("real.dat");
        std::fs::write(&real, b"old").unwrap();
        let link = dir.join("link.dat");
        std::os::unix::fs::symlink(&real, &link).unwrap();
        let mut f = AtomicFile::create(&link).unwrap();
        f.write_all(b"new data").unwrap();
        f.commit().unwrap();
        assert!(std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(std::fs::read(&real).unwrap(), b"new data");
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn directory_is_an_error() {
        let dir = dir("isdir");
        let e = AtomicFile::create(&dir).err().unwrap();
        assert!(format!("{e:#}").contains("is a directory"), "{e:#}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
