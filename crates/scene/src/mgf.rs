//! MGF (Materials and Geometry Format, version 2) → Radiance primitives, as genBSDF
//! reads a device: materials `m` (`rd td ed rs ts ir sides`), colours `c`/`cxy`,
//! vertices `v`/`p`/`n`, objects `o`, transforms `xf` with arrays `-a`, includes `i`,
//! and the surfaces `f fh sph cyl cone ring prism`. Materials map to Radiance types by
//! the rules mgf2rad applies (light, glass, trans, plastic, metal); names follow its
//! scheme (`object.a<k>.object.f<n>`).
//!
//! One file on purpose (about 1 000 lines, a third of them tests): the reader's state
//! (material, colour, vertex and transform contexts) and mgf2rad's conversion rules are
//! one state machine; splitting it would spread that state over modules.

use crate::transform::invert3;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::{anyhow, bail, Context, Result};

use crate::model::{Loc, Primitive};
use crate::transform::Transform;

/// Radiance's luminous efficacy of white light (lm/W), dividing `ed` into radiance.
const WHITE_EFFICACY: f64 = 179.0;

/// A chromaticity (CIE x, y).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Chroma {
    x: f64,
    y: f64,
}

const NEUTRAL: Chroma = Chroma {
    x: 1.0 / 3.0,
    y: 1.0 / 3.0,
};

impl Chroma {
    fn is_grey(&self) -> bool {
        (self.x - NEUTRAL.x).abs() < 1e-6 && (self.y - NEUTRAL.y).abs() < 1e-6
    }

    fn same(&self, o: &Chroma) -> bool {
        (self.x - o.x).abs() < 1e-6 && (self.y - o.y).abs() < 1e-6
    }

    /// RGB (Radiance's standard primaries, equal-energy white) of this chromaticity at luminance `y_lum`.
    fn rgb(&self, y_lum: f64) -> [f64; 3] {
        if y_lum == 0.0 || self.y <= 0.0 {
            return [0.0; 3];
        }
        let xyz = [
            self.x / self.y * y_lum,
            y_lum,
            (1.0 - self.x - self.y) / self.y * y_lum,
        ];
        let m = xyz_to_rgb();
        let mut out = [0.0; 3];
        for (i, o) in out.iter_mut().enumerate() {
            *o = m[i][0] * xyz[0] + m[i][1] * xyz[1] + m[i][2] * xyz[2];
        }
        // Out of gamut: desaturate toward the grey of the same luminance until the
        // negative component reaches zero (as mgf2rad's colours come out).
        let min = out.iter().copied().fold(f64::INFINITY, f64::min);
        if min < 0.0 {
            let t = -min / (y_lum - min);
            for o in out.iter_mut() {
                *o += t * (y_lum - *o);
            }
        }
        out
    }
}

/// The XYZ → RGB matrix of Radiance's default primaries (R .640 .330, G .290 .600,
/// B .150 .060, white 1/3 1/3).
fn xyz_to_rgb() -> [[f64; 3]; 3] {
    let prim = [(0.640, 0.330), (0.290, 0.600), (0.150, 0.060)];
    // Columns: XYZ of each primary at unit Y, then scaled so R+G+B = white (1, 1, 1).
    let mut m = [[0.0; 3]; 3];
    for (j, (x, y)) in prim.iter().enumerate() {
        m[0][j] = x / y;
        m[1][j] = 1.0;
        m[2][j] = (1.0 - x - y) / y;
    }
    let s = solve3(&m, [1.0, 1.0, 1.0]);
    for row in m.iter_mut() {
        for (j, v) in row.iter_mut().enumerate() {
            *v *= s[j];
        }
    }
    invert3(&m)
}

fn solve3(m: &[[f64; 3]; 3], b: [f64; 3]) -> [f64; 3] {
    let inv = invert3(m);
    let mut x = [0.0; 3];
    for (i, v) in x.iter_mut().enumerate() {
        *v = inv[i][0] * b[0] + inv[i][1] * b[1] + inv[i][2] * b[2];
    }
    x
}

/// An MGF material context.
#[derive(Debug, Clone, PartialEq)]
struct Material {
    rd: f64,
    rd_c: Chroma,
    td: f64,
    td_c: Chroma,
    ed: f64,
    ed_c: Chroma,
    rs: f64,
    rs_c: Chroma,
    rs_a: f64,
    ts: f64,
    ts_c: Chroma,
    ts_a: f64,
    ir: f64,
    sides: u8,
}

