//! Geometry of a surface primitive (polygon, sphere, bubble, cone, cup, cylinder, tube,
//! ring) checked and built once, for the tracer and for oconv alike: what one refuses or
//! ignores, so does the other.

use anyhow::{anyhow, Result};
use fenestra_scene::Primitive;
use glam::DVec3;

use crate::polygon::Polygon;
use crate::shape::Shape;

/// Radiance's FTINY (double-precision builds): radii up to it are zero.
const FTINY: f64 = 1e-6;

/// What a surface primitive gives.
pub enum Built {
    /// A shape to trace, with a warning about it (e.g. a non-planar polygon).
    Shape(Shape, Option<String>),
    /// Nothing to trace (degenerate geometry), with the warning saying so.
    Ignored(String),
}

/// Whether `ptype` is a surface whose geometry [`shape_of`] builds.
pub fn is_geometry(ptype: &str) -> bool {
    matches!(
        ptype,
        "polygon" | "sphere" | "bubble" | "cone" | "cup" | "cylinder" | "tube" | "ring"
    )
}

/// Builds the shape of a geometry primitive: an error for the wrong argument count, a
/// warning and nothing for degenerate geometry (zero area, zero radius, zero length), as
/// Radiance's oconv does; a sphere of negative radius turns inside out with a warning
/// (a sphere becomes a bubble and the reverse), also as Radiance.
pub fn shape_of(p: &Primitive) -> Result<Built> {
    let r = &p.rargs;
    let bad = |what: &str| anyhow!("{}: {} '{}': {what}", p.loc, p.ptype, p.name);
    let ignored = |what: &str| {
        Ok(Built::Ignored(format!(
            "{}: {} '{}': {what}; ignored",
            p.loc, p.ptype, p.name
        )))
    };
    let mut warn = None;
    let shape = match p.ptype.as_str() {
        "polygon" => {
            if r.len() % 3 != 0 {
                return Err(bad("polygon needs a multiple of 3 real arguments"));
            }
            let verts: Vec<DVec3> = r.chunks(3).map(|c| DVec3::new(c[0], c[1], c[2])).collect();
            return match Polygon::new(verts) {
                Ok((poly, warn)) => Ok(Built::Shape(
                    Shape::Polygon(poly),
                    warn.map(|w| format!("{}: polygon '{}': {w}", p.loc, p.name)),
                )),
                Err(e) => ignored(&e.to_string()),
            };
        }
        "sphere" | "bubble" => {
            if r.len() != 4 {
                return Err(bad("needs 4 real arguments (centre and radius)"));
            }
            if !r[3].is_finite() {
                return Err(bad("radius is not a finite number"));
            }
            let mut inward = p.ptype == "bubble";
            if r[3] < -FTINY {
                inward = !inward;
                let taken = if inward { "bubble" } else { "sphere" };
                warn = Some(inside_out(p, "radius", taken));
            } else if r[3] <= FTINY {
                return ignored("zero radius");
            }
            return Ok(Built::Shape(
                Shape::Sphere {
                    c: DVec3::new(r[0], r[1], r[2]),
                    r: r[3].abs(),
                    inward,
                },
                warn,
            ));
        }
        "cone" | "cup" | "cylinder" | "tube" => {
            let cyl = p.ptype == "cylinder" || p.ptype == "tube";
            if r.len() != if cyl { 7 } else { 8 } {
                return Err(bad("wrong number of real arguments"));
            }
            let p0 = DVec3::new(r[0], r[1], r[2]);
            let p1 = DVec3::new(r[3], r[4], r[5]);
            let (r0, r1) = if cyl { (r[6], r[6]) } else { (r[6], r[7]) };
            let len = (p1 - p0).length();
            // Radiance's rules: a radius within FTINY of 0 is 0; both 0, or of opposite
            // signs, is degenerate; a negative radius turns the surface inside out (cone ↔
            // cup, cylinder ↔ tube) with a warning and is taken as its magnitude
            let (s0, s1) = (sign(r0), sign(r1));
            if len.is_nan() || len <= 0.0 || s0 + s1 == 0 || !r0.is_finite() || !r1.is_finite() {
                return Ok(Built::Ignored(format!(
                    "{}: {} '{}' is degenerate; ignored",
                    p.loc, p.ptype, p.name
                )));
            }
            let mut inward = p.ptype == "cup" || p.ptype == "tube";
            if s0 < 0 || s1 < 0 {
                inward = !inward;
                let taken = match (cyl, inward) {
                    (true, true) => "tube",
                    (true, false) => "cylinder",
                    (false, true) => "cup",
                    (false, false) => "cone",
                };
                warn = Some(inside_out(p, if cyl { "radius" } else { "radii" }, taken));
            }
            Shape::Cone {
                p0,
                axis: (p1 - p0) / len,
                len,
                r0: r0.abs() * f64::from(s0.abs()),
                r1: r1.abs() * f64::from(s1.abs()),
                inward,
            }
        }
        "ring" => {
            if r.len() != 8 {
                return Err(bad("needs 8 real arguments"));
            }
            let n = DVec3::new(r[3], r[4], r[5]);
            // Radiance's rules: radii within FTINY of 0 are 0, a negative one or two equal
            // ones are degenerate, and the larger is the outer whichever comes first
            let (s0, s1) = (sign(r[6]), sign(r[7]));
            let (r0, r1) = (r[6] * f64::from(s0), r[7] * f64::from(s1));
            let nl = n.length();
            if nl.is_nan() || nl <= 0.0 || s0 < 0 || s1 < 0 || (r0 - r1).abs() <= FTINY {
                return Ok(Built::Ignored(format!(
                    "{}: ring '{}' is degenerate; ignored",
                    p.loc, p.name
                )));
            }
            Shape::Ring {
                c: DVec3::new(r[0], r[1], r[2]),
                n: n.normalize(),
                r0: r0.min(r1),
                r1: r0.max(r1),
            }
        }
        other => return Err(bad(&format!("'{other}' is not a geometry type"))),
    };
    Ok(Built::Shape(shape, warn))
}

/// The warning for a surface a negative radius turned inside out.
fn inside_out(p: &Primitive, radius: &str, taken: &str) -> String {
    format!(
        "{}: {} '{}': negative {radius} (taken as a {taken})",
        p.loc, p.ptype, p.name
    )
}

/// The sign of a radius as Radiance reads it: 0 within FTINY of 0 (NaN counts as 0).
fn sign(x: f64) -> i32 {
    if x < -FTINY {
        -1
    } else if x > FTINY {
        1
    } else {
        0
    }
}
