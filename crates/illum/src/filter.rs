//! The scene filter: reads scene text (comments, `#@mkillum` lines, `!commands`,
//! primitives), converts the selected surfaces and writes everything to the current
//! output (standard output, or the file an `o=` directive names).

use std::io::Write;

use anyhow::{bail, Context, Result};
use fenestra_trace::Tracer;

use crate::directives::Settings;
use crate::geometry::{Face, Ring};
use crate::sample::{self, Job, Shape};
use crate::write::{self, Prim};

/// Where output goes.
enum Sink {
    Stdout(std::io::Stdout),
    File(fenestra_cli::output::AtomicFile),
}

impl Sink {
    fn write(&mut self, s: &str) -> Result<()> {
        match self {
            Sink::Stdout(o) => o.write_all(s.as_bytes())?,
            Sink::File(f) => f.write_all(s.as_bytes())?,
        }
        Ok(())
    }

    fn finish(self) -> Result<()> {
        match self {
            Sink::Stdout(mut o) => o.flush()?,
            Sink::File(f) => f.commit()?,
        }
        Ok(())
    }
}

/// One surface's standard errors (`-E`): its name and per-direction errors.
#[derive(Debug, Clone)]
pub struct SurfaceError {
    /// The surface.
    pub name: String,
    /// Mean radiance (luminance) over the directions.
    pub mean: f64,
    /// Standard error of each direction's luminance, relative to the mean.
    pub rel: Vec<f64>,
}

/// The filter's state over a run.
pub struct Filter<'a> {
    tracer: &'a Tracer,
    /// Directives in effect.
    pub settings: Settings,
    seed: u64,
    header: String,
    done_header: bool,
    sink: Option<Sink>,
    surfaces: u64,
    /// Per-surface standard errors, collected when `Some`.
    pub errors: Option<Vec<SurfaceError>>,
    /// Progress per surface (rays), when shown.
    pub progress: Option<&'a fenestra_cli::progress::Progress>,
    /// BSDF files loaded by `d=` directives.
    bsdfs: std::collections::HashMap<String, std::sync::Arc<crate::bsdf_mode::BsdfData>>,
}

fn warn(msg: impl std::fmt::Display) {
    fenestra_cli::warn(msg);
}

impl<'a> Filter<'a> {
    /// A filter over `tracer`; `header` is the command line printed before the first output.
    pub fn new(tracer: &'a Tracer, seed: u64, header: String) -> Self {
        Filter {
            tracer,
            settings: Settings::default(),
            seed,
            header,
            done_header: false,
            sink: Some(Sink::Stdout(std::io::stdout())),
            surfaces: 0,
            errors: None,
            progress: None,
            bsdfs: std::collections::HashMap::new(),
        }
    }

    fn emit(&mut self, s: &str) -> Result<()> {
        self.sink.as_mut().expect("an output").write(s)
    }

    fn check_header(&mut self) -> Result<()> {
        if !self.done_header {
            self.done_header = true;
            let h = format!("# {}\n#@mkillum !\n", self.header);
            self.emit(&h)?;
        }
        Ok(())
    }

    /// Finishes the output (commits an `o=` file).
    pub fn finish(mut self) -> Result<()> {
        if let Some(s) = self.sink.take() {
            s.finish()?;
        }
        Ok(())
    }

    /// Filters scene text read from `name` (a file, "standard input" or a `!command`).
    pub fn run_text(&mut self, text: &str, name: &str) -> Result<()> {
        if text.as_bytes().contains(&0) || text.starts_with("#?RADIANCE") {
            bail!("({name}): not scene text (an octree or binary file?); mkillum reads the surfaces to convert as Radiance scene text");
        }
        let mut pos = 0;
        let bytes = text.as_bytes();
        while pos < bytes.len() {
            let c = bytes[pos];
            if c.is_ascii_whitespace() {
                pos += 1;
                continue;
            }
            let line_end = text[pos..].find('\n').map_or(text.len(), |k| pos + k + 1);
            if c == b'#' {
                let line = &text[pos..line_end];
                pos = line_end;
                self.options(line, name)?;
                continue;
            }
            if c == b'!' {
                let cmd = text[pos + 1..line_end].trim_end();
                pos = line_end;
                let out = fenestra_cfmt::sh_c(cmd)
                    .stderr(std::process::Stdio::inherit())
                    .output()
                    .with_context(|| format!("cannot execute \"!{cmd}\""))?;
                let sub = String::from_utf8_lossy(&out.stdout).into_owned();
                self.run_text(&sub, &format!("!{cmd}"))?;
                if !out.status.success() {
                    warn(format!("bad status from \"!{cmd}\""));
                }
                continue;
            }
            pos = self.object(text, pos, name)?;
        }
        Ok(())
    }

