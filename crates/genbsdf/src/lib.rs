//! genBSDF's Klems characterisation in one process: a device's geometry traced with the
//! library's tracer from a stratified sample plane, every Klems incident direction in
//! turn, what leaves toward either hemisphere binned by Klems patch, as Radiance's genBSDF
//! gets it from rfluxmtx (facts from its `genBSDF.pl` and `wrapBSDF.c`; our own code).
//!
//! Geometry frame (genBSDF's): X = width, Y = up, +Z into the room; the device lies at
//! Z ≤ 0. Backward components (light from the room side, +Z) are `Transmission Back` and
//! `Reflection Back`; forward ones (light from outside) `Transmission Front` and
//! `Reflection Front` (WINDOW 6 naming, as wrapBSDF writes them). The element at row o,
//! column i is the flux leaving through patch o for light arriving within patch i, per
//! unit incident flux, divided by patch o's projected solid angle: the BSDF in sr⁻¹.
//! Patch indices use Radiance's mapping of directions to the XML's bases (the one the
//! `BSDF` material reads back): the incident direction (toward the source) mirrored in
//! x and y, each side's hemisphere folded onto +Z.

mod checkpoint;
pub mod geometry;
mod summary;
pub use summary::summary;
pub mod reduce;
pub mod reduce_stream;
pub mod tree4;

use anyhow::{bail, Result};
use fenestra_bsdf::{Block, BlockData, Bsdf, DataStructure, Direction, KlemsBasis, KlemsMatrix};
use fenestra_scene::Scene;
use fenestra_trace::{DVec3, TraceOptions, Tracer};
use rayon::prelude::*;

/// What one incident patch gathered, by slot (0..np toward the far side, np..2np back
/// toward the near side): sums over the samples of Y, of each sample's Y squared (with
/// `-E`), and of X and Z (with `+C`).
struct PatchSums {
    y: Vec<f64>,
    y_sq: Vec<f64>,
    x: Vec<f64>,
    z: Vec<f64>,
}

/// Which quantity a matrix holds.
#[derive(Clone, Copy)]
enum Channel {
    Y,
    YError,
    X,
    Z,
}

/// What to characterise and how.
#[derive(Debug, Clone)]
pub struct Options {
    /// Samples per incident direction asked for (`-c`; the sample plane's grid rounds it).
    pub samples: usize,
    /// Light from outside (`+f`): `Transmission Front`, `Reflection Front`.
    pub forward: bool,
    /// Light from the room (`+b`): `Transmission Back`, `Reflection Back`.
    pub backward: bool,
    /// The bounding box `x0 x1 y0 y1 z0 z1` (`-dim`), else the geometry's.
    pub dim: Option<[f64; 6]>,
    /// Render options (genBSDF's `-ab 5 -ad 700 -lw 3e-6` over rcontrib's defaults).
    pub trace: TraceOptions,
    /// Also estimate every element's standard error (`-E`).
    pub errors: bool,
    /// Colour (`+C`): CIE-X and CIE-Z blocks beside the `Visible` (Y) ones.
    pub colour: bool,
    /// A resumable run (`-checkpoint file`): directions done are kept there.
    pub checkpoint: Option<std::path::PathBuf>,
    /// The Klems basis (`-k kf|kh|kq`, fenestra): full (145 patches, Radiance's genBSDF's
    /// only one), half (77) or quarter (41).
    pub basis: &'static KlemsBasis,
    /// Rank-4 trees: reduce without the whole grid in memory, tracing every incident cell
    /// twice (`tree4::streams`: on by itself from `-t4 7`; forced here for tests).
    pub stream_trees: bool,
}

impl Options {
    /// genBSDF's defaults: `-c 2000`, backward only, `-ab 5 -ad 700 -lw 3e-6`.
    pub fn genbsdf() -> Options {
        let mut trace = TraceOptions::rcontrib();
        trace.ab = 5;
        trace.ad = 700;
        trace.lw = 3e-6;
        Options {
            samples: 2000,
            forward: false,
            backward: true,
            dim: None,
            trace,
            errors: false,
            colour: false,
            checkpoint: None,
            basis: KlemsBasis::full(),
            stream_trees: false,
        }
    }
}

