//! The `BSDF` material with a Klems XML file (thickness 0): Radiance's front/back
//! conventions (front = +Z = surface normal side; XML blocks mapped crosswise) and its
//! "view vector in" evaluation order, so a room-side viewer looking out uses the
//! `Transmission Back` block, as Radiance's renderer does.
//!
//! On loading, each matrix gives up its Lambertian part as Radiance's loader does: the
//! minimum over the whole matrix (with Radiance's position factor) when above 0.01/π is
//! subtracted from every element and kept as a diffuse reflectance or transmittance
//! (π × minimum); a remainder whose largest hemispherical total is 0.001 or less is
//! dropped. A file with one transmission matrix gives its Lambertian part to both sides.

use std::sync::Arc;

use anyhow::{bail, Context, Result};
use fenestra_bsdf::tree_render::{Lobe, Slice, TreeBsdf};
use fenestra_bsdf::{Direction, KlemsMatrix, Wavelength};
use fenestra_io::raypath::Resolver;
use fenestra_scene::Primitive;
use glam::DVec3;

/// One Klems component (its non-diffuse remainder) ready for evaluation and sampling.
#[derive(Debug)]
pub struct Component {
    m: KlemsMatrix,
    /// Per element (`o·n_in + i`): RGB over Y of a coloured file's element (`None`: grey).
    colour: Option<Vec<[f32; 3]>>,
    /// Per incident patch: Σ RGB·λ over outgoing patches (the coloured hemispherical total).
    hemi_rgb: Vec<DVec3>,
    /// Per incident patch: cumulative BSDF·λ over outgoing patches.
    cdf: Vec<Vec<f64>>,
    /// Whether the outgoing side is the back (−Z) side.
    out_back: bool,
    /// Whether the incident (view) vector is on the back side.
    in_back: bool,
    /// Largest directional-hemispherical total over incident patches.
    pub max_hemi: f64,
    /// Projected solid angle of the smallest patch of the bases.
    pub min_size: f64,
}

/// A compiled BSDF material.
#[derive(Debug, Clone)]
pub struct BsdfMat {
    /// Up vector (world).
    pub up: DVec3,
    /// Reflection for a viewer on the front side (XML Reflection Back).
    pub rf: Option<Arc<Component>>,
    /// Reflection for a viewer on the back side (XML Reflection Front).
    pub rb: Option<Arc<Component>>,
    /// Transmission for a viewer on the front side (XML Transmission Back).
    pub tf: Option<Arc<Component>>,
    /// Transmission for a viewer on the back side (XML Transmission Front).
    pub tb: Option<Arc<Component>>,
    /// Diffuse reflectance (hemispherical) of the front side: the real arguments plus the
    /// Lambertian part of the front reflection matrix.
    pub rd_front: DVec3,
    /// Diffuse reflectance of the back side (arguments plus Lambertian part).
    pub rd_back: DVec3,
    /// Diffuse transmittance for a viewer on the front side (arguments plus Lambertian part).
    pub td_front: DVec3,
    /// Diffuse transmittance for a viewer on the back side.
    pub td_back: DVec3,
    /// Tensor-tree data (the Klems components are then absent).
    pub tree: Option<Arc<TreeBsdf>>,
    /// Thickness (first string argument): non-zero for a proxy of geometry modelled in
    /// place, which view and shadow rays pass straight through.
    pub thick: f64,
    /// `aBSDF`: the transmission peak along the view is extracted and passed to view and
    /// shadow rays as a straight-through component.
    pub through: bool,
    /// The file's own Lambertian parts (hemispherical): reflection front, reflection back,
    /// transmission for a front view, transmission for a back view.
    pub lamb: [f64; 4],
}

