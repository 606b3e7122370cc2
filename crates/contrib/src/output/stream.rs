//! Open output streams: standard output, files (written aside, moved into place),
//! commands and OpenEXR pictures; record writing and flushing.

use super::*;

use std::io::Write;
use std::process::{Child, ChildStdin, Stdio};

use anyhow::{bail, Context, Result};

pub(super) enum Dest {
    Stdout(std::io::BufWriter<std::io::Stdout>),
    File(PartialFile),
    Cmd(Child, std::io::BufWriter<ChildStdin>, String),
    /// A picture (`-ffc` with `-x -y`) to a file named `*.exr`: pixels kept, written as
    /// OpenEXR at the end (unrounded floats instead of RGBE).
    Exr(ExrOut),
}

/// A picture collected for OpenEXR output.
pub(super) struct ExrOut {
    path: String,
    width: usize,
    height: usize,
    pixels: Vec<[f32; 3]>,
    command: String,
}

/// An open stream.
pub struct Stream {
    /// Its plan.
    pub plan: StreamPlan,
    dest: Dest,
    buf: Vec<u8>,
    /// Scratch text of one number (ASCII output).
    txt: String,
}

impl Stream {
    /// Opens the destination and writes the header.
    pub fn open(plan: StreamPlan, info: &HeaderInfo) -> Result<Stream> {
        let dest = match &plan.name {
            None => Dest::Stdout(std::io::BufWriter::with_capacity(
                1 << 16,
                std::io::stdout(),
            )),
            Some(n) if n.starts_with('!') => {
                let cmd = &n[1..];
                let mut child = fenestra_cfmt::sh_c(cmd)
                    .stdin(Stdio::piped())
                    .spawn()
                    .with_context(|| format!("cannot run output command '{cmd}'"))?;
                let stdin = child.stdin.take().context("no pipe to output command")?;
                Dest::Cmd(
                    child,
                    std::io::BufWriter::with_capacity(1 << 16, stdin),
                    cmd.to_string(),
                )
            }
            Some(n) => {
                if let Some(dir) = std::path::Path::new(n).parent() {
                    if !dir.as_os_str().is_empty() && !dir.exists() {
                        std::fs::create_dir_all(dir)
                            .with_context(|| format!("cannot create folder '{}'", dir.display()))?;
                    }
                }
                if fenestra_formats::exr::is_exr_path(n) {
                    if info.format != Format::Rgbe || info.xres == 0 || info.yres == 0 {
                        bail!("'{n}': OpenEXR output needs picture output (-ffc with -x and -y)");
                    }
                    if plan.items.len() != 1 {
                        bail!("'{n}': OpenEXR output holds one bin per file (use %d in -o)");
                    }
                    Dest::Exr(ExrOut {
                        path: n.clone(),
                        width: info.xres,
                        height: info.yres,
                        pixels: Vec::with_capacity(info.xres * info.yres),
                        command: info.command.clone(),
                    })
                } else {
                    Dest::File(PartialFile::create(n)?)
                }
            }
        };
        let mut s = Stream {
            buf: header_text(&plan, info),
            txt: String::new(),
            plan,
            dest,
        };
        s.flush_buf()?;
        Ok(s)
    }

    /// Reopens an output file for `-r`, keeping its header and first `records` records.
    pub fn resume(
        plan: StreamPlan,
        part: &Partial,
        records: u64,
        format: Format,
    ) -> Result<Stream> {
        let name = plan
            .name
            .clone()
            .context("cannot recover the standard output")?;
        if fenestra_formats::exr::is_exr_path(&name) {
            bail!("'{name}': OpenEXR outputs cannot be recovered with -r (run again with -fo)");
        }
        if part.complete {
            std::fs::rename(&name, partial_path(&name))
                .with_context(|| format!("cannot reopen '{name}' to recover"))?;
        }
        let rs = record_size(&plan, format).context("cannot recover ASCII output")?;
        let f = PartialFile::resume(&name, part.header + records * rs)?;
        Ok(Stream {
            plan,
            dest: Dest::File(f),
            buf: Vec::new(),
            txt: String::new(),
        })
    }

    pub(super) fn w(&mut self) -> &mut dyn Write {
        match &mut self.dest {
            Dest::Stdout(w) => w,
            Dest::File(f) => f,
            Dest::Cmd(_, w, _) => w,
            Dest::Exr(_) => unreachable!("OpenEXR output is not a byte stream"),
        }
    }