impl Default for Material {
    fn default() -> Self {
        Material {
            rd: 0.0,
            rd_c: NEUTRAL,
            td: 0.0,
            td_c: NEUTRAL,
            ed: 0.0,
            ed_c: NEUTRAL,
            rs: 0.0,
            rs_c: NEUTRAL,
            rs_a: 0.0,
            ts: 0.0,
            ts_c: NEUTRAL,
            ts_a: 0.0,
            ir: 1.0,
            sides: 2,
        }
    }
}

/// A vertex context: point and (optional, zero = none) normal.
#[derive(Debug, Clone, Copy, Default)]
struct Vertex {
    p: [f64; 3],
    n: [f64; 3],
}

/// One logical MGF line: its words and where it starts.
#[derive(Debug, Clone)]
struct Line {
    words: Vec<String>,
    loc: Loc,
    dir: Arc<PathBuf>,
}

/// Converts MGF text into Radiance primitives (modifiers named, not yet resolved).
pub(crate) fn convert(text: &str, file: &str) -> Result<Vec<Primitive>> {
    let dir = Path::new(file)
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_default();
    let lines = split_lines(text, Arc::from(file), Arc::new(dir))?;
    let mut st = State::default();
    st.run(&lines, &Transform::identity(), 0)?;
    if !st.objects.is_empty() {
        bail!(
            "{file}: end of input inside object '{}' (a bare 'o' closes it)",
            st.objects.join(".")
        );
    }
    Ok(st.out)
}

fn split_lines(text: &str, file: Arc<str>, dir: Arc<PathBuf>) -> Result<Vec<Line>> {
    let mut out = Vec::new();
    let mut pending = String::new();
    let mut start = 0u32;
    for (i, raw) in text.lines().enumerate() {
        if pending.is_empty() {
            start = i as u32 + 1;
        }
        if let Some(head) = raw.strip_suffix('\\') {
            pending.push_str(head);
            pending.push(' ');
            continue;
        }
        pending.push_str(raw);
        let words: Vec<String> = pending.split_whitespace().map(str::to_string).collect();
        pending.clear();
        if words.is_empty() || words[0].starts_with('#') {
            continue;
        }
        out.push(Line {
            words,
            loc: Loc {
                file: file.clone(),
                line: start,
            },
            dir: dir.clone(),
        });
    }
    if !pending.trim().is_empty() {
        bail!("{file}:{start}: the last line ends with '\\' at end of input");
    }
    Ok(out)
}

#[derive(Default)]
struct State {
    vertices: HashMap<String, Vertex>,
    cur_vertex: Option<String>,
    colours: HashMap<String, Chroma>,
    /// The current colour: `None` is the unnamed one (`unnamed_colour`).
    cur_colour: Option<String>,
    unnamed_colour: Option<Chroma>,
    materials: HashMap<String, Material>,
    cur_material: Option<String>,
    unnamed_material: Material,
    /// Radiance name and definition of each material as last emitted.
    emitted: HashMap<String, Material>,
    objects: Vec<String>,
    counts: HashMap<String, usize>,
    warned: Vec<String>,
    out: Vec<Primitive>,
}

/// A context entity line (`v`, `c` or `m`) over `table`, the defined entries of `kind`:
/// `x name` selects an entry, `x name =` defines it as `fresh()` and `x name = template`
/// as a copy of another. Returns the new current entry's name, None for a bare `x` (the
/// unnamed entry); `usage` lists the accepted forms for the error.
fn context_entry<T: Clone>(
    l: &Line,
    table: &mut HashMap<String, T>,
    kind: &str,
    fresh: impl FnOnce() -> T,
    usage: &str,
) -> Result<Option<String>> {
    let w = &l.words;
    match w.len() {
        1 => Ok(None),
        2 => {
            if !table.contains_key(&w[1]) {
                bail!("{}: undefined {kind} '{}'", l.loc, w[1]);
            }
            Ok(Some(w[1].clone()))
        }
        3 | 4 if w[2] == "=" => {
            let v = if w.len() == 4 {
                table
                    .get(&w[3])
                    .cloned()
                    .ok_or_else(|| anyhow!("{}: undefined {kind} template '{}'", l.loc, w[3]))?
            } else {
                fresh()
            };
            table.insert(w[1].clone(), v);
            Ok(Some(w[1].clone()))
        }
        _ => bail!("{}: expected {usage}", l.loc),
    }
}

