//! Output destinations of the contribution tracer: `-o` specs with `%s`/`%d` fields,
//! the streams they make (which modifier bins go where), headers, and record writing.

use std::io::Write;
use std::process::{Child, ChildStdin, Command, Stdio};

use anyhow::{bail, Context, Result};
use std::fs::File;
use std::io::{BufWriter, Seek, SeekFrom};
use std::path::{Path, PathBuf};

/// Output data format (`-fXo`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Text, `%.6e` and a tab per value.
    Ascii,
    /// 32-bit floats, native byte order.
    Float,
    /// 64-bit floats, native byte order.
    Double,
    /// RGBE, 4 bytes per bin.
    Rgbe,
}

impl Format {
    /// The format letter's meaning (`a f d c`).
    pub fn from_letter(c: char, output: bool) -> Result<Format> {
        Ok(match c {
            'a' => Format::Ascii,
            'f' => Format::Float,
            'd' => Format::Double,
            'c' if output => Format::Rgbe,
            _ => bail!("Illegal i/o format '{c}' (input: a, f, d; output: a, f, d, c)"),
        })
    }

    fn header_name(self) -> &'static str {
        match self {
            Format::Ascii => "ascii",
            Format::Float => "float",
            Format::Double => "double",
            Format::Rgbe => "32-bit_rle_rgbe",
        }
    }
}

/// A parsed `-o` spec: where its `%s` and bin field are.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Spec {
    /// The spec text.
    pub text: String,
    /// Has a `%s` field.
    pub has_mod: bool,
    /// Has a bin field (`%d`, `%03d`, `%x` …).
    pub has_bin: bool,
}

impl Spec {
    /// Parses a spec; any conversion other than one `%s` and one integer field is an error.
    pub fn parse(text: &str) -> Result<Spec> {
        let (mut has_mod, mut has_bin) = (false, false);
        let b: Vec<char> = text.chars().collect();
        let mut i = 0;
        while i < b.len() {
            if b[i] == '%' {
                i += 1;
                if b.get(i) == Some(&'%') {
                    i += 1;
                    continue;
                }
                let start = i;
                while i < b.len() && (b[i].is_ascii_digit() || b[i] == '-' || b[i] == '+') {
                    i += 1;
                }
                let flags: String = b[start..i].iter().collect();
                fenestra_cli::printf::check_width(text, flags.trim_start_matches(['-', '+', '0']))?;
                match b.get(i) {
                    Some('s') if !has_mod => has_mod = true,
                    Some('d' | 'i' | 'o' | 'x' | 'X') if !has_bin => has_bin = true,
                    _ => bail!("bad output format '{text}' (one %s and one %d field allowed)"),
                }
            }
            i += 1;
        }
        Ok(Spec {
            text: text.to_string(),
            has_mod,
            has_bin,
        })
    }

    /// The destination name for a modifier and bin.
    pub fn expand(&self, modifier: &str, bin: usize) -> String {
        let b: Vec<char> = self.text.chars().collect();
        let mut out = String::new();
        let mut i = 0;
        while i < b.len() {
            if b[i] != '%' {
                out.push(b[i]);
                i += 1;
                continue;
            }
            i += 1;
            if b.get(i) == Some(&'%') {
                out.push('%');
                i += 1;
                continue;
            }
            let start = i;
            while i < b.len() && (b[i].is_ascii_digit() || b[i] == '-' || b[i] == '+') {
                i += 1;
            }
            let flags: String = b[start..i].iter().collect();
            let left = flags.contains('-');
            let zero = flags.trim_start_matches(['-', '+']).starts_with('0');
            let width: usize = flags
                .trim_start_matches(['-', '+', '0'])
                .parse()
                .unwrap_or(0);
            let body = match b.get(i) {
                Some('s') => modifier.to_string(),
                Some('o') => format!("{bin:o}"),
                Some('x') => format!("{bin:x}"),
                Some('X') => format!("{bin:X}"),
                _ => bin.to_string(),
            };
            i += 1;
            let pad = width.saturating_sub(body.chars().count());
            if left {
                out.push_str(&body);
                out.push_str(&" ".repeat(pad));
            } else if zero && !matches!(b.get(i - 1), Some('s')) {
                out.push_str(&"0".repeat(pad));
                out.push_str(&body);
            } else {
                out.push_str(&" ".repeat(pad));
                out.push_str(&body);
            }
        }
        out
    }
}

