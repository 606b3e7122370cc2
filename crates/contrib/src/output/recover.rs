//! Partial output files and `-r`: where an interrupted run left its records, and the
//! sums an earlier `-c 0` run wrote.

use super::*;

use std::fs::File;
use std::io::{BufWriter, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

/// Where an output file is written until the run completes (then renamed over the output).
/// An interrupted run leaves it behind for `-r`.
pub fn partial_path(name: &str) -> PathBuf {
    let p = Path::new(name);
    let file = p
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_default();
    p.with_file_name(format!(".{file}.rtcontrib-partial"))
}

/// An output being written under its partial name.
/// A target that exists and is not a regular file (a link, pipe or device) is written
/// through, as Radiance does, and cannot be recovered with `-r`.
pub(super) struct PartialFile {
    target: PathBuf,
    tmp: Option<PathBuf>,
    w: Option<BufWriter<File>>,
}

impl PartialFile {
    pub(super) fn create(target: &str) -> Result<PartialFile> {
        use fenestra_cli::output::{target_kind, Target};
        if target_kind(Path::new(target))? == Target::Through {
            let f = std::fs::OpenOptions::new()
                .write(true)
                .truncate(true)
                .open(target)
                .with_context(|| format!("cannot open '{target}' for writing"))?;
            return Ok(PartialFile {
                target: PathBuf::from(target),
                tmp: None,
                w: Some(BufWriter::with_capacity(1 << 16, f)),
            });
        }
        let tmp = partial_path(target);
        let f = File::create(&tmp)
            .with_context(|| format!("cannot open '{target}' for writing ({})", tmp.display()))?;
        Ok(PartialFile {
            target: PathBuf::from(target),
            tmp: Some(tmp),
            w: Some(BufWriter::with_capacity(1 << 16, f)),
        })
    }

    /// Reopens the partial file of `target`, keeping its first `keep` bytes.
    pub(super) fn resume(target: &str, keep: u64) -> Result<PartialFile> {
        let tmp = partial_path(target);
        let mut f = std::fs::OpenOptions::new()
            .write(true)
            .open(&tmp)
            .with_context(|| format!("cannot reopen '{}' to recover", tmp.display()))?;
        f.set_len(keep)?;
        f.seek(SeekFrom::End(0))?;
        Ok(PartialFile {
            target: PathBuf::from(target),
            tmp: Some(tmp),
            w: Some(BufWriter::with_capacity(1 << 16, f)),
        })
    }

    pub(super) fn commit(mut self) -> Result<()> {
        if let Some(w) = self.w.take() {
            let f = w
                .into_inner()
                .map_err(|e| anyhow::anyhow!("write error on '{}': {e}", self.target.display()))?;
            if self.tmp.is_some() {
                f.sync_all().ok();
            }
        }
        match self.tmp.take() {
            Some(tmp) => std::fs::rename(&tmp, &self.target)
                .with_context(|| format!("cannot rename output into '{}'", self.target.display())),
            None => Ok(()),
        }
    }
}

impl Write for PartialFile {
    fn write(&mut self, b: &[u8]) -> std::io::Result<usize> {
        match &mut self.w {
            Some(w) => w.write(b),
            None => Ok(0),
        }
    }
    fn flush(&mut self) -> std::io::Result<()> {
        match &mut self.w {
            Some(w) => w.flush(),
            None => Ok(()),
        }
    }
}

impl Drop for PartialFile {
    fn drop(&mut self) {
        // an error (not a kill): no partial output is left behind
        if self.w.take().is_some() {
            if let Some(tmp) = &self.tmp {
                let _ = std::fs::remove_file(tmp);
            }
        }
    }
}

/// Bytes per record of a stream in a binary format (`None` for text).
pub fn record_size(plan: &StreamPlan, format: Format) -> Option<u64> {
    let per = match format {
        Format::Ascii => return None,
        Format::Float => 12,
        Format::Double => 24,
        Format::Rgbe | Format::Xyze => 4,
    };
    Some(per * plan.items.len() as u64)
}

/// What `-r` found for one output file: the bytes of its header and complete records.
#[derive(Debug, Clone, Copy)]
pub struct Partial {
    /// Header length (with the resolution line of a picture).
    pub header: u64,
    /// Complete records present.
    pub records: u64,
    /// The output was complete (no partial file): it is moved back to its partial name.
    pub complete: bool,
}

/// Examines an output for `-r`: `None` when neither it nor its partial file exists.
pub fn examine_partial(plan: &StreamPlan, format: Format) -> Result<Option<Partial>> {
    let Some(name) = plan.name.as_deref() else {
        bail!("cannot recover output written to the standard output");
    };
    if name.starts_with('!') {
        bail!("cannot recover output written to a command ({name})");
    }
    if fenestra_cli::output::target_kind(Path::new(name))? == fenestra_cli::output::Target::Through
    {
        bail!("cannot recover '{name}': it is a link, pipe or device, written through");
    }
    let rs = record_size(plan, format).context("cannot recover ASCII output")?;
    let tmp = partial_path(name);
    let (path, complete) = if tmp.exists() {
        (tmp, false)
    } else if Path::new(name).exists() {
        (PathBuf::from(name), true)
    } else {
        return Ok(None);
    };
    let data = std::fs::read(&path).with_context(|| format!("cannot read '{}'", path.display()))?;
    // an information header starts with "#?"; without one (-h-) the data start at once
    let mut h = if data.starts_with(b"#?") {
        data.windows(2)
            .position(|w| w == b"\n\n")
            .map(|p| p + 2)
            .with_context(|| format!("cannot recover '{name}': incomplete header"))?
    } else {
        0
    };
    if h > 0 {
        let head = String::from_utf8_lossy(&data[..h]);
        let want = format!("FORMAT={}", format.as_str());
        if !head.lines().any(|l| l == want) {
            bail!("cannot recover '{name}': its header does not say {want}");
        }
    }
    if data[h..].starts_with(b"-Y ") || data[h..].starts_with(b"+Y ") {
        match data[h..].iter().position(|&c| c == b'\n') {
            Some(e) => h += e + 1,
            None => bail!("cannot recover '{name}': incomplete resolution line"),
        }
    }
    let records = (data.len() - h) as u64 / rs;
    Ok(Some(Partial {
        header: h as u64,
        records,
        complete,
    }))
}

/// `-r` with `-c 0`: the sums an earlier run wrote to this stream's file, one RGB triple per
/// item, or `None` when there is no such file (a standard output or a command has none).
/// Any format Radiance's matrices and pictures come in is read.
pub fn reload_sums(plan: &StreamPlan) -> Result<Option<Vec<[f64; 3]>>> {
    let Some(name) = &plan.name else {
        return Ok(None);
    };
    if name.starts_with('!') || !std::path::Path::new(name).exists() {
        return Ok(None);
    }
    let m = fenestra_formats::matrix::Matrix::read_reporting(name, fenestra_cli::warn_note)
        .with_context(|| format!("cannot reload the sums in '{name}'"))?;
    let want = plan.items.len() * 3;
    if m.ncomp != 3 || m.data.len() != want {
        bail!(
            "reload file '{name}': {} values in {} component(s), expected {want} (3 per bin of this run's {} bin(s))",
            m.data.len(),
            m.ncomp,
            plan.items.len()
        );
    }
    if let Some(v) = m.data.iter().find(|v| !v.is_finite()) {
        bail!("reload file '{name}': the value {v} is not a number");
    }
    Ok(Some(
        m.data.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
    ))
}

/// Checks that files can be created (no existing file unless `overwrite`).
pub fn check_files(plans: &[StreamPlan], overwrite: bool) -> Result<()> {
    for p in plans {
        if let Some(n) = &p.name {
            if n.starts_with('!') {
                continue;
            }
            if !overwrite && std::path::Path::new(n).exists() {
                bail!("cannot open '{n}' for writing: the file exists (use -fo to overwrite)");
            }
            if !overwrite && partial_path(n).exists() {
                bail!(
                    "cannot open '{n}' for writing: '{}' holds the partial output of an interrupted run (continue it with -r, or use -fo to start again)",
                    partial_path(n).display()
                );
            }
        }
    }
    Ok(())
}
