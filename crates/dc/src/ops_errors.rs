//! Monte Carlo errors through rmtxop's operations. An operand may come with replicas (K
//! independent estimates whose mean is the matrix, as `rtcontrib -E -Er K` writes them);
//! each becomes a *source* of error: its K deviations from their mean, scaled by
//! 1/√(K(K−1)) so that their squares add up to the variance of the mean. Every linear
//! operation (component transform, scaling, transposition) is applied to the deviations as
//! to the matrix; a sum keeps both operands' sources (independent runs); a product A·B
//! turns A's deviations into dev·B and B's into A·dev, so that every covariance within a
//! source is carried; an element-wise product does the same to first order. The result's
//! variance is the sum of the squares of all deviations.

use anyhow::{bail, Result};

use crate::ops::Mtx;

/// A matrix with the error sources it carries.
#[derive(Debug, Clone)]
pub struct Tracked {
    /// The value.
    pub value: Mtx,
    /// Per source, its scaled deviations (each the value's shape).
    pub sources: Vec<Vec<Mtx>>,
}

impl Tracked {
    /// A value without errors.
    pub fn exact(value: Mtx) -> Tracked {
        Tracked {
            value,
            sources: Vec::new(),
        }
    }

    /// `value` with the replicas in `reps` (K·rows rows, row `r·K + q` replica q of row r).
    pub fn with_replicas(value: Mtx, reps: &Mtx, k: usize, name: &str) -> Result<Tracked> {
        // (checked before allocating: rtcontrib -Er writes 2 to 4096)
        if !(2..=4096).contains(&k)
            || value.nrows == 0
            || reps.nrows != value.nrows * k
            || reps.ncols != value.ncols
            || reps.ncomp != value.ncomp
        {
            bail!(
                "{name}: {}×{}×{} replica values do not hold {k} replicas of the {}×{}×{} matrix",
                reps.nrows,
                reps.ncols,
                reps.ncomp,
                value.nrows,
                value.ncols,
                value.ncomp
            );
        }
        let row = value.row_len();
        let f = 1.0 / ((k * (k - 1)) as f64).sqrt();
        let mut devs = vec![Mtx::zeros(value.nrows, value.ncols, value.ncomp); k];
        for r in 0..value.nrows {
            for j in 0..row {
                let mean: f64 = (0..k)
                    .map(|q| f64::from(reps.data[(r * k + q) * row + j]))
                    .sum::<f64>()
                    / k as f64;
                for (q, d) in devs.iter_mut().enumerate() {
                    d.data[r * row + j] =
                        ((f64::from(reps.data[(r * k + q) * row + j]) - mean) * f) as f32;
                }
            }
        }
        Ok(Tracked {
            value,
            sources: vec![devs],
        })
    }

    /// Applies a linear operation to the value and every deviation.
    pub fn map(&mut self, mut f: impl FnMut(&mut Mtx) -> Result<()>) -> Result<()> {
        f(&mut self.value)?;
        for s in &mut self.sources {
            for d in s.iter_mut() {
                f(d)?;
            }
        }
        Ok(())
    }

    /// The sum `self + other`.
    pub fn sum(mut self, other: Tracked) -> Result<Tracked> {
        self.value.add(&other.value)?;
        self.sources.extend(other.sources);
        Ok(self)
    }

    /// The product `self · other`.
    pub fn multiply(self, other: &Tracked) -> Result<Tracked> {
        let value = self.value.multiply(&other.value)?;
        let mut sources = Vec::with_capacity(self.sources.len() + other.sources.len());
        for s in &self.sources {
            sources.push(
                s.iter()
                    .map(|d| d.multiply(&other.value))
                    .collect::<Result<Vec<_>>>()?,
            );
        }
        for s in &other.sources {
            sources.push(
                s.iter()
                    .map(|d| self.value.multiply(d))
                    .collect::<Result<Vec<_>>>()?,
            );
        }
        Ok(Tracked { value, sources })
    }