/// One output stream: its destination and the (modifier, bin) values of each record.
#[derive(Debug, Clone)]
pub struct StreamPlan {
    /// Destination (`None`: standard output; `!cmd`: a command).
    pub name: Option<String>,
    /// Values of a record in order: (modifier index, bin).
    pub items: Vec<(usize, usize)>,
    /// `MODIFIER=` header value.
    pub modifier: Option<String>,
    /// `BIN=` header value.
    pub bin: Option<usize>,
    spec_has_mod: bool,
}

/// A modifier as far as outputs are concerned.
pub struct ModOut<'a> {
    /// Its name.
    pub name: &'a str,
    /// Its output spec (`None` = standard output).
    pub spec: Option<&'a Spec>,
    /// Its bin count.
    pub nbins: usize,
}

/// Works out the streams for the modifiers, in command-line order. `picture`: with
/// `-x -y` pictures, later modifiers sharing a `%d`-only spec move to the next unused
/// file number (as Radiance does).
pub fn plan(mods: &[ModOut], picture: bool) -> Vec<StreamPlan> {
    let mut streams: Vec<StreamPlan> = Vec::new();
    let mut used: Vec<(String, usize)> = Vec::new();
    let add = |streams: &mut Vec<StreamPlan>,
               name: Option<String>,
               item: (usize, usize),
               modname: &str,
               bin: Option<usize>,
               has_mod: bool| {
        match streams.iter_mut().find(|s| s.name == name) {
            Some(s) => s.items.push(item),
            None => streams.push(StreamPlan {
                name,
                items: vec![item],
                modifier: if has_mod {
                    Some(modname.to_string())
                } else {
                    None
                },
                bin,
                spec_has_mod: has_mod,
            }),
        }
    };
    for (m, md) in mods.iter().enumerate() {
        match md.spec {
            None => {
                for b in 0..md.nbins {
                    add(&mut streams, None, (m, b), md.name, None, false);
                }
            }
            Some(sp) => {
                let shift = if sp.has_bin && !sp.has_mod && picture {
                    match used.iter_mut().find(|(t, _)| *t == sp.text) {
                        Some((_, n)) => {
                            let s = *n;
                            *n += md.nbins;
                            s
                        }
                        None => {
                            used.push((sp.text.clone(), md.nbins));
                            0
                        }
                    }
                } else {
                    0
                };
                for b in 0..md.nbins {
                    let fileno = b + shift;
                    let name = sp.expand(md.name, fileno);
                    let bin = if sp.has_bin { Some(fileno) } else { None };
                    add(&mut streams, Some(name), (m, b), md.name, bin, sp.has_mod);
                }
            }
        }
    }
    for s in &mut streams {
        if s.items.len() == 1 && !s.spec_has_mod {
            s.modifier = Some(mods[s.items[0].0].name.to_string());
        }
    }
    streams
}

/// What every header carries.
#[derive(Debug, Clone)]
pub struct HeaderInfo {
    /// Lines from the scene's own header (e.g. the oconv command).
    pub scene_lines: Vec<String>,
    /// The command line without the scene files.
    pub command: String,
    /// `-x` and `-y`.
    pub xres: usize,
    /// `-y`.
    pub yres: usize,
    /// Output format.
    pub format: Format,
    /// Write the information header (`-h`).
    pub header: bool,
    /// Extra lines (e.g. what an error-estimate file holds).
    pub extra: Vec<String>,
}