/// The sample grid genBSDF uses for `n` samples over a `w` × `h` rectangle:
/// nx = ⌊√(n·w/h) + 1⌋, ny = ⌊n/nx + 1⌋.
pub fn grid(n: usize, w: f64, h: f64) -> (usize, usize) {
    let nx = ((n as f64 * w / h).sqrt() + 1.0).floor().max(1.0) as usize;
    let ny = (n as f64 / nx as f64 + 1.0).floor().max(1.0) as usize;
    (nx, ny)
}

/// The bounding box of a scene's surfaces: `[x0, x1, y0, y1, z0, z1]`.
pub fn bounding_box(scene: &Scene) -> Result<[f64; 6]> {
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for p in &scene.prims {
        if p.modifier.is_none() || !fenestra_trace::surface::is_geometry(&p.ptype) {
            continue;
        }
        if let fenestra_trace::surface::Built::Shape(s, _) = fenestra_trace::surface::shape_of(p)? {
            let (a, b) = s.bounds();
            lo = lo.min(a);
            hi = hi.max(b);
        }
    }
    if !lo.is_finite() || !hi.is_finite() {
        bail!("the device has no surfaces");
    }
    Ok([lo.x, hi.x, lo.y, hi.y, lo.z, hi.z])
}

/// The receivers: glows at infinity on the room side and behind, named so the device
/// cannot use the names.
const RECEIVERS: &str = "\
void glow genbsdf_receiver_face\n0\n0\n4 1 1 1 0\n\
genbsdf_receiver_face source genbsdf_face\n0\n0\n4 0 0 1 180\n\
void glow genbsdf_receiver_behind\n0\n0\n4 1 1 1 0\n\
genbsdf_receiver_behind source genbsdf_behind\n0\n0\n4 0 0 -1 180\n";

/// What both characterisations start from: the bounding box, genBSDF's warnings, and a
/// tracer over the device with the two receivers (tracked).
pub(crate) struct Setup {
    pub(crate) dim: [f64; 6],
    pub(crate) warnings: Vec<String>,
    pub(crate) tracer: Tracer,
    pub(crate) tracked: Vec<bool>,
}

/// Checks the device and builds its tracer with the receivers.
pub(crate) fn setup(scene: &Scene, opts: &Options) -> Result<Setup> {
    if !opts.forward && !opts.backward {
        bail!("nothing to do: neither +forward nor +backward");
    }
    let dim = match opts.dim {
        Some(d) => d,
        None => bounding_box(scene)?,
    };
    let [x0, x1, y0, y1, z0, z1] = dim;
    let (w, h) = (x1 - x0, y1 - y0);
    if !(w > 0.0 && h > 0.0) {
        bail!("the device's bounding box is empty ({w} x {h})");
    }
    if z0 >= 0.0 {
        bail!("Device entirely inside room!");
    }
    let mut warnings = Vec::new();
    if z1 > 1e-5 {
        warnings.push("Device extends into room".to_string());
    }
    if z1 * z1 > 0.01 * w * h {
        warnings.push("Device far behind Z==0 plane".to_string());
    }
    // the device with the two receivers
    let mut parser = fenestra_scene::Parser::new();
    parser.add_scene(scene.clone())?;
    parser.add_str(RECEIVERS, "genBSDF receivers")?;
    let full = parser.finish();
    let tracer = Tracer::new(&full, &opts.trace)?;
    // CIE X, Y, Z of an RGB contribution: Radiance's primaries with an equal-energy white
    // (Y alone for `Visible`; X and Z too with `+C`)
    let find = |name: &str| full.prims.iter().position(|p| p.name == name);
    let (Some(face), Some(behind)) = (
        find("genbsdf_receiver_face"),
        find("genbsdf_receiver_behind"),
    ) else {
        bail!("internal: receivers missing");
    };
    let mut tracked = vec![false; full.prims.len()];
    tracked[face] = true;
    tracked[behind] = true;
    Ok(Setup {
        dim,
        warnings,
        tracer,
        tracked,
    })
}