    pub(super) fn flush_buf(&mut self) -> Result<()> {
        if matches!(self.dest, Dest::Exr(_)) {
            self.buf.clear();
            return Ok(());
        }
        let buf = std::mem::take(&mut self.buf);
        let name = self
            .plan
            .name
            .clone()
            .unwrap_or_else(|| "standard output".into());
        if let Err(e) = self.w().write_all(&buf) {
            if let Dest::Cmd(child, _, cmd) = &mut self.dest {
                // a command that ended without reading its input: say so (a closed pipe
                // would otherwise end the run without a message)
                let status = child
                    .wait()
                    .map(|st| st.to_string())
                    .unwrap_or_else(|_| "unknown status".into());
                bail!("output command '{cmd}' stopped reading its input ({status}): {e}");
            }
            return Err(e).with_context(|| format!("write error on '{name}'"));
        }
        self.buf = buf;
        self.buf.clear();
        Ok(())
    }

    /// Writes out what is buffered and flushes the destination (a record boundary where
    /// Radiance flushes: `-x` records, a dummy ray).
    pub fn flush(&mut self) -> Result<()> {
        self.flush_buf()?;
        if matches!(self.dest, Dest::Exr(_)) {
            return Ok(());
        }
        let name = self
            .plan
            .name
            .clone()
            .unwrap_or_else(|| "standard output".into());
        self.w()
            .flush()
            .with_context(|| format!("write error on '{name}'"))
    }

    /// Writes one record; `value(m, b)` gives the RGB sums of modifier `m`, bin `b`,
    /// to be multiplied by `scale` (in single precision for float and RGBE output, in
    /// double precision otherwise, as Radiance does).
    pub fn write_record(
        &mut self,
        format: Format,
        scale: f64,
        value: impl Fn(usize, usize) -> [f64; 3],
    ) -> Result<()> {
        for k in 0..self.plan.items.len() {
            let (m, b) = self.plan.items[k];
            let s = value(m, b);
            let v = match format {
                Format::Float | Format::Rgbe | Format::Xyze => {
                    s.map(|x| ((x as f32) * (scale as f32)) as f64)
                }
                _ => s.map(|x| x * scale),
            };
            match format {
                Format::Ascii => {
                    for c in v {
                        self.txt.clear();
                        fenestra_formats::matrix::format_c_e(&mut self.txt, c, 6);
                        self.buf.extend_from_slice(self.txt.as_bytes());
                        self.buf.push(b'\t');
                    }
                }
                Format::Float => {
                    for c in v {
                        self.buf.extend_from_slice(&(c as f32).to_ne_bytes());
                    }
                }
                Format::Double => {
                    for c in v {
                        self.buf.extend_from_slice(&c.to_ne_bytes());
                    }
                }
                Format::Rgbe | Format::Xyze => {
                    if let Dest::Exr(e) = &mut self.dest {
                        e.pixels.push([v[0] as f32, v[1] as f32, v[2] as f32]);
                        continue;
                    }
                    let p = fenestra_formats::rgbe::encode_f64(v);
                    self.buf.extend_from_slice(&p);
                }
            }
        }
        if format == Format::Ascii {
            self.buf.push(b'\n');
        }
        if self.buf.len() >= 1 << 15 {
            self.flush_buf()?;
        }
        Ok(())
    }

    /// Flushes and closes: a file is renamed into place, a command is waited for.
    pub fn finish(mut self) -> Result<()> {
        self.flush_buf()?;
        match self.dest {
            Dest::Stdout(mut w) => w.flush()?,
            Dest::File(f) => f.commit()?,
            Dest::Exr(e) => {
                if e.pixels.len() != e.width * e.height {
                    bail!(
                        "'{}': {} pixels for a {} x {} picture",
                        e.path,
                        e.pixels.len(),
                        e.width,
                        e.height
                    );
                }
                let head = fenestra_formats::picture::PictureHeader {
                    command: Some(e.command),
                    ..Default::default()
                };
                fenestra_formats::exr::write_picture_file(
                    &e.path,
                    Some(&head),
                    e.width,
                    e.height,
                    &e.pixels,
                )?;
            }
            Dest::Cmd(mut child, mut w, cmd) => {
                if let Err(e) = w.flush() {
                    let st = child.wait().map(|st| st.to_string()).unwrap_or_default();
                    bail!("output command '{cmd}' stopped reading its input ({st}): {e}");
                }
                drop(w);
                let st = child.wait()?;
                if !st.success() {
                    bail!("output command '{cmd}' failed ({st})");
                }
            }
        }
        Ok(())
    }
}