    fn options(&mut self, line: &str, name: &str) -> Result<()> {
        let is_ours = line.starts_with("#@mkillum")
            && line[9..].starts_with(|c: char| c.is_ascii_whitespace());
        if !is_ours {
            let mut l = line.to_string();
            if !l.ends_with('\n') {
                l.push('\n');
            }
            return self.emit(&l);
        }
        let before = self.settings.clone();
        let mut fx = self.settings.apply(&line[10..]);
        if let Some(file) = fx.bsdf.take() {
            if !self.bsdfs.contains_key(&file) {
                match crate::bsdf_mode::load(&file, self.tracer.resolver()) {
                    Ok(d) => {
                        self.bsdfs.insert(file.clone(), d);
                    }
                    Err(e) => {
                        fx.warnings.push(format!("d={file}: {e:#}"));
                        fx.errors += 1;
                        self.settings.bsdf = before.bsdf.clone();
                    }
                }
            }
        }
        if fx.processed {
            warn(format!("({name}): already processed!"));
            return Ok(());
        }
        for w in &fx.warnings {
            warn(w);
        }
        if let Some(o) = fx.output {
            let f = fenestra_cli::output::AtomicFile::create(&o)
                .with_context(|| format!("cannot open output file \"{o}\""))?;
            if let Some(old) = self.sink.replace(Sink::File(f)) {
                old.finish()?;
            }
            self.done_header = false;
        }
        self.check_header()?;
        let body = line[2..].trim_end_matches(['\n', '\r']);
        if fx.errors > 0 {
            warn(format!(
                "({name}): {} error(s) in option line: {}",
                fx.errors,
                line.trim_end()
            ));
            let e = format!(
                "# {}: the following option line has {} error(s):\n",
                fenestra_cli::prog(),
                fx.errors
            );
            self.emit(&e)?;
        }
        let c = format!("# {body}\n");
        self.emit(&c)
    }

    /// Reads and handles one primitive starting at `pos`; returns the position after it.
    fn object(&mut self, text: &str, mut pos: usize, name: &str) -> Result<usize> {
        let start = pos;
        let line = || text[..start].matches('\n').count() + 1;
        let mut word = |what: &str| -> Result<String> {
            let rest = &text[pos..];
            let skip = rest.len() - rest.trim_start().len();
            let rest = &rest[skip..];
            let end = rest.find(char::is_whitespace).unwrap_or(rest.len());
            if end == 0 {
                bail!(
                    "({name}): error reading input (line {}: expected {what})",
                    text[..start].matches('\n').count() + 1
                );
            }
            pos += skip + end;
            Ok(rest[..end].to_string())
        };
        let modifier = word("a modifier")?;
        let ptype = word("a primitive type")?;
        if ptype == "alias" {
            let new = word("the alias name")?;
            let target = word("the aliased modifier")?;
            self.check_header()?;
            let s = format!("\n{modifier} alias {new}\t{target}\n");
            self.emit(&s)?;
            return Ok(pos);
        }
        if fenestra_scene::types::rule(&ptype).is_none() {
            bail!("({name}): unknown type \"{ptype}\" (line {})", line());
        }
        let id = word("a primitive name")?;
        let count = |w: String, what: &str| -> Result<usize> {
            match w.parse::<usize>() {
                Ok(n) if n <= 1 << 20 => Ok(n),
                _ => bail!(
                    "({name}): error reading input (line {}: '{id}': expected the number of {what}, found '{w}')",
                    line()
                ),
            }
        };
        let ns = count(word("a count")?, "string arguments")?;
        let sargs = (0..ns)
            .map(|_| word("a string argument"))
            .collect::<Result<Vec<_>>>()?;
        let ni = count(word("a count")?, "integer arguments")?;
        let iargs = (0..ni)
            .map(|_| word("an integer argument"))
            .collect::<Result<Vec<_>>>()?;
        let nr = count(word("a count")?, "real arguments")?;
        let mut rargs = Vec::with_capacity(nr.min(4096));
        for _ in 0..nr {
            let w = word("a real argument")?;
            match fenestra_cli::opts::parse_real(&w) {
                Some(v) if v.is_finite() => rargs.push(v),
                _ => bail!(
                    "({name}): error reading input (line {}: '{id}': '{w}' is not a real number)",
                    line()
                ),
            }
        }
        let p = Prim {
            modifier,
            ptype,
            name: id,
            sargs,
            iargs,
            rargs,
        };
        let doit =
            self.settings.selects(&p.modifier) && fenestra_scene::types::is_surface(&p.ptype);
        self.check_header()?;
        let mut out = String::new();
        if doit {
            self.convert(&p, name, &mut out)?;
        } else {
            write::printobj(&mut out, &p.modifier, &p);
        }
        self.emit(&out)?;
        Ok(pos)
    }