/// The header (and resolution string) of a stream.
pub fn header_text(plan: &StreamPlan, info: &HeaderInfo) -> Vec<u8> {
    let mut h = String::new();
    let one = plan.items.len() == 1;
    if info.header {
        h.push_str("#?RADIANCE\n");
        for l in &info.scene_lines {
            h.push_str(l);
            h.push('\n');
        }
        h.push_str(&info.command);
        h.push('\n');
        h.push_str("SOFTWARE= fenestra\n");
        for l in fenestra_formats::picture::capdate_lines() {
            h.push_str(&l);
            h.push('\n');
        }
        h.push_str("NCOMP=3\n");
        if let Some(m) = &plan.modifier {
            h.push_str(&format!("MODIFIER={m}\n"));
        }
        if let Some(b) = plan.bin {
            h.push_str(&format!("BIN={b}\n"));
        }
        for l in &info.extra {
            h.push_str(l);
            h.push('\n');
        }
        if info.yres > 0 {
            h.push_str(&format!("NROWS={}\n", info.yres * info.xres.max(1)));
        }
        if !(info.xres > 0 && one) {
            h.push_str(&format!("NCOLS={}\n", plan.items.len()));
        }
        if matches!(info.format, Format::Float | Format::Double) {
            let be = if cfg!(target_endian = "big") { 1 } else { 0 };
            h.push_str(&format!("BigEndian={be}\n"));
        }
        h.push_str(&format!("FORMAT={}\n\n", info.format.header_name()));
    }
    if info.xres > 0 && info.yres > 0 && one {
        h.push_str(&format!("-Y {:8} +X {:8}\n", info.yres, info.xres));
    }
    h.into_bytes()
}

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
struct PartialFile {
    target: PathBuf,
    tmp: Option<PathBuf>,
    w: Option<BufWriter<File>>,
}

impl PartialFile {
    fn create(target: &str) -> Result<PartialFile> {
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
    fn resume(target: &str, keep: u64) -> Result<PartialFile> {
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

    fn commit(mut self) -> Result<()> {
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
        Format::Rgbe => 4,
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
        let want = format!("FORMAT={}", format.header_name());
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

enum Dest {
    Stdout(std::io::BufWriter<std::io::Stdout>),
    File(PartialFile),
    Cmd(Child, std::io::BufWriter<ChildStdin>, String),
    /// A picture (`-ffc` with `-x -y`) to a file named `*.exr`: pixels kept, written as
    /// OpenEXR at the end (unrounded floats instead of RGBE).
    Exr(ExrOut),
}

/// A picture collected for OpenEXR output.
struct ExrOut {
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
    let m = fenestra_formats::matrix::Matrix::read(name)
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
                let mut child = Command::new("sh")
                    .arg("-c")
                    .arg(cmd)
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

    fn w(&mut self) -> &mut dyn Write {
        match &mut self.dest {
            Dest::Stdout(w) => w,
            Dest::File(f) => f,
            Dest::Cmd(_, w, _) => w,
            Dest::Exr(_) => unreachable!("OpenEXR output is not a byte stream"),
        }
    }

    fn flush_buf(&mut self) -> Result<()> {
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
                Format::Float | Format::Rgbe => s.map(|x| ((x as f32) * (scale as f32)) as f64),
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
                Format::Rgbe => {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spec_fields() {
        let s = Spec::parse("out/%s_%03d.dat").unwrap();
        assert!(s.has_mod && s.has_bin);
        assert_eq!(s.expand("sky", 7), "out/sky_007.dat");
        assert!(Spec::parse("a%f").is_err());
        assert!(Spec::parse("a%d%d").is_err());
        assert_eq!(Spec::parse("v%x").unwrap().expand("m", 255), "vff");
    }

    #[test]
    fn picture_bins_shift() {
        let sp = Spec::parse("v%03d.hdr").unwrap();
        let mods = [
            ModOut {
                name: "g",
                spec: Some(&sp),
                nbins: 1,
            },
            ModOut {
                name: "s",
                spec: Some(&sp),
                nbins: 3,
            },
        ];
        let p = plan(&mods, true);
        assert_eq!(p.len(), 4);
        assert_eq!(p[3].name.as_deref(), Some("v003.hdr"));
        assert_eq!(p[3].modifier.as_deref(), Some("s"));
        let p = plan(&mods, false);
        assert_eq!(p.len(), 3);
        assert_eq!(p[0].items, vec![(0, 0), (1, 0)]);
        assert_eq!(p[0].modifier, None);
    }
}
