//! Deterministic parallel tracing of a stream of records with source thresholding.
//!
//! Thresholding (`-dt > 0`) carries shadow-test statistics over the whole run, as Radiance
//! does. Here it does so deterministically for any thread count. Records are traced in
//! blocks, and one thread traces a block's records in order. Blocks are traced in waves
//! of 1, 1, 2, 4, 8, then [`WAVE_MAX`] blocks. Every block of a wave starts from the
//! statistics of all earlier waves, merged in record order. A block is [`BLOCK_AB0`]
//! records with `-ab 0`: such records are cheap, and the first 32 follow each other
//! exactly. With `-ab > 0` a block is one record: each record traces many rays, and they
//! spread over the threads. Without thresholding, records are independent: they go to the
//! threads in chunks of [`CHUNK`].
//!
//! Records arrive in batches: rtrace reads its input as it traces. A full batch is a whole
//! number of the widest waves, so the waves are those of one pass over all the records
//! whatever the batches; only a batch cut short, where output is flushed, ends a wave early.

use rayon::prelude::*;

use crate::tracer::{DirectState, Tracer};

/// Records per block with `-ab 0` under thresholding.
pub const BLOCK_AB0: usize = 16;
/// The widest wave, in blocks.
pub const WAVE_MAX: usize = 16;
/// Records per parallel chunk without thresholding.
pub const CHUNK: usize = 1024;

/// Blocks in wave `w` (0, 1, …) of a thresholded run: 1, then doubling from 1 up to
/// [`WAVE_MAX`].
pub fn wave_width(w: usize) -> usize {
    if w == 0 {
        1
    } else {
        (1usize << (w - 1).min(16)).min(WAVE_MAX)
    }
}

/// The wave schedule of one run: it holds the merged statistics and the wave count from
/// batch to batch.
pub struct Waves {
    thresholding: bool,
    block: usize,
    wave: usize,
    base: DirectState,
    done: usize,
}

impl Waves {
    /// The schedule for `tracer` with `ab` ambient bounces.
    pub fn new(tracer: &Tracer, ab: u32) -> Self {
        let thresholding = tracer.thresholding();
        Waves {
            thresholding,
            block: if thresholding && ab == 0 {
                BLOCK_AB0
            } else {
                1
            },
            wave: 0,
            base: tracer.direct_state(),
            done: 0,
        }
    }

    /// Whether source thresholding carries statistics over the run.
    pub fn thresholding(&self) -> bool {
        self.thresholding
    }

    /// Records per block.
    pub fn block(&self) -> usize {
        self.block
    }

    /// The largest batch worth gathering before tracing (a whole number of waves).
    pub fn batch_max(&self) -> usize {
        if self.thresholding {
            64 * WAVE_MAX * self.block
        } else {
            CHUNK * 8
        }
    }

    /// Traces the next `items.len()` records (numbered on from the previous batches):
    /// `record(k, item, state)` computes record `k`; `emit` receives each wave's records
    /// in order, with the number traced.
    pub fn run<T: Sync, R: Send>(
        &mut self,
        pool: &rayon::ThreadPool,
        items: &[T],
        record: impl Fn(usize, &T, &mut DirectState) -> R + Sync,
        mut emit: impl FnMut(Vec<R>) -> anyhow::Result<()>,
    ) -> anyhow::Result<()> {
        let (n, block, k0) = (items.len(), self.block, self.done);
        let mut start = 0usize;
        while start < n {
            let width = if self.thresholding {
                wave_width(self.wave)
            } else {
                CHUNK
            };
            let end = (start + width * block).min(n);
            let base = &self.base;
            let blocks: Vec<(Vec<R>, DirectState)> = pool.install(|| {
                (start..end)
                    .step_by(block)
                    .collect::<Vec<_>>()
                    .into_par_iter()
                    .map(|b| {
                        let mut st = base.fork();
                        let recs = (b..(b + block).min(end))
                            .map(|k| record(k0 + k, &items[k], &mut st))
                            .collect();
                        (recs, st)
                    })
                    .collect()
            });
            let (vals, states): (Vec<Vec<R>>, Vec<DirectState>) = blocks.into_iter().unzip();
            if self.thresholding {
                // all of a wave at once: the blocks' states are dropped before their
                // changes are applied, so the cache cells they shared are not copied
                self.base.merge(states);
            }
            emit(vals.into_iter().flatten().collect())?;
            start = end;
            self.wave += 1;
        }
        self.done += n;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn waves_grow_to_the_most() {
        let w: Vec<usize> = (0..8).map(super::wave_width).collect();
        assert_eq!(w, [1, 1, 2, 4, 8, 16, 16, 16]);
        assert_eq!(super::wave_width(usize::MAX), super::WAVE_MAX);
    }
}
