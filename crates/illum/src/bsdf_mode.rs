//! mkillum from WINDOW 6 / genBSDF data (`#@mkillum d=file.xml`, the method Radiance 4 had
//! and Radiance 6 removed): the radiance arriving at the window's outside is sampled over
//! the BSDF's incident Klems patches, light sources added explicitly (a sun is not lost in
//! a patch of 0.05 sr), and the illum's distribution is the transmission matrix applied to
//! it, at the BSDF's own resolution. The scene must be the outside as seen from the window
//! (as for a daylight matrix: no window material in the opening). A tensor-tree file is
//! first projected on the full Klems basis (`fenestra_bsdf::tree_klems`).

use std::sync::Arc;

use anyhow::{bail, Context, Result};
use fenestra_bsdf::klems::Frame;
use fenestra_bsdf::KlemsBasis;
use glam::DVec3;
use rayon::prelude::*;

use crate::geometry::Face;
use crate::sample::{Distribution, Job};
use fenestra_trace::rng::stratified2;

/// Grid of the written distribution: altitude rows (uniform in sin²θ) and azimuth columns.
pub const GRID: (usize, usize) = (45, 72);

/// A BSDF file's transmission (room side ← outside), as dctimestep builds it.
#[derive(Debug)]
pub struct BsdfData {
    /// `T[o][i]` = BSDF·λ_in, RGB: rows outgoing (room side), columns incident (outside).
    pub t: fenestra_bsdf::radiance::RgbMatrix,
    /// Incident (column) basis.
    pub incident: &'static KlemsBasis,
    /// Outgoing (row) basis.
    pub outgoing: &'static KlemsBasis,
}

fn basis_of(n: usize) -> Option<&'static KlemsBasis> {
    [
        KlemsBasis::full(),
        KlemsBasis::half(),
        KlemsBasis::quarter(),
    ]
    .into_iter()
    .find(|b| b.len() == n)
}

/// Loads `name` (found through `resolver`: RAYPATH and fenestra's library by default).
pub fn load(name: &str, resolver: &fenestra_cli::raypath::Resolver) -> Result<Arc<BsdfData>> {
    let path = resolver
        .find(name)
        .with_context(|| format!("cannot find BSDF file '{name}' (searched RAYPATH)"))?;
    let b = fenestra_bsdf::read_file(&path)
        .map_err(|e| anyhow::anyhow!("cannot load BSDF file '{}': {e}", path.display()))?;
    let t = match fenestra_bsdf::radiance::transmission_matrix(&b) {
        Ok(t) => t,
        // a tensor tree: its transmission projected on the full Klems basis
        Err(e) => match fenestra_bsdf::tree_render::TreeBsdf::load(&b) {
            Some(tree) => {
                let full = KlemsBasis::full();
                if !tree.has(fenestra_bsdf::tree_render::Lobe::Transmission, true)
                    && tree.lambertian(fenestra_bsdf::tree_render::Lobe::Transmission, true) <= 0.0
                {
                    bail!("BSDF file '{}' has no transmission", path.display());
                }
                fenestra_bsdf::tree_klems::tree_transmission_matrix(&tree, full)
            }
            None => bail!("BSDF file '{}': {e}", path.display()),
        },
    };
    let (Some(outgoing), Some(incident)) = (basis_of(t.rows), basis_of(t.cols)) else {
        bail!(
            "BSDF file '{}': a {}x{} transmission matrix is not on a Klems full, half or quarter basis",
            path.display(),
            t.rows,
            t.cols
        );
    };
    Ok(Arc::new(BsdfData {
        t,
        incident,
        outgoing,
    }))
}

/// The Klems frame of a window with normal `n` (into the room) and up vector `up`:
/// (u, v, n) with u = unit(up × n), v = n × u; `None` when `up` is along `n`.
pub fn frame(n: DVec3, up: DVec3) -> Option<[DVec3; 3]> {
    let u = up.cross(n);
    (u.length() > 1e-9 * up.length().max(1e-300)).then(|| {
        let u = u.normalize();
        [u, n.cross(u), n]
    })
}

/// The default up vector of a window with normal `n`: +Z unless `n` is within ~45° of ±Z,
/// then +Y (rfluxmtx's rule).
pub fn default_up(n: DVec3) -> DVec3 {
    if n.z.abs() < 0.7 {
        DVec3::Z
    } else {
        DVec3::Y
    }
}

