//! A tensor tree's transmission as a Klems matrix, the matrix `transmission_matrix` gives for
//! a Klems file (light from outside toward the room side, +Z), so tools that need a matrix
//! (mkillum's `d=` mode) take tree files too. For each outgoing patch, stratified view
//! directions; for each view, the tree's slice (every leaf of the incident distribution,
//! spread as a fine grid of points) binned into the incident patches, so a peaked tree
//! (light passing straight through) keeps its peak in the right patch pair. Rank-4 slices
//! are shared by every view in one finest cell, so each is binned once.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use rayon::prelude::*;

use crate::klems::KlemsBasis;
use crate::radiance::RgbMatrix;
use crate::tree_render::{Lobe, TreeBsdf};

/// Binned slices by their shared identity.
type Binned = Mutex<HashMap<crate::tree_render::SliceKey, Arc<Vec<f64>>>>;

/// The Klems transmission matrix (`basis` × `basis`, grey) of `tree`: 16 × 16 views per
/// patch, leaves spread at 1/256 of the concentric square (converged to 1e-4 on a blind's
/// rank-4 tree); rank-3 slices, binned per view, at 8 × 8 and 1/64.
pub fn tree_transmission_matrix(tree: &TreeBsdf, basis: &KlemsBasis) -> RgbMatrix {
    let shared = tree
        .slice(Lobe::Transmission, true, [0.0, 0.0, 1.0])
        .is_some_and(|s| s.shared_id().is_some());
    if shared {
        transmission_with(tree, basis, 16, 1.0 / 256.0)
    } else {
        transmission_with(tree, basis, 8, 1.0 / 64.0)
    }
}

/// [`tree_transmission_matrix`] with `s` × `s` views per patch and leaves spread at `h`.
pub fn transmission_with(tree: &TreeBsdf, basis: &KlemsBasis, s: usize, h: f64) -> RgbMatrix {
    let n = basis.len();
    let s = s.max(1);
    let lam = basis.lambdas();
    // patch centres (for slices that cannot be binned)
    let centres: Vec<Option<[f64; 3]>> = (0..n)
        .map(|i| basis.sample_projected(i, 0.5, 0.5))
        .collect();
    let lamb = tree.lambertian(Lobe::Transmission, true) / std::f64::consts::PI;
    // a slice's points binned by the patch of the way their light travels (each binned once
    // per shared slice; computed on whichever thread needs it first, the same numbers either way)
    let binned: Binned = Mutex::new(HashMap::new());
    let bin = |slice: &crate::tree_render::Slice| {
        let mut v = vec![0.0; n];
        slice.spread(h, &mut |l, share| {
            // l points back toward the light; it travels along −l into the room
            if let Some(i) = basis.patch([-l[0], -l[1], -l[2]]) {
                v[i] += share;
            }
        });
        v
    };
    let rows: Vec<Vec<f64>> = (0..n)
        .into_par_iter()
        .map(|o| {
            let mut row = vec![0.0f64; n];
            let views: Vec<[f64; 3]> = (0..s * s)
                .filter_map(|j| {
                    let (a, b) = ((j / s) as f64 + 0.5, (j % s) as f64 + 0.5);
                    basis.sample_projected(o, a / s as f64, b / s as f64)
                })
                .collect();
            let w = 1.0 / views.len().max(1) as f64;
            for v in &views {
                match tree.slice(Lobe::Transmission, true, *v) {
                    Some(slice) => {
                        let b: Arc<Vec<f64>> = match slice.shared_id() {
                            Some(id) => {
                                let hit = binned.lock().ok().and_then(|m| m.get(&id).cloned());
                                match hit {
                                    Some(b) => b,
                                    None => {
                                        let b = Arc::new(bin(&slice));
                                        if let Ok(mut m) = binned.lock() {
                                            m.insert(id, b.clone());
                                        }
                                        b
                                    }
                                }
                            }
                            None => Arc::new(bin(&slice)),
                        };
                        row.iter_mut().zip(b.iter()).for_each(|(r, x)| *r += w * x);
                    }
                    None => {
                        // no slice (a rank-3 tree used in reverse): the BSDF at patch centres
                        for (i, x) in row.iter_mut().enumerate() {
                            if let Some(b) = centres[i] {
                                let l = [-b[0], -b[1], -b[2]];
                                *x += w * tree.eval(Lobe::Transmission, true, *v, l).0 * lam[i];
                            }
                        }
                    }
                }
            }
            row
        })
        .collect();
    let mut t = RgbMatrix::zeros(n, n);
    for (o, row) in rows.iter().enumerate() {
        for i in 0..n {
            let x = row[i] + lamb * lam[i];
            t.data[o * n + i] = [x, x, x];
        }
    }
    t
}