fn num(l: &Line, k: usize, what: &str) -> Result<f64> {
    let w = l
        .words
        .get(k)
        .ok_or_else(|| anyhow!("{}: '{}' needs {what} (argument {k})", l.loc, l.words[0]))?;
    crate::words::parse_real(w)
        .filter(|v| v.is_finite())
        .ok_or_else(|| anyhow!("{}: '{}': {what} is not a number: '{w}'", l.loc, l.words[0]))
}

fn nargs(l: &Line, n: usize) -> Result<()> {
    if l.words.len() != n + 1 {
        bail!(
            "{}: '{}' takes {n} argument(s), got {}",
            l.loc,
            l.words[0],
            l.words.len() - 1
        );
    }
    Ok(())
}

impl State {
    fn colour(&self) -> Chroma {
        match &self.cur_colour {
            Some(n) => self.colours[n],
            None => self.unnamed_colour.unwrap_or(NEUTRAL),
        }
    }

    fn material_mut(&mut self) -> &mut Material {
        match &self.cur_material {
            Some(n) => self.materials.get_mut(n).expect("current material exists"),
            None => &mut self.unnamed_material,
        }
    }

    /// Runs lines under transform `xf` (innermost transforms apply first).
    fn run(&mut self, lines: &[Line], xf: &Transform, depth: usize) -> Result<()> {
        let mut i = 0;
        while i < lines.len() {
            let l = &lines[i];
            let kw = l.words[0].as_str();
            match kw {
                "xf" if l.words.len() == 1 => {
                    bail!(
                        "{}: 'xf' without a matching 'xf' transform before it",
                        l.loc
                    )
                }
                "xf" => {
                    let end = matching_xf_end(lines, i)?;
                    self.transform_block(&l.words[1..], &l.loc, &lines[i + 1..end], xf, depth)?;
                    i = end + 1;
                    continue;
                }
                "i" => self.include(l, xf, depth)?,
                _ => self.entity(l, xf)?,
            }
            i += 1;
        }
        Ok(())
    }

    /// An `xf` block (possibly an array): runs `body` once per instance.
    fn transform_block(
        &mut self,
        args: &[String],
        loc: &Loc,
        body: &[Line],
        outer: &Transform,
        depth: usize,
    ) -> Result<()> {
        // Split at `-a N`: the words before the first -a apply once; each -a N repeats the
        // words after it (up to the next -a) k times for instance k.
        let mut pre: Vec<String> = Vec::new();
        let mut arrays: Vec<(usize, Vec<String>)> = Vec::new();
        let mut k = 0;
        while k < args.len() {
            if args[k] == "-a" {
                let n = args
                    .get(k + 1)
                    .and_then(|w| w.parse::<usize>().ok())
                    .filter(|&n| n > 0)
                    .ok_or_else(|| anyhow!("{loc}: xf -a needs a positive count"))?;
                arrays.push((n, Vec::new()));
                k += 2;
                continue;
            }
            match arrays.last_mut() {
                Some((_, seg)) => seg.push(args[k].clone()),
                None => pre.push(args[k].clone()),
            }
            k += 1;
        }
        let pre_t = Transform::parse_all(&pre).map_err(|e| anyhow!("{loc}: xf: {e}"))?;
        let mut segs = Vec::new();
        for (n, seg) in &arrays {
            let t = Transform::parse_all(seg).map_err(|e| anyhow!("{loc}: xf: {e}"))?;
            segs.push((*n, t));
        }
        let mut idx = vec![0usize; segs.len()];
        loop {
            let mut t = pre_t;
            for ((_, s), &k) in segs.iter().zip(&idx) {
                for _ in 0..k {
                    t = t.then(s);
                }
            }
            let total = t.then(outer);
            if segs.is_empty() {
                self.run(body, &total, depth)?;
            } else {
                let name = format!(
                    "a{}",
                    idx.iter()
                        .map(|k| k.to_string())
                        .collect::<Vec<_>>()
                        .join(".")
                );
                self.objects.push(name);
                let r = self.run(body, &total, depth);
                self.objects.pop();
                r?;
            }
            // Next instance (last index fastest).
            let mut d = segs.len();
            loop {
                if d == 0 {
                    return Ok(());
                }
                d -= 1;
                idx[d] += 1;
                if idx[d] < segs[d].0 {
                    break;
                }
                idx[d] = 0;
            }
        }
    }

