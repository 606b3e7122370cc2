//! Standard errors carried from V and D (as `rtcontrib -E` writes them) to every value of
//! `V·T·D·s` (or of `DC·s`), per channel. T and the sky are exact; V and D are independent
//! of each other (separate runs), so their variance terms add. Each matrix's error is known
//! in one of two ways:
//!
//! - **Independent elements** (`-Ev`/`-Ed`: the standard error of every element). With
//!   W = T·D·s and U = V·T,
//!   `var(r[k,t]) = Σ_j σV[k,j]² W[j,t]² + Σ_i U[k,i]² Σ_l σD[i,l]² s[l,t]²`.
//!   Elements of one row are not independent in fact: they are sums over the same rays,
//!   and a ray that lands in one bin is missing from the others, so their covariances are
//!   negative and this variance is an upper bound.
//! - **Replicas** (`-Rv`/`-Rd`: `rtcontrib -E -Er K`'s K independent estimates of every
//!   row, whose mean is the matrix). The product is formed with each replica in turn,
//!   the other factors fixed, and the variance of the mean is estimated from the spread of
//!   those K results: `var(r) = Σ_q (r_q − r̄)² / (K(K−1))`. This carries every covariance
//!   within a row (an unbiased estimate with K−1 degrees of freedom per value).
//!
//! tests/dctimestep_errors.rs measures both against the spread of repeated runs.

use anyhow::{bail, Result};

use crate::timestep::{PackedSky, Planar};

/// What is known of a matrix's Monte Carlo error.
pub enum Uncertainty {
    /// Exact (or not known): no term.
    Exact,
    /// The standard error of every element, taken as independent.
    Independent(Planar),
    /// K ≥ 2 independent replica estimates of the matrix (their mean is the matrix).
    Replicas(Vec<Planar>),
}

impl Uncertainty {
    /// Splits `all`, K replica rows per matrix row (row `r·K + q` is replica q of row r),
    /// into K matrices; `name` is for messages.
    pub fn replicas(all: &Planar, k: usize, name: &str) -> Result<Uncertainty> {
        // (checked before allocating: rtcontrib -Er writes 2 to 4096)
        if !(2..=4096).contains(&k) || all.rows == 0 || all.rows % k != 0 {
            bail!(
                "{name}: {} rows are not a whole number of records of {k} replicas",
                all.rows
            );
        }
        let rows = all.rows / k;
        let mut reps = vec![Planar::zeros(rows, all.cols); k];
        for (q, rep) in reps.iter_mut().enumerate() {
            for c in 0..3 {
                for r in 0..rows {
                    let src = &all.data[c][(r * k + q) * all.cols..][..all.cols];
                    rep.data[c][r * all.cols..][..all.cols].copy_from_slice(src);
                }
            }
        }
        Ok(Uncertainty::Replicas(reps))
    }

    fn check(&self, what: &str, m: &Planar) -> Result<()> {
        match self {
            Uncertainty::Exact => Ok(()),
            Uncertainty::Independent(e) => check_shape(what, e, m),
            Uncertainty::Replicas(reps) => check_shape(what, &reps[0], m),
        }
    }
}

/// The replicas' deviations from their mean, scaled so that the squares of their
/// products sum to the variance of the mean: `(R_q − R̄) / √(K(K−1))`.
fn scaled_deviations(reps: &[Planar]) -> Vec<Planar> {
    let k = reps.len() as f64;
    let mut mean = Planar::zeros(reps[0].rows, reps[0].cols);
    for r in reps {
        add(&mut mean, r);
    }
    let f = 1.0 / (k * (k - 1.0)).sqrt();
    reps.iter()
        .map(|r| {
            let mut d = r.clone();
            for (pd, pm) in d.data.iter_mut().zip(&mean.data) {
                for (x, m) in pd.iter_mut().zip(pm) {
                    *x = (*x - m / k) * f;
                }
            }
            d
        })
        .collect()
}

fn squared(m: &Planar) -> Planar {
    let mut out = m.clone();
    for plane in &mut out.data {
        for v in plane.iter_mut() {
            *v *= *v;
        }
    }
    out
}

/// The sky as a planar matrix (patches × steps).
fn sky_planar(sky: &PackedSky) -> Planar {
    let (np, ns) = (sky.patches(), sky.steps());
    let mut s = Planar::zeros(np, ns);
    for c in 0..3 {
        for l in 0..np {
            for t in 0..ns {
                s.data[c][l * ns + t] = sky.get(c, l, t);
            }
        }
    }
    s
}

