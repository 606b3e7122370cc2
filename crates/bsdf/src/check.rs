//! What `checkBSDF` reports about a Klems BSDF: per component the Lambertian part, the
//! largest directional-hemispherical total, the angular resolution and the reciprocity
//! error, plus hemispherical totals for normal and diffuse incidence and an energy check.
//!
//! Conventions (learned by running Radiance's checkBSDF): Radiance's "Interior Refl" is the
//! XML `Reflection Back`, "Exterior Refl" `Reflection Front`, "Int->Ext Trans"
//! `Transmission Back`, "Ext->Int Trans" `Transmission Front`. Values are the `Visible`
//! (CIE Y) blocks. The reciprocity error of an element pair is `|a − b| / (max(a, b) + 1e-6)`
//! between `f(o ← i)` and `f'(rot(i) ← rot(o))`, rot = the same-ring patch turned by 180°,
//! `f' = f` for reflection and `f'` = the opposite transmission block; min, mean and max are over
//! all element pairs whose elements both exceed 1e-4.

pub mod sampled;

use crate::klems::KlemsBasis;
use crate::model::{Bsdf, Direction, KlemsMatrix, Wavelength};

pub use crate::radiance::{radiance_min, LAMBERTIAN_MIN, TREE_LAMBERTIAN_MAX};

/// Summary of one component (one XML direction).
#[derive(Debug, Clone, PartialEq)]
pub struct ComponentCheck {
    /// Lambertian part as CIE X, Y, Z hemispherical fractions (π × minimum; 0 below
    /// [`LAMBERTIAN_MIN`]).
    pub lambertian_xyz: [f64; 3],
    /// The Lambertian part's CIE Y as a BSDF value (sr⁻¹; 0 when nothing is split off).
    pub lambertian_y: f64,
    /// Largest directional-hemispherical total over incident patches (fraction).
    pub max_total: f64,
    /// Angular resolution in degrees: `2·√(λ_min/π)` for the smallest projected solid angle.
    pub min_angle_deg: f64,
    /// Directional-hemispherical total at normal incidence (incident patch 0).
    pub normal_total: f64,
    /// Hemispherical-hemispherical total for diffuse incidence: `Σ_i λ_i·total(i) / π`.
    pub diffuse_total: f64,
    /// Directional-hemispherical total per incident patch.
    pub totals: Vec<f64>,
}

/// Reciprocity error statistics (fractions).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reciprocity {
    /// Smallest element error.
    pub min: f64,
    /// Mean over all element pairs.
    pub mean: f64,
    /// Largest element error.
    pub max: f64,
}

/// Summarises the `Visible` Klems matrix of `d`, `None` when the file has none (the file
/// loaded first in a process, for the colour dither; see [`component_with`]).
pub fn component(b: &Bsdf, d: Direction) -> Option<ComponentCheck> {
    let colour = crate::radiance::colour_lambertians(b, &mut crate::radiance::Drand48::new());
    component_with(b, d, &colour)
}

/// [`component`] with the coloured Lambertian parts Radiance splits off this file, from
/// [`crate::radiance::colour_lambertians`] with the process's dither generator. A coloured
/// component (CIE-X and CIE-Z blocks) reports π × that part's CIE XYZ (zero when nothing is split
/// off); a grey one π × its minimum ([`radiance_min`]) when above [`LAMBERTIAN_MIN`].
pub fn component_with(
    b: &Bsdf,
    d: Direction,
    colour: &[(Direction, [f64; 3])],
) -> Option<ComponentCheck> {
    let y = b.klems(d, &Wavelength::Visible)?;
    let ymin = radiance_min(y);
    let coloured =
        b.klems(d, &Wavelength::CieX).is_some() && b.klems(d, &Wavelength::CieZ).is_some();
    let lambertian = if coloured {
        colour
            .iter()
            .find(|(c, _)| *c == d)
            .map_or([0.0; 3], |(_, xyz)| *xyz)
    } else if ymin > LAMBERTIAN_MIN {
        [ymin; 3]
    } else {
        [0.0; 3]
    };
    let lambertian_xyz = lambertian.map(|v| std::f64::consts::PI * v);
    let totals = totals(y);
    let max_total = totals.iter().copied().fold(0.0, f64::max);
    let lmin = |k: &KlemsBasis| k.lambdas().into_iter().fold(f64::INFINITY, f64::min);
    let lam_min = lmin(&y.outgoing).min(lmin(&y.incident));
    let min_angle_deg = (2.0 * (lam_min / std::f64::consts::PI).sqrt()).to_degrees();
    let lam_in = y.incident.lambdas();
    let diffuse_total =
        totals.iter().zip(&lam_in).map(|(t, l)| t * l).sum::<f64>() / std::f64::consts::PI;
    Some(ComponentCheck {
        lambertian_xyz,
        lambertian_y: lambertian[1],
        max_total,
        min_angle_deg,
        normal_total: totals.first().copied().unwrap_or(0.0),
        diffuse_total,
        totals,
    })
}

