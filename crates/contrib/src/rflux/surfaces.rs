//! Sender and receiver surfaces: the polygons, rings and sources of a Radiance file, grouped
//! by modifier with the `#@rfluxmtx` directives in effect, read the way rfluxmtx reads them
//! (comments and `!command` lines included; other primitives skipped).

use anyhow::{bail, Context, Result};
use glam::DVec3;

use super::directive::Params;

/// Smallest area a surface may have (Radiance's FTINY²).
const MIN_AREA: f64 = 1e-12;

/// The shape of one surface.
#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    /// Polygon vertices.
    Polygon(Vec<DVec3>),
    /// A ring (disk with a hole): centre, unit axis, inner and outer radius.
    Ring {
        /// Centre.
        centre: DVec3,
        /// Unit axis (the normal).
        axis: DVec3,
        /// Inner radius.
        r0: f64,
        /// Outer radius.
        r1: f64,
    },
    /// A distant source: direction and angular diameter (degrees).
    Source {
        /// Direction towards the source.
        dir: DVec3,
        /// Angular diameter (degrees).
        angle: f64,
    },
}

/// One surface of a group.
#[derive(Debug, Clone, PartialEq)]
pub struct Surface {
    /// The surface's name.
    pub name: String,
    /// Its shape.
    pub shape: Shape,
    /// Unit normal (for a source: minus its direction).
    pub normal: DVec3,
    /// Area (for a source: `π sin²(angle/2)`).
    pub area: f64,
}

impl Surface {
    /// `true` for a source.
    pub fn is_source(&self) -> bool {
        matches!(self.shape, Shape::Source { .. })
    }
}

/// Surfaces sharing a modifier, with their directives.
#[derive(Debug, Clone)]
pub struct Group {
    /// The modifier (tracked by rcontrib for a receiver).
    pub modifier: String,
    /// Directives in effect.
    pub params: Params,
    /// Surfaces, in file order.
    pub surfaces: Vec<Surface>,
    /// Area-weighted sum of the normals.
    pub normal_sum: DVec3,
}

impl Group {
    fn new(modifier: &str, params: Params) -> Self {
        Group {
            modifier: modifier.to_string(),
            params,
            surfaces: Vec::new(),
            normal_sum: DVec3::ZERO,
        }
    }

    /// The group's unit normal (`None` when the normals cancel).
    pub fn normal(&self) -> Option<DVec3> {
        let l = self.normal_sum.length();
        (l > 0.0 && l.is_finite()).then(|| self.normal_sum / l)
    }

    /// The up vector: as given, else +Z unless the normal is within ~45° of ±Z, then +Y.
    pub fn up(&self, normal: DVec3) -> DVec3 {
        self.params.up.unwrap_or(if normal.z.abs() < 0.7 {
            DVec3::Z
        } else {
            DVec3::Y
        })
    }
}

/// A primitive as read: modifier, type, name and arguments.
struct Prim {
    modifier: String,
    ptype: String,
    name: String,
    reals: Vec<f64>,
}

/// What reading a file met, in order.
enum Item {
    Directive(String),
    Prim(Prim),
}

/// Reads a scene spec (a file, or `!command` whose output is read) into items.
fn read_items(spec: &str, items: &mut Vec<Item>, warnings: &mut Vec<String>) -> Result<()> {
    let (text, origin) = if let Some(cmd) = spec.strip_prefix('!') {
        let out = fenestra_cfmt::sh_c(cmd)
            .stderr(std::process::Stdio::inherit())
            .output()
            .with_context(|| format!("cannot run '{cmd}'"))?;
        if !out.status.success() {
            bail!(
                "error loading '{spec}' (the command failed: {})",
                out.status
            );
        }
        (
            String::from_utf8_lossy(&out.stdout).into_owned(),
            spec.to_string(),
        )
    } else {
        let bytes = std::fs::read(spec).with_context(|| format!("cannot load '{spec}'"))?;
        if fenestra_scene::compiled::is_compiled(&bytes)
            || fenestra_scene::compiled::is_radiance_octree(&bytes)
        {
            bail!("'{spec}' is an octree; senders and receivers must be Radiance scene text");
        }
        (
            String::from_utf8_lossy(&bytes).into_owned(),
            spec.to_string(),
        )
    };
    parse_text(&text, &origin, items, warnings)
}

/// A word cursor over scene text that knows line numbers.
struct Cursor<'a> {
    text: &'a str,
    pos: usize,
    origin: &'a str,
}

impl<'a> Cursor<'a> {
    /// Line number of a byte position (counted only when a message needs it).
    fn line_at(&self, pos: usize) -> usize {
        self.text[..pos].matches('\n').count() + 1
    }

    fn skip_space(&mut self) {
        let rest = &self.text[self.pos..];
        self.pos += rest.len() - rest.trim_start().len();
    }

