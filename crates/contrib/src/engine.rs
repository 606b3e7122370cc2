//! Tracing input rays, binning what reaches tracked modifiers, accumulating records
//! (`-c N` averages, `-c 0` sums) and the Monte Carlo standard error of every value.

use std::collections::BTreeSet;
use std::io::BufRead;
use std::sync::Mutex;

use anyhow::{anyhow, Result};
use fenestra_calc::State;
use fenestra_trace::{Contribution, DVec3, Tracer};
use rayon::prelude::*;

use crate::bins::Bins;

/// Input data format (`-fi`).
pub use fenestra_cli::rays::RayFormat as InFormat;

/// One input ray: origin and direction (with `-I`: point and surface normal).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InputRay {
    /// Origin (point).
    pub org: DVec3,
    /// Direction (normal); zero marks a dummy ray.
    pub dir: DVec3,
}

/// Reads input rays one at a time: a ray with a value that is not finite becomes a dummy
/// ray (zero direction, no contribution) and is counted for a warning.
pub struct RayInput<R: BufRead> {
    reader: fenestra_cli::rays::RayReader<R>,
    /// Rays replaced by dummies because a value was not finite.
    pub bad: u64,
}

impl<R: BufRead> RayInput<R> {
    /// Reads rays of format `fmt` from `rd`.
    pub fn new(rd: R, fmt: InFormat) -> Self {
        RayInput {
            reader: fenestra_cli::rays::RayReader::new(rd, fmt),
            bad: 0,
        }
    }

    /// The next ray (`None` at the end of input or where a word is not a number).
    pub fn next_ray(&mut self) -> Result<Option<InputRay>> {
        let Some(r) = self.reader.next_ray()? else {
            return Ok(None);
        };
        if !fenestra_cli::rays::finite(&r) {
            self.bad += 1;
            return Ok(Some(InputRay {
                org: DVec3::ZERO,
                dir: DVec3::ZERO,
            }));
        }
        Ok(Some(InputRay {
            org: DVec3::from(r.0),
            dir: DVec3::from(r.1),
        }))
    }

    /// Reads up to `limit` rays (all when `None`).
    pub fn read_all(&mut self, limit: Option<usize>) -> Result<Vec<InputRay>> {
        let mut rays = Vec::new();
        while limit.is_none_or(|l| rays.len() < l) {
            match self.next_ray()? {
                Some(r) => rays.push(r),
                None => break,
            }
        }
        Ok(rays)
    }

    /// Warnings about the input (where it stopped, rays that were not finite), once.
    pub fn take_warnings(&mut self) -> Vec<String> {
        let mut w: Vec<String> = self.reader.take_warning().into_iter().collect();
        if self.bad > 0 {
            w.push(format!(
                "{} input ray(s) with a value that is not finite (nan, inf) taken as dummy rays",
                self.bad
            ));
            self.bad = 0;
        }
        w
    }
}

/// A tracked modifier as the engine sees it.
#[derive(Debug, Clone)]
pub struct Tracked {
    /// Scene indices of the primitives carrying this modifier's name.
    pub scene_mods: Vec<usize>,
    /// Number of bins.
    pub nbins: usize,
}

/// Settings of a run.
#[derive(Debug, Clone)]
pub struct RunOptions {
    /// `-I`: the input direction is a surface normal (irradiance).
    pub irradiance: bool,
    /// `-i`: irradiance at the first surface along each ray that is not passed
    /// ([`Tracer::irradiance_at_hit`]).
    pub irradiance_at_hit: bool,
    /// `-V`: contributions (coefficient × radiance) instead of coefficients.
    pub value: bool,
    /// `-c`: rays per record (0: one summed record).
    pub count: usize,
    /// Compute standard errors.
    pub errors: bool,
    /// With `-c 1` and errors: independent batches per ray (the value is their mean).
    pub batches: usize,
    /// Replicas per record (`-Er K`, needs errors; 0: none): the rays of a record in K
    /// interleaved groups (ray j in group j mod K; with `-c 1`, K batches), each group's
    /// estimate written as a row, so that a later product can measure its own variance.
    pub replicas: usize,
    /// `-ld+`: rays end at the length of their direction vector (transmitted rays carry
    /// the rest on).
    pub limit_dist: bool,
}