    fn include(&mut self, l: &Line, xf: &Transform, depth: usize) -> Result<()> {
        if depth > 32 {
            bail!("{}: includes nested more than 32 deep", l.loc);
        }
        let name = l
            .words
            .get(1)
            .ok_or_else(|| anyhow!("{}: 'i' needs a file name", l.loc))?;
        let path = if Path::new(name).is_absolute() {
            PathBuf::from(name)
        } else {
            l.dir.join(name)
        };
        let text = crate::source::decode_text(std::fs::read(&path).with_context(|| {
            format!(
                "{}: cannot read included MGF file '{}'",
                l.loc,
                path.display()
            )
        })?);
        let file: Arc<str> = Arc::from(path.display().to_string());
        let dir = Arc::new(path.parent().map(Path::to_path_buf).unwrap_or_default());
        let lines = split_lines(&text, file, dir)?;
        if l.words.len() > 2 {
            self.transform_block(&l.words[2..], &l.loc, &lines, xf, depth + 1)
        } else {
            self.run(&lines, xf, depth + 1)
        }
    }

    fn entity(&mut self, l: &Line, xf: &Transform) -> Result<()> {
        let w = &l.words;
        match w[0].as_str() {
            "v" => self.context_vertex(l),
            "p" => {
                nargs(l, 3)?;
                let p = [num(l, 1, "x")?, num(l, 2, "y")?, num(l, 3, "z")?];
                self.current_vertex(l)?.p = p;
                Ok(())
            }
            "n" => {
                nargs(l, 3)?;
                let n = [num(l, 1, "dx")?, num(l, 2, "dy")?, num(l, 3, "dz")?];
                let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                let n = if len > 0.0 {
                    [n[0] / len, n[1] / len, n[2] / len]
                } else {
                    [0.0; 3]
                };
                self.current_vertex(l)?.n = n;
                Ok(())
            }
            "c" => self.context_colour(l),
            "cxy" => {
                nargs(l, 2)?;
                let (x, y) = (num(l, 1, "x")?, num(l, 2, "y")?);
                if !(x >= 0.0 && y > 0.0 && x + y <= 1.0 + 1e-9) {
                    bail!("{}: cxy {x} {y} is not a chromaticity", l.loc);
                }
                let c = Chroma { x, y };
                match &self.cur_colour {
                    Some(n) => {
                        self.colours.insert(n.clone(), c);
                    }
                    None => self.unnamed_colour = Some(c),
                }
                Ok(())
            }
            "cspec" | "cct" | "cmix" => bail!(
                "{}: MGF colour entity '{}' is not supported (give colours as 'cxy x y')",
                l.loc,
                w[0]
            ),
            "m" => self.context_material(l),
            "sides" => {
                nargs(l, 1)?;
                let s = num(l, 1, "1 or 2")?;
                if s != 1.0 && s != 2.0 {
                    bail!("{}: sides must be 1 or 2, got {s}", l.loc);
                }
                self.material_mut().sides = s as u8;
                Ok(())
            }
            "rd" | "td" | "ed" => {
                nargs(l, 1)?;
                let v = num(l, 1, "a value")?;
                let c = self.colour();
                let range_ok = if w[0] == "ed" {
                    v >= 0.0
                } else {
                    (0.0..=1.0).contains(&v)
                };
                if !range_ok {
                    bail!("{}: {} {v} is out of range", l.loc, w[0]);
                }
                let m = self.material_mut();
                match w[0].as_str() {
                    "rd" => (m.rd, m.rd_c) = (v, c),
                    "td" => (m.td, m.td_c) = (v, c),
                    _ => (m.ed, m.ed_c) = (v, c),
                }
                Ok(())
            }
            "rs" | "ts" => {
                nargs(l, 2)?;
                let (v, a) = (num(l, 1, "a value")?, num(l, 2, "a roughness")?);
                if !(0.0..=1.0).contains(&v) || a < 0.0 {
                    bail!("{}: {} {v} {a} is out of range", l.loc, w[0]);
                }
                let c = self.colour();
                let m = self.material_mut();
                if w[0] == "rs" {
                    (m.rs, m.rs_c, m.rs_a) = (v, c, a);
                } else {
                    (m.ts, m.ts_c, m.ts_a) = (v, c, a);
                }
                Ok(())
            }
            "ir" => {
                nargs(l, 2)?;
                let n = num(l, 1, "the real index")?;
                if n <= 1e-6 {
                    bail!(
                        "{}: ir {n}: the index of refraction must be positive",
                        l.loc
                    );
                }
                self.material_mut().ir = n;
                Ok(())
            }
            "o" => {
                if w.len() == 1 {
                    if self.objects.pop().is_none() {
                        bail!("{}: 'o' closes an object that was never opened", l.loc);
                    }
                } else {
                    self.objects.push(w[1].clone());
                }
                Ok(())
            }
            "f" => self.face(l, xf),
            "fh" => self.face_with_holes(l, xf),
            "sph" => self.sphere(l, xf),
            "cyl" => self.cylinder(l, xf),
            "cone" => self.cone(l, xf),
            "ring" => self.ring(l, xf),
            "prism" => self.prism(l, xf),
            "torus" | "ies" => bail!("{}: MGF entity '{}' is not supported", l.loc, w[0]),
            other => {
                if !self.warned.iter().any(|k| k == other) {
                    self.warned.push(other.to_string());
                    eprintln!(
                        "mgf: warning - {}: unknown MGF entity '{other}' skipped",
                        l.loc
                    );
                }
                Ok(())
            }
        }
    }