/// The distribution of a polygon window with BSDF `bsdf` (frame axes returned with it).
pub fn face(
    job: &Job,
    f: &Face,
    bsdf: &BsdfData,
    up: DVec3,
) -> Result<Option<(Distribution, [DVec3; 3])>> {
    let Some(axes) = frame(f.norm, up) else {
        bail!("the BSDF up vector is along the window's normal (give u= across the window)");
    };
    let [u, v, n] = axes;
    let kframe = Frame::new(n.to_array(), up.to_array());
    let s = job.nsamps;
    let ni = bsdf.incident.len();
    let eps = 0.005 * f.area.sqrt();
    // a point uniform over the window (Face::uniform_point), moved outward
    let point = |xy: (f64, f64), rng: &mut fenestra_trace::rng::Rng| -> Option<DVec3> {
        f.uniform_point(xy, rng, 1000).0.map(|q| q - eps * n)
    };
    // radiance arriving from outside, per incident patch (sources not seen directly)
    let rays: Vec<Option<(usize, [f64; 3])>> = (0..ni * s)
        .into_par_iter()
        .map(|idx| {
            let (i, k, mut rng, id) = job.start_ray(idx);
            // start point and direction within the patch stratified jointly (as the
            // traced mode's bins)
            let [x, y, s0, s1] = job.cell_point(i, k, &mut rng);
            let l = bsdf.incident.sample_projected(i, s0, s1)?;
            let dir = -(l[0] * u + l[1] * v + l[2] * n);
            let org = point((x, y), &mut rng)?;
            Some((i, job.tracer.radiance_specular(id, org, dir)))
        })
        .collect();
    if rays.iter().any(Option::is_none) {
        return Ok(None);
    }
    let mut lin = vec![[0.0f64; 3]; ni];
    for (i, c) in rays.into_iter().flatten() {
        for (a, b) in lin[i].iter_mut().zip(c) {
            *a += b / s as f64;
        }
    }
    // light sources, as uniform radiance over their patch, from points spread evenly over
    // the window (a sun's shadow edge crosses windows: its irradiance needs many points)
    let lam = bsdf.incident.lambdas();
    let npts = (16 * s).max(256);
    // per point: (incident patch, radiance added to it) of each source sample
    type PatchLight = Vec<(usize, [f64; 3])>;
    let lights: Vec<Option<PatchLight>> = (0..npts)
        .into_par_iter()
        .map(|k| {
            let (mut rng, id) = job.stream((ni * s + k) as u64);
            let xy = stratified2(k, npts, &mut rng);
            let org = point(xy, &mut rng)?;
            let mut out = Vec::new();
            for src in job.tracer.source_light(id, org) {
                let c = -src.dir.dot(n);
                if c <= 0.0 {
                    continue;
                }
                let Some(i) = kframe.bin(bsdf.incident, src.dir.to_array()) else {
                    continue;
                };
                let w = src.omega * c / lam[i] / npts as f64;
                out.push((i, src.value.map(|x| x * w)));
            }
            Some(out)
        })
        .collect();
    for l in lights {
        let Some(l) = l else { return Ok(None) };
        for (i, v) in l {
            for (a, b) in lin[i].iter_mut().zip(v) {
                *a += b;
            }
        }
    }
    // radiance leaving toward the room, per outgoing patch
    let no = bsdf.outgoing.len();
    let lout: Vec<[f64; 3]> = (0..no)
        .map(|o| {
            let mut acc = [0.0; 3];
            for (i, l) in lin.iter().enumerate() {
                let t = bsdf.t.data[o * ni + i];
                for c in 0..3 {
                    acc[c] += t[c] * l[c];
                }
            }
            acc
        })
        .collect();
    // sampled on the illum's grid: node (a, z) at sin²θ = (a + ½)/nalt, φ = 2π z/nazi
    let (nalt, nazi) = GRID;
    let mut sums = Vec::with_capacity(nalt * nazi);
    for a in 0..nalt {
        let s2 = (a as f64 + 0.5) / nalt as f64;
        let (st, ct) = (s2.sqrt(), (1.0 - s2).sqrt());
        for z in 0..nazi {
            let ph = std::f64::consts::TAU * z as f64 / nazi as f64;
            let e = st * ph.cos() * u + st * ph.sin() * v + ct * n;
            let o = kframe.bin(bsdf.outgoing, (-e).to_array());
            sums.push(o.map_or([0.0; 3], |o| lout[o]));
        }
    }
    let d = Distribution {
        nalt,
        nazi,
        nsamps: 1,
        sumsq: vec![0.0; sums.len()],
        lights: vec![[0.0; 3]; sums.len()],
        sums,
    };
    Ok(Some((d, axes)))
}