/// Directional-hemispherical total per incident patch of a matrix (no Lambertian split, so no
/// colour dither: [`ComponentCheck::totals`] without the rest of [`component_with`]).
fn totals(y: &KlemsMatrix) -> Vec<f64> {
    (0..y.incident.len()).map(|i| y.hemispherical(i)).collect()
}

/// Radiance's relative difference: `|a − b| / (max(a, b) + 1e-6)`.
fn pair_error(a: f64, b: f64) -> f64 {
    (a - b).abs() / (a.max(b) + 1e-6)
}

/// Reciprocity error of `f` against `g` (`f(o ← i)` vs `g(rot(i) ← rot(o))`); `None` when
/// the bases do not allow the pairing (g's outgoing basis must be f's incident one and
/// vice versa).
pub fn reciprocity(f: &KlemsMatrix, g: &KlemsMatrix) -> Option<Reciprocity> {
    reciprocity_shifted(f, g, 0.0)
}

/// [`reciprocity`] with `shift` added to every value of `g`.
fn reciprocity_shifted(f: &KlemsMatrix, g: &KlemsMatrix, shift: f64) -> Option<Reciprocity> {
    if f.incident != g.outgoing || f.outgoing != g.incident {
        return None;
    }
    let (ni, no) = (f.incident.len(), f.outgoing.len());
    let rot_i: Vec<usize> = (0..ni)
        .map(|i| f.incident.rotate180(i).unwrap_or(i))
        .collect();
    let rot_o: Vec<usize> = (0..no)
        .map(|o| f.outgoing.rotate180(o).unwrap_or(o))
        .collect();
    let (mut lo, mut hi, mut sum, mut count) = (f64::INFINITY, 0.0f64, 0.0, 0usize);
    for (o, &ro) in rot_o.iter().enumerate() {
        for (i, &ri) in rot_i.iter().enumerate() {
            // g's outgoing index rot(i) lives in f's incident basis, its incident rot(o) in f's outgoing.
            let (a, b) = (f.get(o, i), g.get(ri, ro) + shift);
            // Radiance leaves out pairs with an element at most 1e-4.
            if a <= 1e-4 || b <= 1e-4 {
                continue;
            }
            let e = pair_error(a, b);
            lo = lo.min(e);
            hi = hi.max(e);
            sum += e;
            count += 1;
        }
    }
    Some(Reciprocity {
        min: if lo.is_finite() { lo } else { 0.0 },
        mean: sum / count.max(1) as f64,
        max: hi,
    })
}

/// Reciprocity of a reflection component with itself (`None` without that block).
pub fn reflection_reciprocity(b: &Bsdf, d: Direction) -> Option<Reciprocity> {
    let m = b.klems(d, &Wavelength::Visible)?;
    reciprocity(m, m)
}

/// Reciprocity between the two transmission components (`None` unless both exist), with the
/// Lambertian parts of the file loaded first in a process (see
/// [`transmission_reciprocity_with`]).
pub fn transmission_reciprocity(b: &Bsdf) -> Option<Reciprocity> {
    // One fresh generator, as `component` gives each call: both parts from the same dither.
    let colour = crate::radiance::colour_lambertians(b, &mut crate::radiance::Drand48::new());
    let l = |d| component_with(b, d, &colour).map_or(0.0, |c| c.lambertian_y);
    transmission_reciprocity_with(
        b,
        l(Direction::TransmissionFront),
        l(Direction::TransmissionBack),
    )
}