    fn current_vertex(&mut self, l: &Line) -> Result<&mut Vertex> {
        let name = self.cur_vertex.clone().ok_or_else(|| {
            anyhow!(
                "{}: '{}' without a current vertex (use 'v name =')",
                l.loc,
                l.words[0]
            )
        })?;
        Ok(self.vertices.get_mut(&name).expect("current vertex exists"))
    }

    fn context_vertex(&mut self, l: &Line) -> Result<()> {
        let usage = "'v name', 'v name =' or 'v name = template'";
        self.cur_vertex = context_entry(l, &mut self.vertices, "vertex", Vertex::default, usage)?;
        Ok(())
    }

    fn context_colour(&mut self, l: &Line) -> Result<()> {
        let usage = "'c', 'c name', 'c name =' or 'c name = template'";
        self.cur_colour = context_entry(l, &mut self.colours, "colour", || NEUTRAL, usage)?;
        if self.cur_colour.is_none() {
            self.unnamed_colour = None;
        }
        Ok(())
    }

    fn context_material(&mut self, l: &Line) -> Result<()> {
        let usage = "'m', 'm name', 'm name =' or 'm name = template'";
        let table = &mut self.materials;
        self.cur_material = context_entry(l, table, "material", Material::default, usage)?;
        if self.cur_material.is_none() {
            self.unnamed_material = Material::default();
        }
        Ok(())
    }

    /// The Radiance modifier name for the current material, emitting its definition
    /// when it is new or has changed since it was last emitted.
    fn use_material(&mut self, loc: &Loc) -> Result<String> {
        let (name, m) = match &self.cur_material {
            Some(n) => (n.clone(), self.materials[n].clone()),
            None => ("mgf_default".to_string(), self.unnamed_material.clone()),
        };
        if self.emitted.get(&name) != Some(&m) {
            let (ptype, rargs) =
                radiance_material(&m).map_err(|e| anyhow!("{loc}: material '{name}': {e}"))?;
            self.out.push(Primitive {
                modifier: None,
                modifier_name: "void".into(),
                ptype: ptype.into(),
                name: name.clone(),
                sargs: Vec::new(),
                iargs: Vec::new(),
                rargs,
                loc: loc.clone(),
            });
            self.emitted.insert(name.clone(), m);
        }
        Ok(name)
    }

    /// `objects.kind<n>`, counting each kind of surface separately (as mgf2rad names them).
    fn surface_name(&mut self, kind: &str) -> String {
        let n = self.counts.entry(kind.to_string()).or_insert(0);
        *n += 1;
        let mut s = self.objects.join(".");
        if !s.is_empty() {
            s.push('.');
        }
        format!("{s}{kind}{n}")
    }

    fn emit(&mut self, loc: &Loc, ptype: &str, kind: &str, rargs: Vec<f64>) -> Result<()> {
        let modifier_name = self.use_material(loc)?;
        let name = self.surface_name(kind);
        self.out.push(Primitive {
            modifier: None,
            modifier_name,
            ptype: ptype.into(),
            name,
            sargs: Vec::new(),
            iargs: Vec::new(),
            rargs,
            loc: loc.clone(),
        });
        Ok(())
    }

