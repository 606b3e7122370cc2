//! A whole contribution run in-process, as rtcontrib drives it: the bin-probing first pass,
//! records written to their output streams (streamed from the input, from rays read
//! beforehand, or the single sum of `-c 0`), and `-r` recovery's skipped records. genBSDF
//! and rfluxmtx call these directly: no rcontrib process, pipes or temporary files.

use std::io::BufRead;

use anyhow::Result;
use fenestra_trace::{DVec3, Tracer};

use crate::bins::Bins;
use crate::engine::{Engine, InputRay, RayInput, Record, RunOptions, Tracked};
use crate::output::{Format, Stream};

/// Where the records of a run go: the value streams and (with `-E`) the streams of their
/// standard errors, in one output format.
pub struct Outputs {
    /// Value streams, in plan order.
    pub values: Vec<Stream>,
    /// Standard-error streams (empty without `-E`).
    pub errors: Vec<Stream>,
    /// Replica streams (empty without `-Er`): K rows per record.
    pub replicas: Vec<Stream>,
    /// Data format of every stream.
    pub format: Format,
    /// What the written records add up to (for `-v`).
    pub budget: crate::budget::Budget,
}

impl Outputs {
    /// Writes one record to every stream.
    pub fn write(&mut self, engine: &Engine, rec: &Record) -> Result<()> {
        self.budget.add(engine, rec);
        for s in self.values.iter_mut() {
            s.write_record(self.format, rec.scale, |m, b| {
                let k = engine.slot(m, b) * 3;
                [rec.sums[k], rec.sums[k + 1], rec.sums[k + 2]]
            })?;
        }
        if let Some(e) = &rec.errors {
            for s in self.errors.iter_mut() {
                s.write_record(self.format, 1.0, |m, b| {
                    let k = engine.slot(m, b) * 3;
                    [e[k], e[k + 1], e[k + 2]]
                })?;
            }
        }
        if let Some(r) = &rec.replicas {
            let n3 = rec.sums.len();
            for s in self.replicas.iter_mut() {
                for rep in r.chunks(n3.max(1)) {
                    s.write_record(self.format, 1.0, |m, b| {
                        let k = engine.slot(m, b) * 3;
                        [rep[k], rep[k + 1], rep[k + 2]]
                    })?;
                }
            }
        }
        Ok(())
    }

    /// Flushes every stream (a record boundary where Radiance flushes).
    pub fn flush(&mut self) -> Result<()> {
        let all = self.values.iter_mut().chain(self.errors.iter_mut());
        for s in all.chain(self.replicas.iter_mut()) {
            s.flush()?;
        }
        Ok(())
    }

    /// Closes every stream (files move into place, commands are waited for).
    pub fn finish(self) -> Result<()> {
        for s in self
            .values
            .into_iter()
            .chain(self.errors)
            .chain(self.replicas)
        {
            s.finish()?;
        }
        Ok(())
    }
}

/// Records per parallel block for `count` rays per record on `nproc` threads.
pub fn block_records(count: usize, nproc: usize) -> usize {
    (8192 / count.max(1)).max(32 * nproc).max(1)
}

/// What the passes of a run share: the tracer, the compiled bins, the scene's primitive
/// count and the worker pool.
pub struct Context<'a> {
    /// The compiled scene.
    pub tracer: &'a Tracer,
    /// The tracked modifiers' bin expressions.
    pub bins: &'a Bins,
    /// Primitives in the scene.
    pub nprims: usize,
    /// Worker threads.
    pub pool: &'a rayon::ThreadPool,
}

/// rtcontrib without `-bn`: a first pass over `rays` finds the bins each tracked modifier
/// reaches and raises the `nbins` of those marked `dynamic` (rays are seeded by index, so
/// the main pass meets the same bins). `opts` are the main pass's options.
pub fn probe_bins(
    cx: &Context,
    tracked: &mut [Tracked],
    dynamic: &[bool],
    rays: &[InputRay],
    opts: &RunOptions,
) -> Result<()> {
    let pool = cx.pool;
    // the same random streams as the main pass: replicas with -E -c 1, ray indices
    // otherwise (-c 0 is probed in records of 256 rays)
    let c = if opts.count == 0 { 256 } else { opts.count };
    let probe_opts = RunOptions {
        count: c,
        ..opts.clone()
    };
    let probe = Engine::new(cx.tracer, cx.bins, cx.nprims, tracked, probe_opts);
    let nrec = rays.len().div_ceil(c);
    let mut r = 0;
    while r < nrec {
        let n = 256.min(nrec - r);
        probe.records(rays, 0, r, n, pool)?;
        r += n;
    }
    for (m, b) in probe.take_bad_bins() {
        if dynamic[m] {
            tracked[m].nbins = tracked[m].nbins.max(b as usize + 1);
        }
    }
    Ok(())
}

