//! Standard errors carried from V and D (as `rtcontrib -E` writes them) to every value of
//! `V·T·D·s` (or of `DC·s`), per channel.
//!
//! Model: every element of V and D is an independent estimate with the given standard
//! error; T and the sky are exact. Then, with W = T·D·s and U = V·T,
//! `var(r[k,t]) = Σ_j σV[k,j]² W[j,t]² + Σ_i U[k,i]² Σ_l σD[i,l]² s[l,t]²`.
//! Elements of one row are not independent in fact: they are sums over the same rays, and a
//! ray that lands in one bin is missing from the others, so their covariances are negative
//! and the model's variance is an upper bound (for rays that each land in one bin, larger
//! by about the share of rays that land at all). tests/dctimestep_errors.rs measures it
//! against the spread of repeated runs.

use anyhow::{bail, Result};

use crate::timestep::{PackedSky, Planar};

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
            "{what}: the standard errors are {}×{} but the matrix is {}×{}",
            err.rows,
            err.cols,
            m.rows,
            m.cols
        );
    }
    Ok(())
}

/// Standard errors of `V·T·D·s`: `sv` and `sd` are V's and D's (`None`: exact).
pub fn three_phase(
    v: &Planar,
    sv: Option<&Planar>,
    t: &Planar,
    d: &Planar,
    sd: Option<&Planar>,
    sky: &PackedSky,
) -> Result<Planar> {
    let s = sky_planar(sky);
    let mut var = Planar::zeros(v.rows, s.cols);
    if let Some(sv) = sv {
        check_shape("V", sv, v)?;
        let w = t.mul(d)?.mul(&s)?;
        add(&mut var, &squared(sv).mul(&squared(&w))?);
    }
    if let Some(sd) = sd {
        check_shape("D", sd, d)?;
        let u = v.mul(t)?;
        let inner = squared(sd).mul(&squared(&s))?;
        add(&mut var, &squared(&u).mul(&inner)?);
    }
    Ok(root(var))
}

/// Standard errors of `DC·s` from those of DC.
pub fn two_phase(dc: &Planar, sdc: &Planar, sky: &PackedSky) -> Result<Planar> {
    check_shape("DC", sdc, dc)?;
    let s = sky_planar(sky);
    Ok(root(squared(sdc).mul(&squared(&s))?))
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
        let e = three_phase(&v, Some(&sv), &t, &d, Some(&sd), &sky).unwrap();
        assert!((e.get(1, 0, 0) - (2.92f64 + 2.92).sqrt()).abs() < 1e-12);
        let only_v = three_phase(&v, Some(&sv), &t, &d, None, &sky).unwrap();
        assert!((only_v.get(0, 0, 0) - 2.92f64.sqrt()).abs() < 1e-12);
        assert!(three_phase(&v, Some(&sd), &t, &d, None, &sky).is_err());
        let dc = grey(1, 1, &[5.0]);
        let sdc = grey(1, 1, &[0.5]);
        let e = two_phase(&dc, &sdc, &sky).unwrap();
        assert!((e.get(2, 0, 0) - 1.0).abs() < 1e-12);
    }
}