    fn vertex(&self, l: &Line, name: &str) -> Result<Vertex> {
        self.vertices
            .get(name)
            .copied()
            .ok_or_else(|| anyhow!("{}: undefined vertex '{name}'", l.loc))
    }

    fn face(&mut self, l: &Line, xf: &Transform) -> Result<()> {
        if l.words.len() < 4 {
            bail!("{}: 'f' needs at least 3 vertices", l.loc);
        }
        let mut pts = Vec::new();
        for n in &l.words[1..] {
            pts.push(xf.point(self.vertex(l, n)?.p));
        }
        self.polygon(l, xf, pts, "f")
    }

    fn polygon(
        &mut self,
        l: &Line,
        xf: &Transform,
        mut pts: Vec<[f64; 3]>,
        kind: &str,
    ) -> Result<()> {
        if xf.mirrors() {
            pts.reverse();
        }
        let rargs = pts.iter().flatten().copied().collect();
        self.emit(&l.loc, "polygon", kind, rargs)
    }

    fn face_with_holes(&mut self, l: &Line, xf: &Transform) -> Result<()> {
        // Contours separated by '-': the outer one, then holes, joined by seams back to
        // the outer contour's last vertex.
        let mut contours: Vec<Vec<[f64; 3]>> = vec![Vec::new()];
        for n in &l.words[1..] {
            if n == "-" {
                contours.push(Vec::new());
            } else {
                let p = xf.point(self.vertex(l, n)?.p);
                contours.last_mut().expect("a contour").push(p);
            }
        }
        if contours.iter().any(|c| c.len() < 3) {
            bail!("{}: 'fh': every contour needs at least 3 vertices", l.loc);
        }
        let mut pts = contours[0].clone();
        let anchor = *pts.last().expect("outer contour");
        for hole in &contours[1..] {
            pts.extend_from_slice(hole);
            pts.push(hole[0]);
            pts.push(anchor);
        }
        self.polygon(l, xf, pts, "f")
    }

    fn scale(xf: &Transform) -> f64 {
        xf.sca.abs()
    }

    fn sphere(&mut self, l: &Line, xf: &Transform) -> Result<()> {
        nargs(l, 2)?;
        let c = xf.point(self.vertex(l, &l.words[1])?.p);
        let r = num(l, 2, "a radius")?;
        if r == 0.0 {
            bail!("{}: sphere of zero radius", l.loc);
        }
        let ptype = if r < 0.0 { "bubble" } else { "sphere" };
        self.emit(
            &l.loc,
            ptype,
            "s",
            vec![c[0], c[1], c[2], r.abs() * Self::scale(xf)],
        )
    }

    fn cylinder(&mut self, l: &Line, xf: &Transform) -> Result<()> {
        nargs(l, 3)?;
        let a = xf.point(self.vertex(l, &l.words[1])?.p);
        let r = num(l, 2, "a radius")?;
        let b = xf.point(self.vertex(l, &l.words[3])?.p);
        if r == 0.0 {
            bail!("{}: cylinder of zero radius", l.loc);
        }
        let ptype = if r < 0.0 { "tube" } else { "cylinder" };
        let s = r.abs() * Self::scale(xf);
        self.emit(
            &l.loc,
            ptype,
            "cy",
            vec![a[0], a[1], a[2], b[0], b[1], b[2], s],
        )
    }

    fn cone(&mut self, l: &Line, xf: &Transform) -> Result<()> {
        nargs(l, 4)?;
        let a = xf.point(self.vertex(l, &l.words[1])?.p);
        let r1 = num(l, 2, "a radius")?;
        let b = xf.point(self.vertex(l, &l.words[3])?.p);
        let r2 = num(l, 4, "a radius")?;
        if (r1 < 0.0 && r2 > 0.0) || (r1 > 0.0 && r2 < 0.0) || (r1 == 0.0 && r2 == 0.0) {
            bail!(
                "{}: cone radii {r1} {r2}: both of one sign, not both zero",
                l.loc
            );
        }
        let inward = r1 < 0.0 || r2 < 0.0;
        let s = Self::scale(xf);
        let ptype = if inward { "cup" } else { "cone" };
        self.emit(
            &l.loc,
            ptype,
            "c",
            vec![
                a[0],
                a[1],
                a[2],
                b[0],
                b[1],
                b[2],
                r1.abs() * s,
                r2.abs() * s,
            ],
        )
    }