/// `-c 0`: the single summed record of `rays` (dummy rays skipped), plus the sums earlier
/// runs wrote (`-r -c 0`: `previous[k]` for value stream k), written to `out`.
pub fn sum_run(
    engine: &Engine,
    rays: &[InputRay],
    previous: &[Option<Vec<[f64; 3]>>],
    pool: &rayon::ThreadPool,
    out: &mut Outputs,
    progress: &dyn Fn(u64),
) -> Result<()> {
    let mut rec = engine.sum_all(rays, pool, progress)?;
    for (s, prev) in out.values.iter().zip(previous) {
        let Some(p) = prev else { continue };
        for (&(m, b), v) in s.plan.items.iter().zip(p) {
            let k = engine.slot(m, b) * 3;
            for (sum, x) in rec.sums[k..k + 3].iter_mut().zip(v) {
                *sum += x / rec.scale;
            }
        }
    }
    out.write(engine, &rec)
}

/// Records of `count` rays each from rays read beforehand, from record `first` on (`-r`
/// skips those already written). Returns whether the last record is partial.
pub fn buffered_run(
    engine: &Engine,
    rays: &[InputRay],
    count: usize,
    first: usize,
    pool: &rayon::ThreadPool,
    out: &mut Outputs,
    progress: &dyn Fn(u64),
) -> Result<bool> {
    let nrec = rays.len().div_ceil(count);
    let block = block_records(count, pool.current_num_threads());
    let mut r = first.min(nrec);
    progress(((r * count).min(rays.len())) as u64);
    while r < nrec {
        let n = block.min(nrec - r);
        for rec in &engine.records(rays, 0, r, n, pool)? {
            out.write(engine, rec)?;
        }
        let lo = r * count;
        let hi = ((r + n) * count).min(rays.len());
        progress((hi - lo) as u64);
        r += n;
    }
    Ok(rays.len() % count != 0)
}

/// How a streamed run reads and flushes.
#[derive(Debug, Clone, Copy)]
pub struct StreamPlan {
    /// Rays per record (`-c`, at least 1).
    pub count: usize,
    /// Flush after this many records (0: only after dummy rays), as Radiance: `-x`
    /// unless `-y` makes a picture with lines of more than one record.
    pub flush_every: usize,
    /// Rays expected (`-x × -y × -c`), if known: reading stops there.
    pub expect: Option<usize>,
    /// Records already written (`-r`): their rays are read and skipped.
    pub skip_records: usize,
}

/// What a streamed run read.
#[derive(Debug, Clone, Copy)]
pub struct StreamEnd {
    /// Rays read (skipped ones included).
    pub rays: usize,
    /// The last record got fewer than `count` rays.
    pub partial: bool,
}

/// Records traced as rays are read from `input`, in batches that end where Radiance
/// flushes (after every `flush_every` records, after a record holding a dummy ray).
pub fn streamed_run<R: BufRead>(
    engine: &Engine,
    input: &mut RayInput<R>,
    plan: StreamPlan,
    pool: &rayon::ThreadPool,
    out: &mut Outputs,
    progress: &dyn Fn(u64),
) -> Result<StreamEnd> {
    let count = plan.count.max(1);
    let block = block_records(count, pool.current_num_threads());
    let skip = plan.skip_records * count;
    let mut base = 0usize;
    while base < skip && input.next_ray()?.is_some() {
        base += 1;
    }
    progress(base as u64);
    let mut schedule = fenestra_cli::rays::FlushSchedule::new(plan.flush_every);
    let mut batch: Vec<InputRay> = Vec::new();
    let mut partial = false;
    loop {
        batch.clear();
        let mut flush = false;
        let mut dummy = false;
        while batch.len() < block * count && plan.expect.is_none_or(|e| base + batch.len() < e) {
            let Some(ray) = input.next_ray()? else {
                break;
            };
            dummy |= ray.dir == DVec3::ZERO;
            batch.push(ray);
            if (base + batch.len()) % count == 0 && schedule.record_done(dummy) {
                flush = true;
                break;
            }
        }
        if batch.is_empty() {
            break;
        }
        partial = (base + batch.len()) % count != 0;
        let n = batch.len().div_ceil(count);
        for rec in &engine.records(&batch, base, base / count, n, pool)? {
            out.write(engine, rec)?;
        }
        if flush {
            out.flush()?;
        }
        progress(batch.len() as u64);
        base += batch.len();
        if partial || plan.expect.is_some_and(|e| base >= e) {
            break;
        }
    }
    Ok(StreamEnd {
        rays: base,
        partial,
    })
}