/// One lobe of a BSDF material as a view on one side sees it: a Klems component or a
/// tensor tree's.
#[derive(Clone, Copy)]
pub enum LobeData<'a> {
    /// A Klems matrix (its non-diffuse remainder).
    Klems(&'a Component),
    /// A tensor tree.
    Tree(&'a TreeBsdf, Lobe, bool),
}

impl LobeData<'_> {
    /// Largest hemispherical total over views (an upper bound for trees).
    pub fn max_hemi(&self) -> f64 {
        match self {
            LobeData::Klems(c) => c.max_hemi,
            LobeData::Tree(..) => f64::INFINITY,
        }
    }

    /// Projected solid angle of the cell holding view `v` (a Klems patch; a tree's smallest
    /// leaf in the view's slice).
    pub fn view_size(&self, v: DVec3) -> f64 {
        let klems = |c: &Component| c.view_patch_size(v).unwrap_or(0.0);
        self.per_view(v, klems, |s| s.smallest(), 0.0)
    }

    /// Directional-hemispherical total for view `v`.
    pub fn hemi(&self, v: DVec3) -> f64 {
        self.per_view(v, |c| c.hemi(v), |s| s.total(), 0.0)
    }

    /// Directional-hemispherical total for view `v` in RGB (a grey lobe: the total in
    /// every channel).
    pub fn hemi_rgb(&self, v: DVec3) -> DVec3 {
        let tree = |s: Slice| DVec3::from(s.total_rgb());
        self.per_view(v, |c| c.hemi_rgb(v), tree, DVec3::ZERO)
    }

    /// `klems` of a Klems lobe's component; for a tree lobe, `tree` of its slice for view
    /// `v`, or `none` where the tree has none.
    #[inline]
    fn per_view<R>(
        &self,
        v: DVec3,
        klems: impl FnOnce(&Component) -> R,
        tree: impl FnOnce(Slice) -> R,
        none: R,
    ) -> R {
        match self {
            LobeData::Klems(c) => klems(c),
            LobeData::Tree(t, lobe, front) => {
                t.slice(*lobe, *front, v.to_array()).map_or(none, tree)
            }
        }
    }

    /// A direction for view `v` drawn in proportion to the BSDF × projected solid angle,
    /// with the view's hemispherical total and the colour (RGB over Y) of the cell drawn.
    pub fn sample(&self, v: DVec3, u: f64, u0: f64, u1: f64) -> Option<(DVec3, f64, DVec3)> {
        match self {
            LobeData::Klems(c) => c.sample(v, u, u0, u1),
            LobeData::Tree(t, lobe, front) => {
                let s = t.slice(*lobe, *front, v.to_array())?;
                let d = s.sample(u, u0, u1)?;
                let colour = DVec3::from(t.colour(*lobe, *front, v.to_array(), d));
                Some((DVec3::from(d), s.total(), colour))
            }
        }
    }

    /// Colour (RGB over Y) of the cell of view `v` and light `l` (ones for a grey lobe).
    pub fn colour(&self, v: DVec3, l: DVec3) -> DVec3 {
        match self {
            LobeData::Klems(c) => c.colour(v, l),
            LobeData::Tree(t, lobe, front) => {
                DVec3::from(t.colour(*lobe, *front, v.to_array(), l.to_array()))
            }
        }
    }

    /// BSDF value (sr⁻¹) for view `v` and light `l`, and the projected solid angle over
    /// which Radiance jitters the view for it (the smaller of the two Klems patches; the
    /// tree's leaf holding the pair).
    pub fn eval_sized(&self, v: DVec3, l: DVec3) -> (f64, f64) {
        match self {
            LobeData::Klems(c) => {
                let (f, size, _) = c.eval_full(v, l);
                (f, size)
            }
            LobeData::Tree(t, lobe, front) => t.eval(*lobe, *front, v.to_array(), l.to_array()),
        }
    }

    /// [`Self::eval_sized`] with the colour of [`Self::colour`] where it comes free: a Klems
    /// cell is looked up once for all three; a tree's colour (`None`) costs a descent of
    /// its own, for the caller to make only when it needs it.
    pub fn eval_full(&self, v: DVec3, l: DVec3) -> (f64, f64, Option<DVec3>) {
        match self {
            LobeData::Klems(c) => {
                let (f, size, colour) = c.eval_full(v, l);
                (f, size, Some(colour))
            }
            LobeData::Tree(..) => {
                let (f, size) = self.eval_sized(v, l);
                (f, size, None)
            }
        }
    }

    /// Projected solid angle of the lobe's smallest cell (Radiance's `minProjSA`).
    pub fn min_size(&self) -> f64 {
        match self {
            LobeData::Klems(c) => c.min_size,
            LobeData::Tree(t, lobe, front) => t.min_size(*lobe, *front),
        }
    }

    /// BSDF value (sr⁻¹) for view `v` and light `l`.
    pub fn eval(&self, v: DVec3, l: DVec3) -> f64 {
        match self {
            LobeData::Klems(c) => c.eval(v, l),
            LobeData::Tree(t, lobe, front) => t.eval(*lobe, *front, v.to_array(), l.to_array()).0,
        }
    }
}