    fn ring(&mut self, l: &Line, xf: &Transform) -> Result<()> {
        nargs(l, 3)?;
        let v = self.vertex(l, &l.words[1])?;
        let (r0, r1) = (num(l, 2, "an inner radius")?, num(l, 3, "an outer radius")?);
        if !(0.0 <= r0 && r0 < r1) {
            bail!("{}: ring radii {r0} {r1}: need 0 <= inner < outer", l.loc);
        }
        if v.n == [0.0; 3] {
            bail!(
                "{}: ring centre vertex '{}' has no normal ('n')",
                l.loc,
                l.words[1]
            );
        }
        let c = xf.point(v.p);
        let n = xf.vector(v.n);
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        let s = Self::scale(xf);
        self.emit(
            &l.loc,
            "ring",
            "r",
            vec![
                c[0],
                c[1],
                c[2],
                n[0] / len,
                n[1] / len,
                n[2] / len,
                r0 * s,
                r1 * s,
            ],
        )
    }

    fn prism(&mut self, l: &Line, xf: &Transform) -> Result<()> {
        if l.words.len() < 5 {
            bail!("{}: 'prism' needs at least 3 vertices and a length", l.loc);
        }
        let nv = l.words.len() - 2;
        let len = num(l, nv + 1, "a length")?;
        let mut base = Vec::new();
        for n in &l.words[1..=nv] {
            base.push(self.vertex(l, n)?.p);
        }
        // Newell normal of the base (counter-clockwise = toward the viewer); the prism
        // extends the other way, so the base faces outward.
        let mut nrm = [0.0f64; 3];
        for i in 0..nv {
            let (p, q) = (base[i], base[(i + 1) % nv]);
            nrm[0] += (p[1] - q[1]) * (p[2] + q[2]);
            nrm[1] += (p[2] - q[2]) * (p[0] + q[0]);
            nrm[2] += (p[0] - q[0]) * (p[1] + q[1]);
        }
        let nl = (nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]).sqrt();
        if nl == 0.0 {
            bail!("{}: prism base has no area", l.loc);
        }
        let off = [-nrm[0] / nl * len, -nrm[1] / nl * len, -nrm[2] / nl * len];
        let top: Vec<[f64; 3]> = base
            .iter()
            .map(|p| [p[0] + off[0], p[1] + off[1], p[2] + off[2]])
            .collect();
        for i in 0..nv {
            let j = (i + nv - 1) % nv;
            let side = vec![top[i], base[i], base[j], top[j]];
            let side = side.into_iter().map(|p| xf.point(p)).collect();
            self.polygon(l, xf, side, "f")?;
        }
        let cap: Vec<[f64; 3]> = top.iter().rev().map(|p| xf.point(*p)).collect();
        self.polygon(l, xf, cap, "f")?;
        let b: Vec<[f64; 3]> = base.iter().map(|p| xf.point(*p)).collect();
        self.polygon(l, xf, b, "f")
    }
}

/// Index of the bare `xf` closing the `xf` at `start`.
fn matching_xf_end(lines: &[Line], start: usize) -> Result<usize> {
    let mut depth = 0usize;
    for (k, l) in lines.iter().enumerate().skip(start) {
        if l.words[0] == "xf" {
            if l.words.len() > 1 {
                depth += 1;
            } else {
                depth -= 1;
                if depth == 0 {
                    return Ok(k);
                }
            }
        }
    }
    bail!(
        "{}: 'xf' transform not closed by a bare 'xf' before the end of the file",
        lines[start].loc
    )
}