/// One output record: values and (when asked) standard errors, `3 × total bins` each.
#[derive(Debug, Clone)]
pub struct Record {
    /// Summed values, RGB per bin, modifiers in order (the value is `sums × scale`).
    pub sums: Vec<f64>,
    /// 1/N for an average of N rays, 1 for a sum.
    pub scale: f64,
    /// Standard errors of the values (`sums × scale`), with `-E`.
    pub errors: Option<Vec<f64>>,
    /// With `-Er K`: K replica estimates, `3 × total bins` each, one after the other;
    /// their mean is the value.
    pub replicas: Option<Vec<f64>>,
    /// With `-E`: per modifier, the standard error of the record's total over its bins in
    /// luminance units ([`Y`] weights; from the rays' own totals, so every covariance
    /// between bins is included).
    pub total_se: Option<Vec<f64>>,
}

/// Radiance's luminance weights of R, G, B (the `-v` budget's totals).
pub const Y: [f64; 3] = [0.265, 0.670, 0.065];

/// The contribution tracer.
pub struct Engine<'a> {
    tracer: &'a Tracer,
    bins: &'a Bins,
    tracked: Vec<bool>,
    our_mod: Vec<u32>,
    offsets: Vec<usize>,
    nbins: Vec<usize>,
    /// Modifier of every bin slot (modifiers in order).
    slot_mod: Vec<u32>,
    total: usize,
    opts: RunOptions,
    bad: Mutex<BTreeSet<(usize, i64)>>,
    fail: Mutex<Option<String>>,
}

#[derive(Default)]
struct Acc {
    sum: Vec<f64>,
    sumsq: Vec<f64>,
    /// Per-replica sums (`replicas × 3 × total bins`), with `-Er`.
    rep: Vec<f64>,
    /// Per modifier: sums of the rays' luminance totals and of their squares, with errors.
    tot: Vec<f64>,
    totsq: Vec<f64>,
    n: usize,
}

/// Per-thread working state: bin evaluation states, bad bins met (merged into the
/// engine's set once per record), and the one-ray values of error mode.
struct Scratch {
    states: Vec<State>,
    bad: BTreeSet<(usize, i64)>,
    tmp: Vec<f64>,
    touched: Vec<usize>,
}