/// Reciprocity between the two transmission components given the Lambertian parts (sr⁻¹, CIE Y)
/// split off XML `Transmission Front` (`front`) and `Transmission Back` (`back`). Radiance keeps
/// one Lambertian transmission, the front's: `Transmission Back` enters with its own part
/// replaced by the front's (found by experiment: offsets added to either block, or both).
pub fn transmission_reciprocity_with(b: &Bsdf, front: f64, back: f64) -> Option<Reciprocity> {
    let f = b.klems(Direction::TransmissionFront, &Wavelength::Visible)?;
    let g = b.klems(Direction::TransmissionBack, &Wavelength::Visible)?;
    reciprocity_shifted(f, g, front - back)
}

/// The largest `T + R` over incident patches for light arriving on one side
/// (`exterior`: XML `Transmission Front` + `Reflection Front`; otherwise the Back blocks),
/// with the incident patch where it occurs. `None` when neither block exists or their
/// incident bases differ.
pub fn energy_balance(b: &Bsdf, exterior: bool) -> Option<(f64, usize)> {
    let (t, r) = if exterior {
        (Direction::TransmissionFront, Direction::ReflectionFront)
    } else {
        (Direction::TransmissionBack, Direction::ReflectionBack)
    };
    // Only the totals are read: they do not depend on the Lambertian split or its dither.
    let t = b.klems(t, &Wavelength::Visible).map(totals);
    let r = b.klems(r, &Wavelength::Visible).map(totals);
    let sum: Vec<f64> = match (t, r) {
        (None, None) => return None,
        (Some(t), None) => t,
        (None, Some(r)) => r,
        (Some(t), Some(r)) => {
            if t.len() != r.len() {
                return None;
            }
            t.iter().zip(&r).map(|(a, b)| a + b).collect()
        }
    };
    sum.iter().copied().enumerate().map(|(i, v)| (v, i)).fold(
        None,
        |best: Option<(f64, usize)>, x| match best {
            Some(b) if b.0 >= x.0 => Some(b),
            _ => Some(x),
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Block, BlockData};

    fn lambertian(v: f64, d: Direction) -> Block {
        let k = KlemsBasis::full().clone();
        let n = k.len();
        Block {
            wavelength: Wavelength::Visible,
            direction: d,
            data_type: "BTDF".into(),
            data: BlockData::Klems(KlemsMatrix {
                incident: k.clone(),
                outgoing: k,
                values: vec![v; n * n],
            }),
        }
    }

    #[test]
    fn lambertian_component() {
        let v = 0.5 / std::f64::consts::PI;
        let b = Bsdf {
            blocks: vec![
                lambertian(v, Direction::TransmissionFront),
                lambertian(v, Direction::TransmissionBack),
                lambertian(0.7 / std::f64::consts::PI, Direction::ReflectionFront),
            ],
            ..Default::default()
        };
        let c = component(&b, Direction::TransmissionFront).unwrap();
        // Radiance's minimum: the constant times its smallest position factor, within 3e-4 below.
        let l = c.lambertian_xyz[1];
        assert!(l < 0.5 && l > 0.5 * (1.0 - 3e-4) - 1e-7, "{l}");
        assert!((c.max_total - 0.5).abs() < 1e-9);
        assert!((c.normal_total - 0.5).abs() < 1e-9);
        assert!((c.diffuse_total - 0.5).abs() < 1e-9);
        assert!(
            (c.min_angle_deg - 8.562).abs() < 1e-3,
            "{}",
            c.min_angle_deg
        );
        let r = transmission_reciprocity(&b).unwrap();
        assert_eq!((r.min, r.mean, r.max), (0.0, 0.0, 0.0));
        let (e, _) = energy_balance(&b, true).unwrap();
        assert!((e - 1.2).abs() < 1e-9);
        assert!(energy_balance(&b, false).is_some());
        assert!(reflection_reciprocity(&b, Direction::ReflectionBack).is_none());
    }
}