/// The Radiance type and real arguments of an MGF material, by mgf2rad's rules.
fn radiance_material(m: &Material) -> Result<(&'static str, Vec<f64>)> {
    if m.ed > 0.1 {
        let c = m.ed_c.rgb(m.ed / (std::f64::consts::PI * WHITE_EFFICACY));
        return Ok(("light", c.to_vec()));
    }
    let smooth = m.rs_a <= 0.02 && m.ts_a <= 0.02;
    if m.ir > 1.1 && m.ts > 0.25 && m.rs <= 0.125 && m.rd + m.td <= 0.05 && smooth {
        if m.sides == 1 {
            bail!("one-sided glazing (Radiance dielectric) is not supported; use 'sides 2'");
        }
        let t = m.ts_c.rgb(m.ts);
        let r = m.rs_c.rgb(m.rs);
        return Ok(("glass", vec![t[0] + r[0], t[1] + r[1], t[2] + r[2], m.ir]));
    }
    if m.td + m.ts > 0.01 {
        if m.rs > 0.0 && m.ts > 0.0 && (m.rs_a - m.ts_a).abs() > 1e-9 {
            bail!("specular reflection and transmission of different roughness need Radiance's WGMDfunc, which fenestra does not support");
        }
        let cols: Vec<&Chroma> = [(m.rd, &m.rd_c), (m.td, &m.td_c), (m.ts, &m.ts_c)]
            .iter()
            .filter(|(v, _)| *v > 0.0)
            .map(|(_, c)| *c)
            .collect();
        if cols.windows(2).any(|w| !w[0].same(w[1])) || (m.rs > 0.0 && !m.rs_c.is_grey()) {
            bail!("differently coloured components need Radiance's WGMDfunc, which fenestra does not support");
        }
        let chroma = cols.first().copied().copied().unwrap_or(NEUTRAL);
        let a = m.rd + m.td + m.ts;
        let c = chroma.rgb(a / (1.0 - m.rs));
        let rough = if m.ts > 0.0 { m.ts_a } else { m.rs_a };
        return Ok((
            "trans",
            vec![
                c[0],
                c[1],
                c[2],
                m.rs,
                rough,
                (m.td + m.ts) / a,
                if m.td + m.ts > 0.0 {
                    m.ts / (m.td + m.ts)
                } else {
                    0.0
                },
            ],
        ));
    }
    if m.rs < 0.1 && (m.rs < 0.1 * m.rd || m.rs_c.is_grey()) {
        let c = m.rd_c.rgb(m.rd / (1.0 - m.rs));
        return Ok(("plastic", vec![c[0], c[1], c[2], m.rs, m.rs_a]));
    }
    if m.rd > 0.0 && !m.rd_c.same(&m.rs_c) {
        bail!("diffuse and specular reflection of different colours need Radiance's WGMDfunc, which fenestra does not support");
    }
    let c = m.rs_c.rgb(m.rd + m.rs);
    Ok((
        "metal",
        vec![c[0], c[1], c[2], m.rs / (m.rd + m.rs), m.rs_a],
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn conv(text: &str) -> Vec<Primitive> {
        convert(text, "t.mgf").unwrap()
    }

    #[test]
    fn warm_white_plastic_as_mgf2rad() {
        let p = conv("m w =\n c\n cxy .36 .37\n rd .70\n rs .03 .05\nv a =\n p 0 0 0\nv b =\n p 1 0 0\nv c =\n p 1 1 0\nm w\nf a b c\n");
        assert_eq!(p[0].ptype, "plastic");
        let want = [0.749332, 0.733038, 0.490587, 0.03, 0.05];
        for (g, w) in p[0].rargs.iter().zip(want) {
            assert!((g - w).abs() < 2e-6, "{:?}", p[0].rargs);
        }
        assert_eq!(p[1].name, "f1");
        assert_eq!(p[1].modifier_name, "w");
    }

    #[test]
    fn array_transform_as_mgf2rad() {
        let text = "v a =\n p 0 0 -.04\nv b =\n p 1 0 -.04\nv c =\n p 1 1 -.04\nm m =\n rd .5\no B\nxf -rx -20 -a 3 -t 0 .03 0\nm m\nf a b c\nxf\no\n";
        let p = conv(text);
        let polys: Vec<&Primitive> = p.iter().filter(|q| q.ptype == "polygon").collect();
        assert_eq!(polys.len(), 3);
        assert_eq!(polys[1].name, "B.a1.f2");
        assert!((polys[1].rargs[1] - (0.03 - 0.013680805)).abs() < 1e-6);
    }

    #[test]
    fn errors_name_the_line() {
        let e = convert("v a =\n p 0 0 0\nf a b c\n", "x.mgf").unwrap_err();
        assert!(e.to_string().contains("x.mgf:3"), "{e}");
        let e = convert("xf -t 1 0 0\n", "x.mgf").unwrap_err();
        assert!(e.to_string().contains("not closed"), "{e}");
        let e = convert("m q =\n rd 1.5\n", "x.mgf").unwrap_err();
        assert!(e.to_string().contains("x.mgf:2"), "{e}");
    }
}
