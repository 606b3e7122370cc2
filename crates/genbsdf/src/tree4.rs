//! genBSDF's tensor trees: anisotropic (`-t4 L`: incident directions in the cells of a
//! 2^L × 2^L Shirley–Chiu square over each hemisphere) and isotropic (`-t3 L`: incident
//! directions in one plane, 2^(L−1) cells from grazing to normal), what leaves binned into
//! the 2^L × 2^L grid on either side, reduced as rttree_reduce does (culling percentile `-t`,
//! reciprocity averaging with `+a`: the reflection of a rank-4 tree, every rank-3 tree). Frames as Radiance's genBSDF sets them through
//! rfluxmtx (sender and receivers `h=∓scN u=-Y`): a cell (x, y) of the square maps through
//! the concentric map to the disk point (dx, dy), and the direction of travel is
//! (dx, dy, ±√(1 − dx² − dy²)), both for the incident rays and for the outgoing ones.

use anyhow::{bail, Result};
use fenestra_bsdf::tree::{disk_to_square, square_to_disk, TensorTree};
use fenestra_bsdf::{Block, BlockData, Bsdf, DataStructure, Wavelength};
use fenestra_scene::Scene;
use fenestra_trace::rng::Rng;
use fenestra_trace::DVec3;
use rayon::prelude::*;

use crate::reduce::{reciprocity, reduce, Grid};
use crate::reduce_stream::{Rows, StreamReduce};
use crate::{
    add_squares, direction_seeds, grid, sample_seed, sample_start, setup, sides, Characterised,
    Options, Setup,
};

/// The grid cell of a unit direction of travel (its x and y on the disk).
fn cell_of(d: DVec3, n: usize) -> usize {
    let (sx, sy) = disk_to_square(d.x, d.y);
    let c = |s: f64| ((s * n as f64).floor().max(0.0) as usize).min(n - 1);
    c(sx) * n + c(sy)
}

/// One incident cell's sums: transmission and reflection (Y, then X and Z with `+C`, per
/// outgoing cell) and with `-E` the per-sample squares (transmission then reflection).
type CellSums = (Vec<f64>, Vec<f64>, Vec<f64>);

/// log2 of the side of the blocks of incident cells a streamed reduction traces at once
/// (64 cells: a few tens of megabytes at L = 7).
const STREAM_BATCH_LOG2: u32 = 3;

/// Rank-4 trees from this resolution up are reduced without the whole grid in memory
/// (`reduce_stream`: every incident cell traced twice).
pub const STREAM_FROM_LOG2: u32 = 7;

/// Whether a run streams its reduction (and so traces every incident cell twice).
pub fn streams(rank: usize, log2: u32) -> bool {
    rank == 4 && log2 >= STREAM_FROM_LOG2
}

/// What a grid holds.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Kind {
    /// Y / (π/N²): the BSDF.
    Y,
    /// genBSDF's CIE u′ of each cell (4/19 where nothing arrives).
    U,
    /// CIE v′ (9/19 where nothing arrives).
    V,
    /// The standard error of the Y value (`-E`).
    Error,
}

/// One grid of a side: its block's direction, component and culling percentile.
struct Spec {
    dir: fenestra_bsdf::Direction,
    is_trans: bool,
    kind: Kind,
    pct: f64,
}

/// Turns an incident cell's sums into one grid row.
struct Convert {
    ncell: usize,
    ns: usize,
    omega: f64,
}