/// The sides a run characterises: (light from the room?, transmission direction,
/// reflection direction), backward first.
pub(crate) fn sides(opts: &Options) -> Vec<(bool, Direction, Direction)> {
    let mut sides = Vec::new();
    if opts.backward {
        sides.push((true, Direction::TransmissionBack, Direction::ReflectionBack));
    }
    if opts.forward {
        sides.push((
            false,
            Direction::TransmissionFront,
            Direction::ReflectionFront,
        ));
    }
    sides
}

/// The scramble seeds of one incident direction (`key`) under `seed`, one per coordinate of
/// [`sample_start`]'s Sobol points.
pub(crate) fn direction_seeds(seed: u64, key: u64) -> [u64; 4] {
    fenestra_trace::sobol::scramble_seeds(seed ^ 0x736f_626f_6c34, key)
}

/// Where sample `k` of one incident direction starts and which way it heads within the
/// direction's cell: (x, y) on the box's `w` × `h` face from (x0, y0), and two numbers in
/// [0,1) for the direction (in that order: y, direction, direction, x), from a scrambled
/// Sobol point.
///
/// The four are stratified jointly, not each pair on its own: whether a ray passes between
/// two slats depends on where it starts across them and on its direction together, and a
/// joint stratification estimates that fraction far better than independently stratified
/// start points and directions paired at random. The scramble (`seeds`, from
/// [`direction_seeds`] of the incident direction) keeps every sample uniform, so the mean
/// stays unbiased; `rng` (the sample's own stream) fills the digits below the 32nd.
pub(crate) fn sample_start(
    seeds: [u64; 4],
    k: usize,
    rng: &mut fenestra_trace::rng::Rng,
    (x0, y0, w, h): (f64, f64, f64, f64),
) -> (f64, f64, f64, f64) {
    let [y, u0, u1, x] = fenestra_trace::sobol::point4(k as u32, seeds, || rng.next_f64());
    (x0 + w * x, y0 + h * y, u0, u1)
}

/// Adds one sample's squared total per slot to `sq` (for standard errors): the sample's
/// contributions `hits` (slot, value) summed per slot first (sorted in place).
pub(crate) fn add_squares(hits: &mut [(usize, f64)], sq: &mut [f64]) {
    hits.sort_unstable_by_key(|h| h.0);
    let mut j = 0;
    while j < hits.len() {
        let (slot, mut v) = hits[j];
        j += 1;
        while j < hits.len() && hits[j].0 == slot {
            v += hits[j].1;
            j += 1;
        }
        sq[slot] += v * v;
    }
}

/// The seed of the sample plane and directions: `base`, changed by the render options'
/// `-seed` (`-r '-seed N'`), so runs with different seeds are independent replicates.
pub(crate) fn sample_seed(base: u64, opts: &Options) -> u64 {
    base ^ opts.trace.seed.wrapping_mul(0x9e37_79b9_7f4a_7c15)
}

/// What a run measured: the bounding box used and the BSDF.
pub struct Characterised {
    /// `[x0, x1, y0, y1, z0, z1]`.
    pub dim: [f64; 6],
    /// Samples actually traced per incident direction.
    pub samples: usize,
    /// Warnings (as Radiance's genBSDF prints them).
    pub warnings: Vec<String>,
    /// The BSDF (Klems full basis, visible).
    pub bsdf: Bsdf,
    /// With [`Options::errors`]: the same blocks holding each element's standard error
    /// (sr⁻¹), from the spread of the per-sample contributions.
    pub errors: Option<Bsdf>,
    /// Rays the tracer traced, by kind (for `-v`).
    pub rays: fenestra_trace::RayCounts,
    /// What the tracer switched on, and why (for `-v`).
    pub effects: Vec<String>,
}

/// Characterises the device `scene` (genBSDF's frame) on the Klems full basis.
pub fn characterise(
    scene: &Scene,
    opts: &Options,
    pool: &rayon::ThreadPool,
) -> Result<Characterised> {
    characterise_with(scene, opts, pool, &|| {})
}

/// Number of incident directions a run traces (the Klems patches, per side asked for), for
/// progress bars.
pub fn directions(opts: &Options) -> u64 {
    opts.basis.len() as u64 * (u64::from(opts.forward) + u64::from(opts.backward))
}