    fn rest_of_line(&mut self) -> &'a str {
        let rest = &self.text[self.pos..];
        let end = rest.find('\n').unwrap_or(rest.len());
        self.pos += (end + 1).min(rest.len());
        &rest[..end]
    }

    fn word(&mut self, what: &str) -> Result<&'a str> {
        self.skip_space();
        let rest = &self.text[self.pos..];
        let end = rest.find(char::is_whitespace).unwrap_or(rest.len());
        if end == 0 {
            let last = self.text.trim_end().len();
            let line = self.text[..last].matches('\n').count() + 1;
            bail!(
                "{}:{line}: unexpected end of file (expected {what})",
                self.origin
            );
        }
        self.pos += end;
        Ok(&rest[..end])
    }

    fn count(&mut self, what: &str) -> Result<usize> {
        let w = self.word(what)?;
        match w.parse::<usize>() {
            Ok(n) if n <= 1 << 24 => Ok(n),
            _ => bail!(
                "{}:{}: expected {what} (an argument count), found '{w}'",
                self.origin,
                self.line_at(self.pos)
            ),
        }
    }
}

fn parse_text(
    text: &str,
    origin: &str,
    items: &mut Vec<Item>,
    warnings: &mut Vec<String>,
) -> Result<()> {
    let mut c = Cursor {
        text,
        pos: 0,
        origin,
    };
    loop {
        c.skip_space();
        if c.pos >= text.len() {
            return Ok(());
        }
        let rest = &text[c.pos..];
        if rest.starts_with('!') {
            let cmd = c.rest_of_line().trim_end();
            read_items(cmd, items, warnings)?;
            continue;
        }
        if let Some(after) = rest.strip_prefix('#') {
            let line = c.rest_of_line();
            let body = &line[1..];
            if !after.starts_with(char::is_whitespace) {
                if let Some(d) = body.strip_prefix("@rfluxmtx") {
                    if d.is_empty() || d.starts_with(char::is_whitespace) {
                        items.push(Item::Directive(d.to_string()));
                    }
                }
            }
            continue;
        }
        let modifier = c.word("a modifier")?.to_string();
        let ptype = c.word("a primitive type")?.to_string();
        let name = c.word("a primitive name")?.to_string();
        if ptype == "alias" {
            c.word("the aliased modifier")?;
            continue;
        }
        let ns = c.count("the number of string arguments")?;
        for _ in 0..ns {
            c.word("a string argument")?;
        }
        let ni = c.count("the number of integer arguments")?;
        for _ in 0..ni {
            c.word("an integer argument")?;
        }
        let nr = c.count("the number of real arguments")?;
        let mut reals = Vec::with_capacity(nr.min(4096));
        for _ in 0..nr {
            let w = c.word("a real argument")?;
            match fenestra_cli::opts::parse_real(w) {
                Some(v) if v.is_finite() => reals.push(v),
                _ => bail!(
                    "{origin}:{}: '{name}': expected a real argument, found '{w}'",
                    c.line_at(c.pos)
                ),
            }
        }
        items.push(Item::Prim(Prim {
            modifier,
            ptype,
            name,
            reals,
        }));
    }
}

fn is_surface(ptype: &str) -> bool {
    matches!(ptype, "polygon" | "ring" | "source")
}

/// Builds a surface; `Ok(None)` (with a warning) for a zero-area one.
fn make_surface(p: &Prim, warnings: &mut Vec<String>) -> Result<Option<Surface>> {
    let r = &p.reals;
    let bad_count = || anyhow::anyhow!("bad argument count for surface element '{}'", p.name);
    let bad_orient = || anyhow::anyhow!("bad orientation for surface element '{}'", p.name);
    let (shape, normal, area) = match p.ptype.as_str() {
        "polygon" => {
            if r.len() < 9 || r.len() % 3 != 0 {
                return Err(bad_count());
            }
            let v: Vec<DVec3> = r.chunks(3).map(|c| DVec3::new(c[0], c[1], c[2])).collect();
            let mut sum = DVec3::ZERO;
            let mut e1 = v[1] - v[0];
            for w in &v[2..] {
                let e2 = *w - v[0];
                sum += e1.cross(e2);
                e1 = e2;
            }
            let len = sum.length();
            let n = if len > 0.0 { sum / len } else { DVec3::ZERO };
            (Shape::Polygon(v), n, 0.5 * len)
        }
        "ring" => {
            if r.len() != 8 {
                return Err(bad_count());
            }
            let axis = DVec3::new(r[3], r[4], r[5]);
            if axis.length() == 0.0 {
                return Err(bad_orient());
            }
            let axis = axis.normalize();
            let (r0, r1) = if r[7] < r[6] {
                (r[7], r[6])
            } else {
                (r[6], r[7])
            };
            let area = std::f64::consts::PI * (r1 * r1 - r0 * r0);
            (
                Shape::Ring {
                    centre: DVec3::new(r[0], r[1], r[2]),
                    axis,
                    r0,
                    r1,
                },
                axis,
                area,
            )
        }
        _ => {
            if r.len() != 4 {
                return Err(bad_count());
            }
            let dir = DVec3::new(r[0], r[1], r[2]);
            if dir.length() == 0.0 {
                return Err(bad_orient());
            }
            let s = (r[3].to_radians() / 2.0).sin();
            (
                Shape::Source {
                    dir: dir.normalize(),
                    angle: r[3],
                },
                -dir.normalize(),
                std::f64::consts::PI * s * s,
            )
        }
    };
    if area.is_nan() || area <= MIN_AREA {
        warnings.push(format!("zero area for surface '{}'", p.name));
        return Ok(None);
    }
    Ok(Some(Surface {
        name: p.name.clone(),
        shape,
        normal,
        area,
    }))
}