impl<'a> Engine<'a> {
    /// Sets up tracking for `mods` (in command-line order) in a scene of `nprims` primitives.
    pub fn new(
        tracer: &'a Tracer,
        bins: &'a Bins,
        nprims: usize,
        mods: &[Tracked],
        opts: RunOptions,
    ) -> Engine<'a> {
        let mut tracked = vec![false; nprims];
        let mut our_mod = vec![u32::MAX; nprims];
        let mut offsets = Vec::new();
        let mut total = 0;
        for (k, m) in mods.iter().enumerate() {
            for &s in &m.scene_mods {
                tracked[s] = true;
                our_mod[s] = k as u32;
            }
            offsets.push(total);
            total += m.nbins;
        }
        Engine {
            tracer,
            bins,
            tracked,
            our_mod,
            offsets,
            nbins: mods.iter().map(|m| m.nbins).collect(),
            slot_mod: mods
                .iter()
                .enumerate()
                .flat_map(|(k, m)| std::iter::repeat_n(k as u32, m.nbins))
                .collect(),
            total,
            opts,
            bad: Mutex::new(BTreeSet::new()),
            fail: Mutex::new(None),
        }
    }

    /// Index of modifier `m`, bin `b` in a record's values (times 3 for RGB).
    pub fn slot(&self, m: usize, b: usize) -> usize {
        self.offsets[m] + b
    }

    /// Per modifier: the total of a record's values over its bins, in luminance units.
    pub fn modifier_totals(&self, rec: &Record) -> Vec<f64> {
        let mut t = vec![0.0; self.nbins.len()];
        for (k, &m) in self.slot_mod.iter().enumerate() {
            let v = &rec.sums[k * 3..k * 3 + 3];
            t[m as usize] += (Y[0] * v[0] + Y[1] * v[1] + Y[2] * v[2]) * rec.scale;
        }
        t
    }

    /// Bad bin numbers met so far (modifier, bin), for the warning; taken.
    pub fn take_bad_bins(&self) -> Vec<(usize, i64)> {
        let mut b = self.bad.lock().unwrap_or_else(|e| e.into_inner());
        std::mem::take(&mut *b).into_iter().collect()
    }

    /// Traces one input ray, adding its contributions into `acc`; with `touched`, the
    /// index of every RGB slot that was zero before is pushed (for the error sums).
    fn scratch(&self) -> Scratch {
        Scratch {
            states: self.bins.states(),
            bad: BTreeSet::new(),
            tmp: Vec::new(),
            touched: Vec::new(),
        }
    }

    fn trace_one(
        &self,
        index: u64,
        ray: &InputRay,
        acc: &mut [f64],
        mut touched: Option<&mut Vec<usize>>,
        scratch: &mut Scratch,
    ) {
        if ray.dir == DVec3::ZERO {
            return;
        }
        let Scratch { states, bad, .. } = scratch;
        let mut sink = |c: Contribution| {
            let m = self.our_mod[c.modifier];
            if m == u32::MAX {
                return;
            }
            let m = m as usize;
            // Radiance 6 leaves out a contribution at most 1e-6 in every channel: the
            // coefficient, or with -V the value (a sun on a dark surface keeps its value)
            let v = if self.opts.value { c.value } else { c.coef };
            if v.iter().all(|&x| x <= 1e-6) {
                return;
            }
            let b = if self.bins.varies(m) {
                match self.bins.eval_for(m, &c, states) {
                    Ok(bv) => {
                        if bv <= -0.5 || bv.is_nan() {
                            return;
                        }
                        let bn = (bv + 0.5) as i64;
                        if bn as usize >= self.nbins[m] {
                            bad.insert((m, bn));
                            return;
                        }
                        bn as usize
                    }
                    Err(e) => {
                        self.set_fail(format!("bin expression: {e}"));
                        return;
                    }
                }
            } else {
                0
            };
            let s = (self.offsets[m] + b) * 3;
            if let Some(t) = touched.as_deref_mut() {
                if acc[s] == 0.0 && acc[s + 1] == 0.0 && acc[s + 2] == 0.0 {
                    t.push(s);
                }
            }
            acc[s] += v[0];
            acc[s + 1] += v[1];
            acc[s + 2] += v[2];
        };
        if self.opts.irradiance_at_hit {
            // -ld+: the ray ends at the length of its direction vector (surfaces passed on
            // the way do not reset it)
            let len = if self.opts.limit_dist {
                ray.dir.length()
            } else {
                f64::INFINITY
            };
            self.tracer.contributions_irradiance_at_hit(
                index,
                ray.org,
                ray.dir,
                len,
                &self.tracked,
                &mut sink,
            );
        } else if self.opts.irradiance {
            // Radiance's rcontrib -I point: 1e-4 along the normal
            let n = ray.dir.normalize_or_zero();
            let q = Tracer::rcontrib_irradiance_point(ray.org, n);
            self.tracer
                .contributions_irradiance(index, q, n, &self.tracked, &mut sink);
        } else {
            // -ld+: the ray ends at the length of its direction vector
            let len = if self.opts.limit_dist {
                ray.dir.length()
            } else {
                f64::INFINITY
            };
            self.tracer.contributions_limited(
                index,
                ray.org,
                ray.dir,
                len,
                &self.tracked,
                &mut sink,
            );
        }
    }

    fn accumulate(
        &self,
        rays: impl Iterator<Item = (u64, InputRay)>,
        scratch: &mut Scratch,
    ) -> Acc {
        let n3 = self.total * 3;
        let mut a = Acc {
            sum: vec![0.0; n3],
            ..Default::default()
        };
        if self.opts.errors {
            a.sumsq = vec![0.0; n3];
            if scratch.tmp.len() != n3 {
                scratch.tmp = vec![0.0; n3];
            }
            a.rep = vec![0.0; n3 * self.opts.replicas];
            a.tot = vec![0.0; self.nbins.len()];
            a.totsq = vec![0.0; self.nbins.len()];
        }
        let mut ray_tot = vec![
            0.0;
            if self.opts.errors {
                self.nbins.len()
            } else {
                0
            }
        ];
        let nrep = self.opts.replicas;
        for (j, (idx, r)) in rays.enumerate() {
            a.n += 1;
            if self.opts.errors {
                // only the slots this ray reached are added (adding zeros would not
                // change the sums) and reset
                let mut tmp = std::mem::take(&mut scratch.tmp);
                let mut touched = std::mem::take(&mut scratch.touched);
                touched.clear();
                self.trace_one(idx, &r, &mut tmp, Some(&mut touched), scratch);
                if nrep > 0 {
                    let rep = &mut a.rep[(j % nrep) * n3..][..n3];
                    for &s in &touched {
                        for c in s..s + 3 {
                            rep[c] += tmp[c];
                        }
                    }
                }
                for &s in &touched {
                    let y = Y[0] * tmp[s] + Y[1] * tmp[s + 1] + Y[2] * tmp[s + 2];
                    ray_tot[self.slot_mod[s / 3] as usize] += y;
                }
                for (m, t) in ray_tot.iter_mut().enumerate() {
                    a.tot[m] += *t;
                    a.totsq[m] += *t * *t;
                    *t = 0.0;
                }
                for &s in &touched {
                    let sums = a.sum[s..s + 3].iter_mut().zip(&mut a.sumsq[s..s + 3]);
                    for ((sum, sq), t) in sums.zip(&mut tmp[s..s + 3]) {
                        *sum += *t;
                        *sq += *t * *t;
                        *t = 0.0;
                    }
                }
                scratch.tmp = tmp;
                scratch.touched = touched;
            } else {
                self.trace_one(idx, &r, &mut a.sum, None, scratch);
            }
        }
        if !scratch.bad.is_empty() {
            let mut b = self.bad.lock().unwrap_or_else(|e| e.into_inner());
            b.append(&mut scratch.bad);
        }
        a
    }

    fn finish(&self, a: Acc, sum_only: bool) -> Record {
        let n = a.n.max(1) as f64;
        let se = |s: f64, q: f64| {
            if a.n < 2 {
                return 0.0;
            }
            let var = ((q - s * s / n) / (n - 1.0)).max(0.0);
            if sum_only {
                (n * var).sqrt()
            } else {
                (var / n).sqrt()
            }
        };
        let errors = self.opts.errors.then(|| {
            a.sum
                .iter()
                .zip(&a.sumsq)
                .map(|(s, q)| se(*s, *q))
                .collect()
        });
        let total_se = self.opts.errors.then(|| {
            a.tot
                .iter()
                .zip(&a.totsq)
                .map(|(s, q)| se(*s, *q))
                .collect()
        });
        // replica k's estimate is K/n times its group's sum, so that their mean is the value
        let replicas = (self.opts.replicas > 0 && !sum_only).then(|| {
            let f = self.opts.replicas as f64 / n;
            a.rep.iter().map(|v| v * f).collect()
        });
        Record {
            sums: a.sum,
            scale: if sum_only { 1.0 } else { 1.0 / n },
            errors,
            replicas,
            total_se,
        }
    }

    /// Keeps the first error met while tracing (reported when the block ends).
    fn set_fail(&self, msg: String) {
        let mut f = self.fail.lock().unwrap_or_else(|e| e.into_inner());
        if f.is_none() {
            *f = Some(msg);
        }
    }

    fn check_fail(&self) -> Result<()> {
        if let Some(e) = self.fail.lock().unwrap_or_else(|e| e.into_inner()).take() {
            return Err(anyhow!("{e}"));
        }
        Ok(())
    }

    /// Computes records `first..first+n` (`-c N ≥ 1`), in parallel, in order; `rays[0]`
    /// is input ray number `base` (records are numbered over the whole input, so a
    /// stream traced in batches gets the same records as one pass).
    pub fn records(
        &self,
        rays: &[InputRay],
        base: usize,
        first: usize,
        n: usize,
        pool: &rayon::ThreadPool,
    ) -> Result<Vec<Record>> {
        let c = self.opts.count.max(1);
        let batches = if self.opts.errors && c == 1 {
            if self.opts.replicas > 0 {
                self.opts.replicas
            } else {
                self.opts.batches.max(2)
            }
        } else {
            1
        };
        let out: Vec<Record> = pool.install(|| {
            (first..first + n)
                .into_par_iter()
                .map_init(
                    || self.scratch(),
                    |scratch, r| {
                        let acc = if batches > 1 {
                            let ray = rays[r - base];
                            self.accumulate(
                                (0..batches).map(|j| ((r * batches + j) as u64, ray)),
                                scratch,
                            )
                        } else {
                            let lo = r * c;
                            let hi = (lo + c).min(base + rays.len());
                            self.accumulate((lo..hi).map(|k| (k as u64, rays[k - base])), scratch)
                        };
                        self.finish(acc, false)
                    },
                )
                .collect()
        });
        self.check_fail()?;
        Ok(out)
    }

    /// Computes the single summed record of `-c 0` (dummy rays skipped): fixed chunks
    /// summed in parallel, then added in order (the same result for any thread count).
    pub fn sum_all(
        &self,
        rays: &[InputRay],
        pool: &rayon::ThreadPool,
        progress: &dyn Fn(u64),
    ) -> Result<Record> {
        const CHUNK: usize = 256;
        let idx: Vec<usize> = (0..rays.len())
            .filter(|&k| rays[k].dir != DVec3::ZERO)
            .collect();
        let n3 = self.total * 3;
        let mut total = Acc {
            sum: vec![0.0; n3],
            sumsq: if self.opts.errors {
                vec![0.0; n3]
            } else {
                Vec::new()
            },
            tot: vec![
                0.0;
                if self.opts.errors {
                    self.nbins.len()
                } else {
                    0
                }
            ],
            totsq: vec![
                0.0;
                if self.opts.errors {
                    self.nbins.len()
                } else {
                    0
                }
            ],
            ..Default::default()
        };
        for block in idx.chunks(CHUNK * 64) {
            let parts: Vec<Acc> = pool.install(|| {
                block
                    .par_chunks(CHUNK)
                    .map_init(
                        || self.scratch(),
                        |scratch, ch| {
                            self.accumulate(ch.iter().map(|&k| (k as u64, rays[k])), scratch)
                        },
                    )
                    .collect()
            });
            for p in parts {
                total.n += p.n;
                for (t, s) in total.sum.iter_mut().zip(&p.sum) {
                    *t += s;
                }
                for (t, s) in total.sumsq.iter_mut().zip(&p.sumsq) {
                    *t += s;
                }
                for (t, s) in total.tot.iter_mut().zip(&p.tot) {
                    *t += s;
                }
                for (t, s) in total.totsq.iter_mut().zip(&p.totsq) {
                    *t += s;
                }
            }
            progress(block.len() as u64);
        }
        self.check_fail()?;
        Ok(self.finish(total, true))
    }
}