    /// The polygon's face; a zero-area one is passed unchanged (with the warning) and gives
    /// `None`; bad arguments are an error.
    fn face_of(&self, p: &Prim, name: &str, out: &mut String) -> Result<Option<Face>> {
        let face = Face::new(&p.rargs)
            .map_err(|e| anyhow::anyhow!("({name}): polygon \"{}\": {e}", p.name))?;
        if face.is_none() {
            self.pass_unchanged(
                p,
                out,
                &format!("cannot make illum for polygon \"{}\" (zero area)", p.name),
                name,
            );
        }
        Ok(face)
    }

    fn pass_unchanged(&self, p: &Prim, out: &mut String, why: &str, name: &str) {
        warn(format!("({name}): {why}"));
        write::printobj(out, &p.modifier, p);
    }

    fn convert(&mut self, p: &Prim, name: &str, out: &mut String) -> Result<()> {
        // one number per surface (it keys the surface's random streams), refined or not
        self.surfaces += 1;
        let bsdf = self
            .settings
            .bsdf
            .as_ref()
            .and_then(|f| self.bsdfs.get(f))
            .cloned();
        if let Some(data) = bsdf {
            let job = self.job(
                p,
                self.settings.sampdens,
                Some(data.incident.len()),
                0,
                None,
            );
            return self.convert_bsdf(p, name, out, &job, &data);
        }
        let keep = self.settings.sampdens;
        let mut dens = keep;
        let Some(shape) = self.shape_of(p, name, out)? else {
            return Ok(());
        };
        let job = self.job(p, dens, None, 0, None);
        let Some(mut dist) = shape.sample(&job) else {
            self.pass_unchanged(p, out, &format!("polygon \"{}\": bad aspect", p.name), name);
            return Ok(());
        };
        let axes = shape.axes();
        let sphere = matches!(shape, Shape::Sphere(..));
        let mut level = 0;
        let peak = loop {
            let peak = if dens > 0 { dist.peak() } else { None };
            // p+: a peak in one cell: the directions around it sampled again at 4× the
            // density (the others keep their values), while that stays within d=4096
            let refine = self.settings.refine && dens > 0 && dens * 4 <= 4096;
            match peak {
                Some((share, at)) if refine => {
                    level += 1;
                    let around = sample::neighbourhood(at, (dist.nalt, dist.nazi), sphere);
                    let grid = self.divisions(p, dens * 4);
                    let picked: Vec<bool> = (0..grid.0 * grid.1)
                        .map(|k| around[sample::containing_bin(k, grid, (dist.nalt, dist.nazi))])
                        .collect();
                    warn(format!(
                        "{} \"{}\": one of its {} directions carries {:.0}% of the light at d={dens}: sampled again at d={} (p+) in the {} directions around it",
                        p.ptype,
                        p.name,
                        dist.sums.len(),
                        100.0 * share,
                        dens * 4,
                        picked.iter().filter(|&&x| x).count()
                    ));
                    let fine = self.job(p, dens * 4, None, level, Some(picked.clone()));
                    // origins that cannot be placed this time keep the distribution so far
                    let Some(mut finer) = shape.sample(&fine) else {
                        warn(format!(
                            "{} \"{}\": refinement at d={} failed (bad aspect): kept d={dens}",
                            p.ptype,
                            p.name,
                            dens * 4
                        ));
                        break peak.map(|(share, _)| share);
                    };
                    finer.fill_from(&dist, &picked, &around);
                    dist = finer;
                    dens *= 4;
                }
                _ => break peak.map(|(share, _)| share),
            }
        };
        // the distribution is written at the density used
        self.settings.sampdens = dens;
        let r = self.finish_surface(p, out, dist, axes, peak);
        self.settings.sampdens = keep;
        r
    }

    /// Altitude and azimuth divisions of `p`'s distribution at density `dens`.
    fn divisions(&self, p: &Prim, dens: i64) -> (usize, usize) {
        match p.ptype.as_str() {
            "sphere" => crate::directives::round_divisions(dens),
            _ => crate::directives::flat_divisions(dens),
        }
    }