/// [`characterise`], calling `done` after each incident direction (from worker threads).
pub fn characterise_with(
    scene: &Scene,
    opts: &Options,
    pool: &rayon::ThreadPool,
    done: &(dyn Fn() + Sync),
) -> Result<Characterised> {
    let Setup {
        dim,
        mut warnings,
        tracer,
        tracked,
    } = setup(scene, opts)?;
    let [x0, x1, y0, y1, z0, z1] = dim;
    let (w, h) = (x1 - x0, y1 - y0);
    let [x_w, y_w, z_w] = fenestra_bsdf::radiance::rgb_to_xyz_matrix();
    let (nx, ny) = grid(opts.samples.max(1), w, h);
    let n = nx * ny;
    let basis = opts.basis;
    let np = basis.len();
    let omega: Vec<f64> = (0..np)
        .map(|o| basis.projected_solid_angle(o).unwrap_or(0.0))
        .collect();
    let ckpt = match &opts.checkpoint {
        Some(path) => {
            let parts = format!(
                "{nx} {ny} {} {} {} {} {} {dim:?} {:?} {:?}",
                opts.basis.name(),
                opts.forward,
                opts.backward,
                opts.errors,
                opts.colour,
                opts.trace,
                scene.prims
            );
            let c = checkpoint::Checkpoint::open(path, &checkpoint::key(&parts))?;
            if c.len() > 0 {
                warnings.push(format!(
                    "resuming from '{}': {} of {} incident directions already done",
                    path.display(),
                    c.len(),
                    np * sides(opts).len()
                ));
            }
            Some(c)
        }
        None => None,
    };
    let fail: std::sync::Mutex<Option<anyhow::Error>> = std::sync::Mutex::new(None);
    let seed = sample_seed(0x6e6e_b5df, opts);
    let mut blocks = Vec::new();
    let mut error_blocks = Vec::new();
    for (side_k, &(from_room, tdir, rdir)) in sides(opts).iter().enumerate() {
        let z = if from_room { z1 + 1e-5 } else { z0 - 1e-5 };
        // per incident patch: flux fractions toward the far and near receivers, by patch
        // (indices 0..np far, np..2np near), and their per-sample sums of squares
        let rows: Vec<PatchSums> = pool.install(|| {
            (0..np)
                .into_par_iter()
                .map(|i| {
                    if let Some([y, y_sq, x, z]) = ckpt.as_ref().and_then(|c| c.get(side_k, i)) {
                        done();
                        return PatchSums {
                            y: y.clone(),
                            y_sq: y_sq.clone(),
                            x: x.clone(),
                            z: z.clone(),
                        };
                    }
                    let mut sum = vec![0.0; 2 * np];
                    let mut sq = vec![0.0; if opts.errors { 2 * np } else { 0 }];
                    let mut sx = vec![0.0; if opts.colour { 2 * np } else { 0 }];
                    let mut sz = sx.clone();
                    let mut hits: Vec<(usize, f64)> = Vec::new();
                    let key = (side_k * np + i) as u64;
                    let seeds = direction_seeds(seed, key);
                    for k in 0..n {
                        hits.clear();
                        let index = (key * n as u64) + k as u64;
                        let mut rng = fenestra_trace::rng::Rng::for_ray(seed, index);
                        let (px, py, u0, u1) = sample_start(seeds, k, &mut rng, (x0, y0, w, h));
                        let Some(b) = basis.sample_projected(i, u0, u1) else {
                            continue;
                        };
                        // the incident direction (toward the source) is b mirrored in x
                        // and y, on the source's side; rays travel the other way
                        let dir = if from_room {
                            DVec3::new(b[0], b[1], -b[2])
                        } else {
                            DVec3::new(b[0], b[1], b[2])
                        };
                        let org = DVec3::new(px, py, z);
                        tracer.contributions(index, org, dir, &tracked, &mut |c| {
                            if c.negligible_coef() {
                                return;
                            }
                            let dot = |w: [f64; 3]| -> f64 {
                                c.coef.iter().zip(w).map(|(a, w)| a * w).sum()
                            };
                            let y = dot(y_w);
                            let d = c.dir;
                            // the outgoing direction folded onto +Z
                            let o = basis.patch([d.x, d.y, d.z.abs()]);
                            let Some(o) = o else { return };
                            let goes_to_room = d.z > 0.0;
                            let slot = if goes_to_room != from_room { o } else { np + o };
                            hits.push((slot, y));
                            if opts.colour {
                                sx[slot] += dot(x_w);
                                sz[slot] += dot(z_w);
                            }
                        });
                        // in tracing order, so -E leaves the values as they are
                        for &(slot, v) in &hits {
                            sum[slot] += v;
                        }
                        if opts.errors {
                            add_squares(&mut hits, &mut sq);
                        }
                    }
                    done();
                    let sums = PatchSums {
                        y: sum,
                        y_sq: sq,
                        x: sx,
                        z: sz,
                    };
                    if let Some(c) = &ckpt {
                        let all = [
                            sums.y.clone(),
                            sums.y_sq.clone(),
                            sums.x.clone(),
                            sums.z.clone(),
                        ];
                        if let Err(e) = c.put(side_k, i, &all) {
                            fail.lock()
                                .unwrap_or_else(|e| e.into_inner())
                                .get_or_insert(e);
                        }
                    }
                    sums
                })
                .collect()
        });
        if let Some(e) = fail.lock().unwrap_or_else(|e| e.into_inner()).take() {
            return Err(e);
        }
        let nf = n as f64;
        // the mean over the samples (or its standard error) divided by the projected solid angle
        let matrix = |far_side: bool, channel: Channel| {
            let mut values = vec![0.0; np * np];
            let base = if far_side { 0 } else { np };
            for (i, r) in rows.iter().enumerate() {
                for o in 0..np {
                    if omega[o] <= 0.0 {
                        continue;
                    }
                    let k = base + o;
                    values[o * np + i] = match channel {
                        Channel::Y => r.y[k] / nf / omega[o],
                        Channel::X => r.x[k] / nf / omega[o],
                        Channel::Z => r.z[k] / nf / omega[o],
                        Channel::YError if n > 1 => {
                            let mean = r.y[k] / nf;
                            let var = ((r.y_sq[k] / nf - mean * mean) * nf / (nf - 1.0)).max(0.0);
                            (var / nf).sqrt() / omega[o]
                        }
                        Channel::YError => 0.0,
                    };
                }
            }
            KlemsMatrix {
                incident: basis.clone(),
                outgoing: basis.clone(),
                values,
            }
        };
        for (dir, far_side) in [(tdir, true), (rdir, false)] {
            use fenestra_bsdf::Wavelength;
            let block = |wavelength: Wavelength, channel: Channel| Block {
                wavelength,
                direction: dir,
                data_type: "BTDF".into(),
                data: BlockData::Klems(matrix(far_side, channel)),
            };
            // wrapBSDF's order: Visible, CIE-X, CIE-Z for each direction
            blocks.push(block(Wavelength::Visible, Channel::Y));
            if opts.colour {
                blocks.push(block(Wavelength::CieX, Channel::X));
                blocks.push(block(Wavelength::CieZ, Channel::Z));
            }
            if opts.errors {
                error_blocks.push(block(Wavelength::Visible, Channel::YError));
            }
        }
    }
    let file = |name: &str, blocks: Vec<Block>| Bsdf {
        name: name.into(),
        width: Some(w),
        height: Some(h),
        thickness: Some(-z0),
        structure: Some(DataStructure::Columns),
        bases: vec![basis.clone()],
        blocks,
        ..Default::default()
    };
    let errors = opts
        .errors
        .then(|| file("Standard errors", std::mem::take(&mut error_blocks)));
    let bsdf = file("Unnamed", blocks);
    if let Some(c) = ckpt {
        c.finish()?;
    }
    Ok(Characterised {
        dim,
        samples: n,
        warnings,
        bsdf,
        errors,
        rays: tracer.ray_counts(),
        effects: tracer.effects().notes.clone(),
    })
}

#[cfg(test)]
mod tests {
    #[test]
    fn grid_as_genbsdf() {
        assert_eq!(super::grid(2000, 1.0, 1.0), (45, 45));
        assert_eq!(super::grid(1000, 0.3, 0.28856), (33, 31));
    }
}