impl BsdfMat {
    /// The (reflection, transmission) lobes for a view on the front or back side.
    pub fn lobes(&self, front: bool) -> (Option<LobeData<'_>>, Option<LobeData<'_>>) {
        if let Some(t) = &self.tree {
            let get = |lobe| t.has(lobe, front).then_some(LobeData::Tree(t, lobe, front));
            return (get(Lobe::Reflection), get(Lobe::Transmission));
        }
        let (r, tr) = if front {
            (&self.rf, &self.tf)
        } else {
            (&self.rb, &self.tb)
        };
        (
            r.as_deref().map(LobeData::Klems),
            tr.as_deref().map(LobeData::Klems),
        )
    }
}

fn flip(v: DVec3, x: bool, z: bool) -> [f64; 3] {
    let s = if x { -1.0 } else { 1.0 };
    [s * v.x, s * v.y, if z { -v.z } else { v.z }]
}

impl Component {
    fn new(m: KlemsMatrix, rgb: Option<Vec<[f64; 3]>>, in_back: bool, out_back: bool) -> Component {
        let ni = m.incident.len();
        let lam: Vec<f64> = (0..m.outgoing.len())
            .map(|o| m.outgoing.projected_solid_angle(o).unwrap_or(0.0))
            .collect();
        let cdf: Vec<Vec<f64>> = (0..ni)
            .map(|i| {
                let mut acc = 0.0;
                lam.iter()
                    .enumerate()
                    .map(|(o, l)| {
                        acc += m.get(o, i).max(0.0) * l;
                        acc
                    })
                    .collect()
            })
            .collect();
        let max_hemi = cdf
            .iter()
            .map(|c: &Vec<f64>| c.last().copied().unwrap_or(0.0))
            .fold(0.0, f64::max);
        let min_size = (0..m.outgoing.len())
            .filter_map(|o| m.outgoing.projected_solid_angle(o))
            .chain((0..m.incident.len()).filter_map(|i| m.incident.projected_solid_angle(i)))
            .fold(f64::INFINITY, f64::min);
        let hemi_rgb: Vec<DVec3> = match &rgb {
            None => cdf
                .iter()
                .map(|c| DVec3::splat(c.last().copied().unwrap_or(0.0)))
                .collect(),
            Some(rgb) => (0..ni)
                .map(|i| {
                    lam.iter()
                        .enumerate()
                        .map(|(o, l)| DVec3::from(rgb[o * ni + i]) * *l)
                        .sum()
                })
                .collect(),
        };
        let colour = rgb.map(|rgb| {
            rgb.iter()
                .zip(&m.values)
                .map(|(c, &y)| {
                    if y > 0.0 {
                        [(c[0] / y) as f32, (c[1] / y) as f32, (c[2] / y) as f32]
                    } else {
                        [1.0; 3]
                    }
                })
                .collect()
        });
        Component {
            m,
            colour,
            hemi_rgb,
            cdf,
            out_back,
            in_back,
            max_hemi,
            min_size,
        }
    }

    /// Directional-hemispherical total (Σ BSDF·λ) for view `v`; 0 outside the basis.
    pub fn hemi(&self, v: DVec3) -> f64 {
        self.in_index(v)
            .and_then(|i| self.cdf[i].last().copied())
            .unwrap_or(0.0)
    }

    /// The coloured hemispherical total for view `v`.
    pub fn hemi_rgb(&self, v: DVec3) -> DVec3 {
        self.in_index(v).map_or(DVec3::ZERO, |i| self.hemi_rgb[i])
    }

    fn colour_at(&self, o: usize, i: usize) -> DVec3 {
        match &self.colour {
            Some(c) => {
                let f = c[o * self.m.incident.len() + i];
                DVec3::new(f64::from(f[0]), f64::from(f[1]), f64::from(f[2]))
            }
            None => DVec3::ONE,
        }
    }