fn check_shape(what: &str, err: &Planar, m: &Planar) -> Result<()> {
    if (err.rows, err.cols) != (m.rows, m.cols) {
        bail!(
            "{what}: the standard errors (or replicas) are {}×{} but the matrix is {}×{}",
            err.rows,
            err.cols,
            m.rows,
            m.cols
        );
    }
    Ok(())
}

/// Standard errors of `V·T·D·s` from what is known of V's and D's errors.
pub fn three_phase(
    v: &Planar,
    ev: &Uncertainty,
    t: &Planar,
    d: &Planar,
    ed: &Uncertainty,
    sky: &PackedSky,
) -> Result<Planar> {
    ev.check("V", v)?;
    ed.check("D", d)?;
    let s = sky_planar(sky);
    let mut var = Planar::zeros(v.rows, s.cols);
    match ev {
        Uncertainty::Exact => {}
        Uncertainty::Independent(sv) => {
            let w = t.mul(d)?.mul(&s)?;
            add(&mut var, &squared(sv).mul(&squared(&w))?);
        }
        Uncertainty::Replicas(reps) => {
            let w = t.mul(d)?.mul(&s)?;
            for dev in scaled_deviations(reps) {
                add(&mut var, &squared(&dev.mul(&w)?));
            }
        }
    }
    match ed {
        Uncertainty::Exact => {}
        Uncertainty::Independent(sd) => {
            let u = v.mul(t)?;
            let inner = squared(sd).mul(&squared(&s))?;
            add(&mut var, &squared(&u).mul(&inner)?);
        }
        Uncertainty::Replicas(reps) => {
            let u = v.mul(t)?;
            for dev in scaled_deviations(reps) {
                add(&mut var, &squared(&u.mul(&dev)?.mul(&s)?));
            }
        }
    }
    Ok(root(var))
}

/// Standard errors of `DC·s` from what is known of DC's errors.
pub fn two_phase(dc: &Planar, edc: &Uncertainty, sky: &PackedSky) -> Result<Planar> {
    edc.check("DC", dc)?;
    let s = sky_planar(sky);
    let mut var = Planar::zeros(dc.rows, s.cols);
    match edc {
        Uncertainty::Exact => {}
        Uncertainty::Independent(sdc) => add(&mut var, &squared(sdc).mul(&squared(&s))?),
        Uncertainty::Replicas(reps) => {
            for dev in scaled_deviations(reps) {
                add(&mut var, &squared(&dev.mul(&s)?));
            }
        }
    }
    Ok(root(var))
}

fn add(a: &mut Planar, b: &Planar) {
    for (pa, pb) in a.data.iter_mut().zip(&b.data) {
        for (x, y) in pa.iter_mut().zip(pb) {
            *x += y;
        }
    }
}

