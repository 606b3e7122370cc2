//! dametrics' inputs: an illuminance matrix as lux per sensor and hour, and the sensors'
//! plan positions from a points file.

use anyhow::{bail, Context, Result};
use fenestra_formats::matrix::Matrix;

/// Radiance's RGB → lux weights (179 lm/W × the luminance coefficients).
pub const LUX: [f64; 3] = [47.435, 119.93, 11.635];

/// The matrix file `name` as (rows, columns, lux row by row): one component as is, three
/// through [`LUX`]; a value that is not a finite number is refused with its place.
pub fn lux_rows(name: &str) -> Result<(usize, usize, Vec<f64>)> {
    let m = Matrix::read_reporting(name, fenestra_cli::warn_note)?;
    let w: &[f64] = match m.ncomp {
        1 => &[1.0],
        3 => &LUX,
        n => bail!("{name}: {n} components per value (1, lux, or 3, RGB, expected)"),
    };
    let v: Vec<f64> = m
        .data
        .chunks(m.ncomp)
        .map(|c| c.iter().zip(w).map(|(x, k)| x * k).sum())
        .collect();
    // a metric over a value that is not a number would be one too: refused, with its place
    if let Some(k) = v.iter().position(|x| !x.is_finite()) {
        bail!(
            "{name}: row {} (sensor), column {} (hour) is not a finite number; no metric can use it",
            k / m.ncols.max(1) + 1,
            k % m.ncols.max(1) + 1
        );
    }
    Ok((m.nrows, m.ncols, v))
}

/// The x y of each sensor of the points file `name` (one per line with numbers).
pub fn sensor_xy(name: &str) -> Result<Vec<(f64, f64)>> {
    let text = std::fs::read_to_string(name).with_context(|| format!("cannot read '{name}'"))?;
    let mut out = Vec::new();
    for (k, line) in text.lines().enumerate() {
        let w: Vec<&str> = line.split_whitespace().collect();
        if w.is_empty() {
            continue;
        }
        let num = |i: usize| {
            w.get(i)
                .and_then(|s| fenestra_cli::opts::parse_real(s))
                .with_context(|| {
                    format!("{name}, line {}: a point 'x y z dx dy dz' expected", k + 1)
                })
        };
        out.push((num(0)?, num(1)?));
    }
    Ok(out)
}