    /// The sampling job of surface number `self.surfaces` (`p`) at density `dens`, its
    /// progress bar restarted; `bsdf_patches`: the incident patches of the BSDF-data mode.
    /// `level`: the refinement level (`p+`), which keys streams of its own (in the seed of
    /// the sampling streams here, in the tracer's ray ids in [`Job::stream`]); `only`: the
    /// bins to sample (all when None).
    fn job(
        &self,
        p: &Prim,
        dens: i64,
        bsdf_patches: Option<usize>,
        level: u64,
        only: Option<Vec<bool>>,
    ) -> Job<'a> {
        let (nalt, nazi) = self.divisions(p, dens);
        let nsamps = self.settings.nsamps.max(1) as usize;
        let job = Job {
            tracer: self.tracer,
            seed: self.seed ^ level.wrapping_mul(0x9e37_79b9_7f4a_7c15),
            surface: self.surfaces,
            nalt,
            nazi,
            nsamps,
            light: self.settings.light,
            only,
            level,
            progress: self.progress,
        };
        if let Some(pr) = self.progress {
            let rays = match bsdf_patches {
                Some(np) => np * nsamps,
                None => job.rays(),
            };
            pr.restart(rays as u64, &format!("mkillum {}", p.name));
        }
        job
    }

    /// The surface `p` as a shape to sample, or `None` when it is passed on unchanged (a
    /// zero-area polygon, a surface of another kind).
    fn shape_of(&mut self, p: &Prim, name: &str, out: &mut String) -> Result<Option<Shape>> {
        Ok(match p.ptype.as_str() {
            "polygon" => self.face_of(p, name, out)?.map(Shape::Face),
            "ring" => {
                Some(Shape::Ring(Ring::new(&p.rargs).map_err(|e| {
                    anyhow::anyhow!("({name}): ring \"{}\": {e}", p.name)
                })?))
            }
            "sphere" => {
                if p.rargs.len() != 4 {
                    bail!("({name}): sphere \"{}\": bad # of arguments", p.name);
                }
                let c = glam::DVec3::new(p.rargs[0], p.rargs[1], p.rargs[2]);
                Some(Shape::Sphere(c, p.rargs[3]))
            }
            other => {
                let why = format!("cannot make illum for {other} \"{}\"", p.name);
                self.pass_unchanged(p, out, &why, name);
                None
            }
        })
    }

    /// BSDF-data mode (`d=file.xml`) for one surface.
    fn convert_bsdf(
        &mut self,
        p: &Prim,
        name: &str,
        out: &mut String,
        job: &Job,
        data: &crate::bsdf_mode::BsdfData,
    ) -> Result<()> {
        if p.ptype != "polygon" {
            self.pass_unchanged(
                p,
                out,
                &format!(
                    "{} \"{}\": BSDF input (d=file) needs a polygon window",
                    p.ptype, p.name
                ),
                name,
            );
            return Ok(());
        }
        let Some(face) = self.face_of(p, name, out)? else {
            return Ok(());
        };
        let up = self
            .settings
            .up
            .unwrap_or_else(|| crate::bsdf_mode::default_up(face.norm));
        let r = crate::bsdf_mode::face(job, &face, data, up)
            .map_err(|e| anyhow::anyhow!("({name}): polygon \"{}\": {e}", p.name))?;
        let Some((dist, axes)) = r else {
            self.pass_unchanged(p, out, &format!("polygon \"{}\": bad aspect", p.name), name);
            return Ok(());
        };
        // the distribution is always written, whatever d= was before
        let keep = self.settings.sampdens;
        self.settings.sampdens = self.settings.sampdens.max(1);
        let peak = dist.peak().map(|(share, _)| share);
        let r = self.finish_surface(p, out, dist, Some(axes), peak);
        self.settings.sampdens = keep;
        r
    }

    /// Writes a sampled surface: its distribution and illum, or the surface unchanged when
    /// too dim.
    fn finish_surface(
        &mut self,
        p: &Prim,
        out: &mut String,
        dist: crate::sample::Distribution,
        axes: Option<[glam::DVec3; 3]>,
        peak: Option<f64>,
    ) -> Result<()> {
        let col = dist.average();
        if crate::bright(col) <= self.settings.minbrt + 1e-6 {
            write::printobj(out, &p.modifier, p);
            return Ok(());
        }
        if let Some(errs) = self.errors.as_mut() {
            let mean = crate::bright(col);
            errs.push(SurfaceError {
                name: p.name.clone(),
                mean,
                rel: dist.std_errors().iter().map(|e| e / mean).collect(),
            });
        }
        if self.settings.sampdens > 0 {
            if let Some(share) = peak {
                // Radiance spreads such a peak over its cell without a word
                warn(format!(
                    "{} \"{}\": one of its {} directions carries {:.0}% of the light leaving it (a peak, as of a sun by way of specular surfaces), spread here over a cell of {:.3} sr (projected); raise d= (now {}), give p+ (fenestra: sampled again finer) or sample the source with l+",
                    p.ptype,
                    p.name,
                    dist.sums.len(),
                    100.0 * share,
                    std::f64::consts::PI / dist.sums.len() as f64,
                    self.settings.sampdens
                ));
            }
            write::distribution(out, &mut self.settings, &dist, col, axes)?;
        } else if p.ptype == "sphere" {
            warn(format!("sphere \"{}\": diffuse distribution", p.name));
        }
        write::illumout(out, &self.settings, &p.modifier, col, p);
        Ok(())
    }
}