impl Convert {
    fn row(&self, r: &CellSums, sp: &Spec) -> Vec<f32> {
        let ncell = self.ncell;
        let sums = if sp.is_trans { &r.0 } else { &r.1 };
        let nf = self.ns as f64;
        match sp.kind {
            Kind::Y => {
                let scale = 1.0 / nf / self.omega;
                sums[..ncell].iter().map(|v| (v * scale) as f32).collect()
            }
            Kind::U | Kind::V => (0..ncell)
                .map(|o| {
                    let (x, y, z) = (sums[ncell + o], sums[o], sums[2 * ncell + o]);
                    let den = x + 15.0 * y + 3.0 * z;
                    (match (y != 0.0, sp.kind == Kind::U) {
                        (true, true) => 4.0 * x / den,
                        (true, false) => 9.0 * y / den,
                        (false, true) => 4.0 / 19.0,
                        (false, false) => 9.0 / 19.0,
                    }) as f32
                })
                .collect(),
            Kind::Error => {
                // from the spread of the samples' totals
                let base = if sp.is_trans { 0 } else { ncell };
                sums[..ncell]
                    .iter()
                    .zip(&r.2[base..base + ncell])
                    .map(|(s, q)| {
                        let se = if self.ns > 1 {
                            let var = ((q - s * s / nf) / (nf - 1.0)).max(0.0);
                            (var / nf).sqrt() / self.omega
                        } else {
                            0.0
                        };
                        se as f32
                    })
                    .collect()
            }
        }
    }
}