    /// Colour (RGB over Y) of the element for view `v` and light `l`.
    pub fn colour(&self, v: DVec3, l: DVec3) -> DVec3 {
        match (self.in_index(v), self.out_index(l)) {
            (Some(i), Some(o)) => self.colour_at(o, i),
            _ => DVec3::ONE,
        }
    }

    /// Projected solid angle of the incident patch holding view `v`.
    pub fn view_patch_size(&self, v: DVec3) -> Option<f64> {
        self.in_index(v)
            .and_then(|i| self.m.incident.projected_solid_angle(i))
    }

    /// Incident index of a view vector `v` (local, pointing away from the surface).
    fn in_index(&self, v: DVec3) -> Option<usize> {
        // incident mappings: fi = (-x,-y,z), bi = (-x,-y,-z)
        self.m.incident.patch(flip(v, true, self.in_back))
    }

    /// Outgoing index of a light vector `l` (local, pointing away from the surface).
    fn out_index(&self, l: DVec3) -> Option<usize> {
        self.m.outgoing.patch(flip(l, false, self.out_back))
    }

    /// BSDF value (sr⁻¹), jitter size (the smaller projected solid angle of the two
    /// patches) and colour for view `v` and light `l`, each patch looked up once; zeros
    /// and a grey colour outside the bases.
    pub fn eval_full(&self, v: DVec3, l: DVec3) -> (f64, f64, DVec3) {
        let (Some(i), Some(o)) = (self.in_index(v), self.out_index(l)) else {
            return (0.0, 0.0, DVec3::ONE);
        };
        let size = self
            .m
            .incident
            .projected_solid_angle(i)
            .zip(self.m.outgoing.projected_solid_angle(o))
            .map_or(0.0, |(a, b)| a.min(b));
        (self.m.get(o, i).max(0.0), size, self.colour_at(o, i))
    }

    /// BSDF value (sr⁻¹) for view `v` and light `l`.
    pub fn eval(&self, v: DVec3, l: DVec3) -> f64 {
        match (self.in_index(v), self.out_index(l)) {
            (Some(i), Some(o)) => self.m.get(o, i).max(0.0),
            _ => 0.0,
        }
    }

    /// Samples an outgoing direction for view `v`: (local direction, hemispherical total,
    /// colour of the element drawn).
    pub fn sample(&self, v: DVec3, u: f64, u0: f64, u1: f64) -> Option<(DVec3, f64, DVec3)> {
        let i = self.in_index(v)?;
        let cdf = &self.cdf[i];
        let tot = *cdf.last()?;
        if tot <= 0.0 {
            return None;
        }
        let x = u * tot;
        let o = cdf.partition_point(|&c| c <= x).min(cdf.len() - 1);
        let d = self.m.outgoing.sample_projected(o, u0, u1)?;
        let z = if self.out_back { -d[2] } else { d[2] };
        Some((DVec3::new(d[0], d[1], z), tot, self.colour_at(o, i)))
    }
}