    /// The element-wise product `self ⊙ other` (errors to first order).
    pub fn elem_mul(self, other: &Tracked) -> Result<Tracked> {
        let mut value = self.value.clone();
        value.elem_mul(&other.value)?;
        let mut sources = Vec::new();
        for s in &self.sources {
            let mut v = Vec::with_capacity(s.len());
            for d in s {
                let mut d = d.clone();
                d.elem_mul(&other.value)?;
                v.push(d);
            }
            sources.push(v);
        }
        for s in &other.sources {
            let mut v = Vec::with_capacity(s.len());
            for d in s {
                // self ⊙ d (not d ⊙ self): a one-component right operand broadcasts
                let mut e = self.value.clone();
                e.elem_mul(d)?;
                v.push(e);
            }
            sources.push(v);
        }
        Ok(Tracked { value, sources })
    }

    /// The standard error of every value (the value's shape).
    pub fn standard_errors(&self) -> Mtx {
        let mut var = vec![0.0f64; self.value.data.len()];
        for s in &self.sources {
            for d in s {
                for (v, x) in var.iter_mut().zip(&d.data) {
                    *v += f64::from(*x) * f64::from(*x);
                }
            }
        }
        let mut out = Mtx::zeros(self.value.nrows, self.value.ncols, self.value.ncomp);
        for (o, v) in out.data.iter_mut().zip(var) {
            *o = v.sqrt() as f32;
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn m(nrows: usize, ncols: usize, v: &[f32]) -> Mtx {
        let mut x = Mtx::zeros(nrows, ncols, 1);
        x.data.copy_from_slice(v);
        x
    }

    #[test]
    fn product_sum_and_scale_by_hand() {
        // V 1×2 = [1 2] from replicas [1 1], [1 3]; W 2×1 = [6; 8] exact:
        // V·W replicas 14 and 30 → sd of the mean 8 (as dctimestep's test)
        let v = Tracked::with_replicas(
            m(1, 2, &[1.0, 2.0]),
            &m(2, 2, &[1.0, 1.0, 1.0, 3.0]),
            2,
            "V",
        )
        .unwrap();
        let w = Tracked::exact(m(2, 1, &[6.0, 8.0]));
        let p = v.clone().multiply(&w).unwrap();
        assert_eq!(p.value.data, vec![22.0]);
        assert!((p.standard_errors().data[0] - 8.0).abs() < 1e-5);
        // scaled by 0.5: sd 4; plus an independent copy of itself: sd √(4² + 4²)
        let mut half = p.clone();
        half.map(|x| x.transform(None, Some(&[0.5]))).unwrap();
        assert!((half.standard_errors().data[0] - 4.0).abs() < 1e-5);
        let sum = half.clone().sum(half).unwrap();
        assert!((sum.standard_errors().data[0] - 32f32.sqrt()).abs() < 1e-4);
        // the exact operand on the left: W^T · V^T carries the same error
        let mut wt = w.clone();
        wt.map(|x| {
            x.transpose();
            Ok(())
        })
        .unwrap();
        let mut vt = v.clone();
        vt.map(|x| {
            x.transpose();
            Ok(())
        })
        .unwrap();
        let q = wt.multiply(&vt).unwrap();
        assert!((q.standard_errors().data[0] - 8.0).abs() < 1e-5);
        // element-wise: V ⊙ [2 2] → replicas [2 2], [2 6]: sd per element 0 and 2
        let e = v.elem_mul(&Tracked::exact(m(1, 2, &[2.0, 2.0]))).unwrap();
        let se = e.standard_errors();
        assert!(se.data[0].abs() < 1e-6 && (se.data[1] - 2.0).abs() < 1e-5);
        // bad replica shapes
        assert!(Tracked::with_replicas(m(1, 2, &[1.0, 2.0]), &m(3, 2, &[0.0; 6]), 2, "V").is_err());
    }
}