/// Characterises the device as tensor trees of rank `rank` (3 or 4) and resolution 2^`log2`.
#[allow(clippy::too_many_arguments)] // genBSDF's tree settings, each a command-line option
pub fn characterise(
    scene: &Scene,
    opts: &Options,
    rank: usize,
    log2: u32,
    pctcull: f64,
    recip: bool,
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
    // channels gathered per outgoing cell: Y, and with +C also X and Z
    let nch = if opts.colour { 3 } else { 1 };
    let n = 1usize << log2;
    let ncell = n * n;
    // incident cells: the square's (rank 4), or the plane's from grazing to normal (rank 3)
    let nin = if rank == 4 { ncell } else { n / 2 };
    let (nx, ny) = grid(opts.samples.max(1), w, h);
    let ns = nx * ny;
    let omega = std::f64::consts::PI / ncell as f64;
    let stream = rank == 4 && (streams(rank, log2) || opts.stream_trees);
    if stream && recip {
        bail!("+a: reciprocity averaging pairs cells across the whole grid, which -t4 {log2} does not hold in memory (use -a)");
    }
    if stream && opts.checkpoint.is_some() {
        bail!("-checkpoint: not available with -t4 {log2} (its reduction traces every incident cell twice)");
    }
    let ckpt = match &opts.checkpoint {
        Some(path) => {
            let parts = format!(
                "tree {rank} {log2} {nx} {ny} {} {} {} {} {dim:?} {:?} {:?}",
                opts.forward, opts.backward, opts.errors, opts.colour, opts.trace, scene.prims
            );
            let c = crate::checkpoint::Checkpoint::open(path, &crate::checkpoint::key(&parts))?;
            if c.len() > 0 {
                warnings.push(format!(
                    "resuming from '{}': {} of {} incident directions already done",
                    path.display(),
                    c.len(),
                    nin * sides(opts).len()
                ));
            }
            Some(c)
        }
        None => None,
    };
    let fail: std::sync::Mutex<Option<anyhow::Error>> = std::sync::Mutex::new(None);
    let seed = sample_seed(0x7472_6565_3400, opts);
    let mut blocks = Vec::new();
    let mut error_blocks = Vec::new();
    for (side_k, &(from_room, tdir, rdir)) in sides(opts).iter().enumerate() {
        let z = if from_room { z1 + 1e-6 } else { z0 - 1e-6 };
        // one incident cell: Y (then X, Z) flux toward the far side (transmission) and back
        // (reflection), channel-major, and with -E each outgoing cell's sum of squared
        // per-sample Y totals (transmission then reflection, 2 × ncell)
        let trace_cell = |cell: usize| -> CellSums {
            let (ix, iy) = (cell / n, cell % n);
            let mut trans = vec![0.0; nch * ncell];
            let mut refl = vec![0.0; nch * ncell];
            let mut sq = vec![0.0; if opts.errors { 2 * ncell } else { 0 }];
            let mut hits: Vec<(usize, f64)> = Vec::new();
            let key = (side_k * nin + cell) as u64;
            let seeds = direction_seeds(seed, key);
            for k in 0..ns {
                hits.clear();
                let index = key * ns as u64 + k as u64;
                let mut rng = Rng::for_ray(seed, index);
                let (px, py, s1, s2) = sample_start(seeds, k, &mut rng, (x0, y0, w, h));
                let (dx, dy) = if rank == 4 {
                    square_to_disk((ix as f64 + s1) / n as f64, (iy as f64 + s2) / n as f64)
                } else {
                    // genBSDF's isotropic rays: sinθ uniform within the cell, the
                    // azimuth at 0 give or take a sliver alternating with the cell
                    let dx = 1.0 - 2.0 * (cell as f64 + s1) / n as f64;
                    let side = if cell % 2 == 1 { -1.0 } else { 1.0 };
                    let dy = (1.0 / n as f64).min((1.0 - dx * dx).max(0.0).sqrt()) * side * s2;
                    (dx, dy)
                };
                let dz = (1.0 - dx * dx - dy * dy).max(0.0).sqrt();
                let dir = DVec3::new(dx, dy, if from_room { -dz } else { dz });
                let org = DVec3::new(px, py, z);
                tracer.contributions(index, org, dir, &tracked, &mut |c| {
                    if c.negligible_coef() {
                        return;
                    }
                    let dot =
                        |w: [f64; 3]| -> f64 { c.coef.iter().zip(w).map(|(a, w)| a * w).sum() };
                    let d = c.dir;
                    let o = cell_of(d, n);
                    // transmission: on past the device (toward the room for light
                    // from outside, away from it for light from the room)
                    let is_t = (d.z > 0.0) != from_room;
                    let to = if is_t { &mut trans } else { &mut refl };
                    let y = dot(y_w);
                    to[o] += y;
                    if opts.errors {
                        hits.push((if is_t { o } else { ncell + o }, y));
                    }
                    if nch == 3 {
                        to[ncell + o] += dot(x_w);
                        to[2 * ncell + o] += dot(z_w);
                    }
                });
                if opts.errors {
                    add_squares(&mut hits, &mut sq);
                }
            }
            (trans, refl, sq)
        };
        // the grids written for this side, in the file's block order
        let mut specs = Vec::new();
        for (dir, is_trans) in [(tdir, true), (rdir, false)] {
            if opts.errors {
                specs.push(Spec {
                    dir,
                    is_trans,
                    kind: Kind::Error,
                    pct: pctcull,
                });
            }
            specs.push(Spec {
                dir,
                is_trans,
                kind: Kind::Y,
                pct: pctcull,
            });
            if opts.colour {
                let pct_uv = 100.0 - (100.0 - pctcull) * 0.25;
                specs.push(Spec {
                    dir,
                    is_trans,
                    kind: Kind::U,
                    pct: pct_uv,
                });
                specs.push(Spec {
                    dir,
                    is_trans,
                    kind: Kind::V,
                    pct: pct_uv,
                });
            }
        }
        let conv = Convert { ncell, ns, omega };
        let texts: Vec<String> = if stream {
            // a block of incident cells at a time, traced again in the second pass
            let rows = |x0: usize, y0: usize, side: usize| -> Result<Rows> {
                let cells: Vec<usize> = (x0..x0 + side)
                    .flat_map(|ix| (y0..y0 + side).map(move |iy| ix * n + iy))
                    .collect();
                Ok(pool.install(|| {
                    cells
                        .par_iter()
                        .map(|&cell| {
                            let r = trace_cell(cell);
                            done();
                            specs.iter().map(|sp| conv.row(&r, sp)).collect()
                        })
                        .collect()
                }))
            };
            let pcts: Vec<f64> = specs.iter().map(|sp| sp.pct).collect();
            let reducer = StreamReduce::new(log2, STREAM_BATCH_LOG2, specs.len(), &rows);
            pool.install(|| reducer.reduce(&pcts))?
        } else {
            let rows: Vec<CellSums> = pool.install(|| {
                (0..nin)
                    .into_par_iter()
                    .map(|cell| {
                        if let Some([t, r, q, _]) = ckpt.as_ref().and_then(|c| c.get(side_k, cell))
                        {
                            done();
                            return (t.clone(), r.clone(), q.clone());
                        }
                        let (trans, refl, sq) = trace_cell(cell);
                        done();
                        if let Some(c) = &ckpt {
                            let all = [trans.clone(), refl.clone(), sq.clone(), Vec::new()];
                            if let Err(e) = c.put(side_k, cell, &all) {
                                fail.lock()
                                    .unwrap_or_else(|e| e.into_inner())
                                    .get_or_insert(e);
                            }
                        }
                        (trans, refl, sq)
                    })
                    .collect()
            });
            if let Some(e) = fail.lock().unwrap_or_else(|e| e.into_inner()).take() {
                return Err(e);
            }
            specs
                .iter()
                .map(|sp| {
                    let mut data: Vec<f32> = Vec::with_capacity(n.pow(rank as u32));
                    for r in &rows {
                        data.extend(conv.row(r, sp));
                    }
                    // a rank-3 grid's upper half of incident cells stays empty (as
                    // rttree_reduce fills it with zeros)
                    data.resize(n.pow(rank as u32), 0.0);
                    // the errors are before reciprocity averaging (with +a an upper bound)
                    if recip && sp.kind != Kind::Error && (rank == 3 || !sp.is_trans) {
                        reciprocity(rank, log2, &mut data);
                    }
                    reduce(
                        &Grid {
                            rank,
                            log2,
                            data: &data,
                        },
                        sp.pct,
                    )
                })
                .collect()
        };
        for (sp, text) in specs.iter().zip(texts) {
            let tree = TensorTree::parse(rank, &text)
                .map_err(|e| anyhow::anyhow!("internal: reduced tree does not parse: {e:?}"))?;
            let block = Block {
                wavelength: match sp.kind {
                    Kind::Y | Kind::Error => Wavelength::Visible,
                    Kind::U => Wavelength::CieU,
                    Kind::V => Wavelength::CieV,
                },
                direction: sp.dir,
                data_type: "BTDF".into(),
                data: BlockData::Tree(tree),
            };
            if sp.kind == Kind::Error {
                error_blocks.push(block);
            } else {
                blocks.push(block);
            }
        }
    }
    let file = |name: &str, blocks: Vec<Block>| Bsdf {
        name: name.into(),
        width: Some(w),
        height: Some(h),
        thickness: Some(-z0),
        structure: Some(if rank == 4 {
            DataStructure::TensorTree4
        } else {
            DataStructure::TensorTree3
        }),
        blocks,
        ..Default::default()
    };
    let bsdf = file("Unnamed", blocks);
    let errors = opts.errors.then(|| file("Standard errors", error_blocks));
    if let Some(c) = ckpt {
        c.finish()?;
    }
    Ok(Characterised {
        dim,
        samples: ns,
        warnings,
        bsdf,
        errors,
        rays: tracer.ray_counts(),
        effects: tracer.effects().notes.clone(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn concentric_map_round_trips() {
        // the bsdf crate's pair (Radiance's scaling), which the tree reader uses too
        for i in 0..50 {
            for j in 0..50 {
                let (sx, sy) = ((i as f64 + 0.5) / 50.0, (j as f64 + 0.5) / 50.0);
                let (x, y) = square_to_disk(sx, sy);
                let (a, b) = disk_to_square(x, y);
                assert!(
                    (a - sx).abs() < 1e-9 && (b - sy).abs() < 1e-9,
                    "{sx} {sy} -> {a} {b}"
                );
            }
        }
    }
}