fn root(mut m: Planar) -> Planar {
    for plane in &mut m.data {
        for v in plane.iter_mut() {
            *v = v.max(0.0).sqrt();
        }
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grey(rows: usize, cols: usize, v: &[f64]) -> Planar {
        let mut p = Planar::zeros(rows, cols);
        for c in 0..3 {
            p.data[c].copy_from_slice(v);
        }
        p
    }

    #[test]
    fn hand_computed_case() {
        // V 1×2 = [1 2] ± [.1 .2]; T = identity 2×2; D 2×1 = [3; 4] ± [.3; .4]; s = [2]
        // W = T·D·s = [6; 8]: term V = .1²·36 + .2²·64 = 0.36 + 2.56 = 2.92
        // U = V·T = [1 2]: term D = 1·(.09·4) + 4·(.16·4) = 0.36 + 2.56 = 2.92
        let v = grey(1, 2, &[1.0, 2.0]);
        let sv = grey(1, 2, &[0.1, 0.2]);
        let t = grey(2, 2, &[1.0, 0.0, 0.0, 1.0]);
        let d = grey(2, 1, &[3.0, 4.0]);
        let sd = grey(2, 1, &[0.3, 0.4]);
        let mut sky = PackedSky::new(1, 1);
        sky.set_row(0, &[2.0, 2.0, 2.0], 3);
        let (ind, exact) = (Uncertainty::Independent, Uncertainty::Exact);
        let e = three_phase(&v, &ind(sv.clone()), &t, &d, &ind(sd.clone()), &sky).unwrap();
        assert!((e.get(1, 0, 0) - (2.92f64 + 2.92).sqrt()).abs() < 1e-12);
        let only_v = three_phase(&v, &ind(sv.clone()), &t, &d, &exact, &sky).unwrap();
        assert!((only_v.get(0, 0, 0) - 2.92f64.sqrt()).abs() < 1e-12);
        assert!(three_phase(&v, &ind(sd.clone()), &t, &d, &exact, &sky).is_err());
        let dc = grey(1, 1, &[5.0]);
        let sdc = grey(1, 1, &[0.5]);
        let e = two_phase(&dc, &ind(sdc), &sky).unwrap();
        assert!((e.get(2, 0, 0) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn replicas_by_hand() {
        // V row 0 from 2 replicas [1 1] and [1 3] (mean [1 2]); W = T·D·s = [6; 8]:
        // results 6+8 = 14 and 6+24 = 30, mean 22; var of the mean = (8² + 8²)/(2·1) = 64,
        // sd 8 (the elements' own errors, sd 0 and 1, taken as independent: 64 too). Row 1
        // with a negative covariance: replicas [1 3] and [3 1] (mean [2 2]): results 30 and
        // 26, var = (2² + 2²)/2 = 4, sd 2, where independent elements (sd 1 and 1) would
        // give 36 + 64 = 100, sd 10.
        let all = grey(4, 2, &[1.0, 1.0, 1.0, 3.0, 1.0, 3.0, 3.0, 1.0]);
        // rows 0,1: record 0's two replicas; rows 2,3: record 1's
        let Uncertainty::Replicas(reps) = Uncertainty::replicas(&all, 2, "V").unwrap() else {
            panic!("replicas expected")
        };
        assert_eq!(reps.len(), 2);
        assert_eq!(reps[0].data[0], vec![1.0, 1.0, 1.0, 3.0]);
        assert_eq!(reps[1].data[0], vec![1.0, 3.0, 3.0, 1.0]);
        let v = grey(2, 2, &[1.0, 2.0, 2.0, 2.0]);
        let t = grey(2, 2, &[1.0, 0.0, 0.0, 1.0]);
        let d = grey(2, 1, &[3.0, 4.0]);
        let mut sky = PackedSky::new(1, 1);
        sky.set_row(0, &[2.0, 2.0, 2.0], 3);
        let e = three_phase(
            &v,
            &Uncertainty::Replicas(reps.clone()),
            &t,
            &d,
            &Uncertainty::Exact,
            &sky,
        )
        .unwrap();
        assert!((e.get(0, 0, 0) - 8.0).abs() < 1e-12, "{}", e.get(0, 0, 0));
        assert!((e.get(1, 1, 0) - 2.0).abs() < 1e-12, "{}", e.get(1, 1, 0));
        // D from replicas: U = V·T = V; D replicas [3;4]±: [2;4] and [4;4] → U·D_q·s for
        // row 0: (2+8)·2 = 20 and (4+8)·2 = 24, var = (4+4)/2 = 4
        let dall = grey(4, 1, &[2.0, 4.0, 4.0, 4.0]);
        let ed = Uncertainty::replicas(&dall, 2, "D").unwrap();
        let e = three_phase(&v, &Uncertainty::Exact, &t, &d, &ed, &sky).unwrap();
        assert!((e.get(2, 0, 0) - 2.0).abs() < 1e-12, "{}", e.get(2, 0, 0));
        // two-phase: DC 1×1 from replicas 4 and 6 (mean 5), s = 2: results 8 and 12 → sd 2
        let dc_reps = Uncertainty::replicas(&grey(2, 1, &[4.0, 6.0]), 2, "DC").unwrap();
        let e = two_phase(&grey(1, 1, &[5.0]), &dc_reps, &sky).unwrap();
        assert!((e.get(0, 0, 0) - 2.0).abs() < 1e-12);
        // shapes: 3 rows are not records of 2 replicas; replicas of another shape
        assert!(Uncertainty::replicas(&grey(3, 2, &[0.0; 6]), 2, "V").is_err());
        let wrong = Uncertainty::replicas(&grey(2, 2, &[0.0; 4]), 2, "V").unwrap();
        assert!(three_phase(&v, &wrong, &t, &d, &Uncertainty::Exact, &sky).is_err());
    }
}