/// The receiver groups of a file, in file order: a new group starts where the modifier
/// changes, taking the directives read since the previous group (the basis persists).
pub fn receivers(spec: &str, warnings: &mut Vec<String>) -> Result<Vec<Group>> {
    let mut items = Vec::new();
    read_items(spec, &mut items, warnings)?;
    let mut groups: Vec<Group> = Vec::new();
    let mut params = Params::default();
    let mut pending = String::new();
    for it in items {
        match it {
            Item::Directive(d) => {
                pending.push_str(&d);
                pending.push('\n');
            }
            Item::Prim(p) if is_surface(&p.ptype) => {
                let new = groups.last().is_none_or(|g| g.modifier != p.modifier);
                if new {
                    if let Some(g) = groups.last() {
                        params = g.params.clone();
                        params.reset_group();
                    }
                    params.apply(&pending)?;
                    pending.clear();
                    groups.push(Group::new(&p.modifier, params.clone()));
                }
                if let Some(s) = make_surface(&p, warnings)? {
                    let g = groups.last_mut().expect("a group was pushed");
                    g.normal_sum += s.normal * s.area;
                    g.surfaces.push(s);
                }
            }
            Item::Prim(_) => {}
        }
    }
    if groups.is_empty() {
        bail!("missing receiver surface! ('{spec}' has no polygon, ring or source)");
    }
    Ok(groups)
}

/// The sender: every polygon and ring of the file as one group (directives apply as
/// they are met; a second modifier is warned about; a source is an error).
pub fn sender(spec: &str, warnings: &mut Vec<String>) -> Result<Group> {
    let mut items = Vec::new();
    read_items(spec, &mut items, warnings)?;
    let mut group: Option<Group> = None;
    let mut pending = String::new();
    for it in items {
        match it {
            Item::Directive(d) => {
                pending.push_str(&d);
                pending.push('\n');
            }
            Item::Prim(p) if is_surface(&p.ptype) => {
                if p.ptype == "source" {
                    bail!("cannot use source as a sender! ('{}' in '{spec}')", p.name);
                }
                let g = group.get_or_insert_with(|| Group::new(&p.modifier, Params::default()));
                if g.modifier != p.modifier {
                    warnings.push("multiple modifiers in sender".to_string());
                    g.modifier = p.modifier.clone();
                }
                g.params.apply(&pending)?;
                pending.clear();
                if let Some(s) = make_surface(&p, warnings)? {
                    g.normal_sum += s.normal * s.area;
                    g.surfaces.push(s);
                }
            }
            Item::Prim(_) => {}
        }
    }
    let Some(g) = group.filter(|g| !g.surfaces.is_empty()) else {
        bail!("no sender surface! ('{spec}' has no polygon or ring)");
    };
    Ok(g)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn items(text: &str) -> Vec<Item> {
        let mut v = Vec::new();
        let mut w = Vec::new();
        parse_text(text, "t.rad", &mut v, &mut w).unwrap();
        v
    }

    #[test]
    fn directives_comments_and_primitives_are_read_in_order() {
        let v = items(
            "# a comment\n#@rfluxmtx h=kf u=Z\nvoid glow g 0 0 4 1 1 1 0\n\
             g polygon w 0 0 9 0 0 0 1 0 0 1 0 1\n#@rfluxmtxx not one\n",
        );
        assert_eq!(v.len(), 3);
        assert!(matches!(&v[0], Item::Directive(d) if d.trim() == "h=kf u=Z"));
        assert!(matches!(&v[2], Item::Prim(p) if p.ptype == "polygon" && p.reals.len() == 9));
    }

    #[test]
    fn polygon_normal_and_area_follow_the_vertex_order() {
        let p = Prim {
            modifier: "m".into(),
            ptype: "polygon".into(),
            name: "p".into(),
            reals: vec![0., 0., 0., 2., 0., 0., 2., 0., 1., 0., 0., 1.],
        };
        let s = make_surface(&p, &mut Vec::new()).unwrap().unwrap();
        assert!((s.area - 2.0).abs() < 1e-12);
        assert!((s.normal - DVec3::new(0.0, -1.0, 0.0)).length() < 1e-12);
    }

    #[test]
    fn truncated_input_names_file_and_line() {
        let mut v = Vec::new();
        let e = parse_text(
            "m polygon p 0 0 9 0 0 0\n1 0",
            "w.rad",
            &mut v,
            &mut Vec::new(),
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("w.rad:2"), "{e}");
    }
}