/// Compiles a `BSDF` primitive: `6 thick file ux uy uz funcfile`, 0/3/6/9 reals (the
/// file found through `resolver`).
pub fn compile(p: &Primitive, resolver: &Resolver) -> Result<BsdfMat> {
    // aBSDF has no thickness argument
    let through = p.ptype == "aBSDF";
    let o = usize::from(!through);
    let kind = &p.ptype;
    if p.sargs.len() < 5 + o {
        bail!(
            "{}: {kind} '{}' needs {} string arguments ({}file, up vector, function file)",
            p.loc,
            p.name,
            5 + o,
            if through { "" } else { "thickness, " }
        );
    }
    if p.sargs.len() > 5 + o {
        bail!("{}: {kind} '{}': transforms after the function file are not supported by fenestra's ray tracer", p.loc, p.name);
    }
    let num = |k: usize| -> Result<f64> {
        fenestra_scene::parse_real(&p.sargs[k]).with_context(|| {
            format!(
                "{}: {kind} '{}': '{}' is not a number",
                p.loc, p.name, p.sargs[k]
            )
        })
    };
    let thick = if through { 0.0 } else { num(0)? };
    let up = DVec3::new(num(1 + o)?, num(2 + o)?, num(3 + o)?);
    if up.length() == 0.0 {
        bail!("{}: {kind} '{}': zero up vector", p.loc, p.name);
    }
    if p.sargs[4 + o] != "." {
        bail!(
            "{}: {kind} '{}': function file '{}' is not supported (use '.')",
            p.loc,
            p.name,
            p.sargs[4 + o]
        );
    }
    let path = resolver
        .find_or_err(&p.sargs[o])
        .with_context(|| format!("{}: BSDF '{}'", p.loc, p.name))?;
    let b = fenestra_bsdf::read_file(&path)
        .map_err(|e| anyhow::anyhow!("{}: BSDF '{}': {e}", p.loc, p.name))?;
    let vis = Wavelength::Visible;
    let r = &p.rargs;
    let v3 = |k: usize| {
        if r.len() >= k + 3 {
            DVec3::new(r[k], r[k + 1], r[k + 2])
        } else {
            DVec3::ZERO
        }
    };
    if let Some(t) = TreeBsdf::load(&b) {
        let l = |lobe, front| DVec3::from(t.lambertian_rgb(lobe, front));
        return Ok(BsdfMat {
            up,
            rf: None,
            rb: None,
            tf: None,
            tb: None,
            rd_front: v3(0) + l(Lobe::Reflection, true),
            rd_back: v3(3) + l(Lobe::Reflection, false),
            td_front: v3(6) + l(Lobe::Transmission, true),
            td_back: v3(6) + l(Lobe::Transmission, false),
            lamb: [
                t.lambertian(Lobe::Reflection, true),
                t.lambertian(Lobe::Reflection, false),
                t.lambertian(Lobe::Transmission, true),
                t.lambertian(Lobe::Transmission, false),
            ],
            tree: Some(Arc::new(t)),
            thick,
            through,
        });
    }
    // Radiance's load: colour encoded, the Lambertian part split off (rf rb tf tb order)
    let comps = fenestra_bsdf::radiance::render_components(&b);
    let get = |d: Direction, in_back: bool, out_back: bool| {
        let k = match d {
            Direction::ReflectionBack => 0,
            Direction::ReflectionFront => 1,
            Direction::TransmissionBack => 2,
            Direction::TransmissionFront => 3,
        };
        match &comps[k] {
            None => (None, DVec3::ZERO, 0.0),
            Some(c) => (
                c.remainder
                    .clone()
                    .map(|r| Arc::new(Component::new(r, c.rgb.clone(), in_back, out_back))),
                DVec3::from(c.lambertian) * std::f64::consts::PI,
                c.lambertian_y * std::f64::consts::PI,
            ),
        }
    };
    let (rf, c_rf, l_rf) = get(Direction::ReflectionBack, false, false);
    let (rb, c_rb, l_rb) = get(Direction::ReflectionFront, true, true);
    let (tf, mut c_tf, mut l_tf) = get(Direction::TransmissionBack, false, true);
    let (tb, mut c_tb, mut l_tb) = get(Direction::TransmissionFront, true, false);
    // one transmission matrix: its Lambertian part serves both sides, as in Radiance
    let has = |d: Direction| b.klems(d, &vis).is_some();
    if !has(Direction::TransmissionBack) {
        (c_tf, l_tf) = (c_tb, l_tb);
    }
    if !has(Direction::TransmissionFront) {
        (c_tb, l_tb) = (c_tf, l_tf);
    }
    let any = [
        Direction::ReflectionBack,
        Direction::ReflectionFront,
        Direction::TransmissionBack,
        Direction::TransmissionFront,
    ]
    .into_iter()
    .any(has);
    if !any {
        bail!(
            "{}: BSDF '{}': '{}' has no visible Klems data",
            p.loc,
            p.name,
            path.display()
        );
    }
    Ok(BsdfMat {
        up,
        rf,
        rb,
        tf,
        tb,
        rd_front: v3(0) + c_rf,
        rd_back: v3(3) + c_rb,
        td_front: v3(6) + c_tf,
        td_back: v3(6) + c_tb,
        tree: None,
        thick,
        through,
        lamb: [l_rf, l_rb, l_tf, l_tb],
    })
}
