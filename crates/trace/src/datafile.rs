//! Radiance data files (the `.dat` files of `brightdata`/`colordata`, e.g. mkillum's
//! output): N dimensions, each `beg end m` (evenly spaced) or `0 0 m x1 … xm`
//! (explicit coordinates), then the m1·…·mN values with the last dimension varying
//! fastest; `#` starts a comment. Values are interpolated multilinearly; outside the
//! grid the end intervals extend linearly (as Radiance's data patterns do).

use std::path::Path;

use anyhow::{anyhow, bail, Context, Result};

/// One dimension's coordinates.
#[derive(Debug, Clone, PartialEq)]
enum Axis {
    /// `m` points from `beg` to `end` (either order).
    Even { beg: f64, end: f64, m: usize },
    /// Explicit, monotonic coordinates.
    Listed(Vec<f64>),
}

impl Axis {
    fn len(&self) -> usize {
        match self {
            Axis::Even { m, .. } => *m,
            Axis::Listed(v) => v.len(),
        }
    }

    /// Lower index of the interval used for `x` and the fraction within it.
    fn locate(&self, x: f64) -> (usize, f64) {
        let n = self.len();
        if n < 2 {
            return (0, 0.0);
        }
        match self {
            Axis::Even { beg, end, m } => {
                let pos = (x - beg) / (end - beg) * (*m as f64 - 1.0);
                let c = pos.floor().clamp(0.0, (*m - 2) as f64);
                (c as usize, pos - c)
            }
            Axis::Listed(v) => {
                let up = v[n - 1] >= v[0];
                // the interval [v[k], v[k+1]] holding x (end intervals extend outward);
                // v is monotonic, so a binary search finds it
                let inner = &v[1..n - 1];
                let k = if up {
                    inner.partition_point(|&c| x >= c)
                } else {
                    inner.partition_point(|&c| x <= c)
                };
                let d = v[k + 1] - v[k];
                (k, if d == 0.0 { 0.0 } else { (x - v[k]) / d })
            }
        }
    }
}

/// A data grid.
#[derive(Debug, Clone, PartialEq)]
pub struct DataGrid {
    axes: Vec<Axis>,
    values: Vec<f64>,
}

impl DataGrid {
    /// Number of dimensions (coordinate expressions a pattern needs).
    pub fn dims(&self) -> usize {
        self.axes.len()
    }

    /// Reads a data file.
    pub fn read(path: &Path) -> Result<DataGrid> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read data file '{}'", path.display()))?;
        DataGrid::parse(&text, &path.display().to_string())
    }

    /// Parses data-file text; `name` labels errors (with line numbers).
    pub fn parse(text: &str, name: &str) -> Result<DataGrid> {
        let mut words: Vec<(&str, usize)> = Vec::new();
        for (ln, line) in text.lines().enumerate() {
            let line = line.split('#').next().unwrap_or("");
            words.extend(line.split_whitespace().map(|w| (w, ln + 1)));
        }
        let mut it = words.into_iter();
        let mut next = |what: &str| -> Result<f64> {
            let (w, ln) = it
                .next()
                .ok_or_else(|| anyhow!("{name}: unexpected end of data, expected {what}"))?;
            fenestra_scene::parse_real(w)
                .filter(|v| v.is_finite())
                .ok_or_else(|| anyhow!("{name}:{ln}: expected {what}, got '{w}'"))
        };
        let count = |v: f64, what: &str| -> Result<usize> {
            if v >= 1.0 && v.fract() == 0.0 && v < 1e8 {
                Ok(v as usize)
            } else {
                bail!("{name}: {what} must be a positive whole number, got {v}")
            }
        };
        let ndim = count(
            next("the number of dimensions")?,
            "the number of dimensions",
        )?;
        if ndim > 16 {
            bail!("{name}: {ndim} dimensions (at most 16)");
        }
        let mut axes = Vec::with_capacity(ndim);
        let mut total = 1usize;
        for d in 0..ndim {
            let beg = next(&format!("the start of dimension {}", d + 1))?;
            let end = next(&format!("the end of dimension {}", d + 1))?;
            let m = count(
                next(&format!("the size of dimension {}", d + 1))?,
                "a dimension size",
            )?;
            let axis = if beg == 0.0 && end == 0.0 && m > 1 {
                let mut v = Vec::with_capacity(m);
                for k in 0..m {
                    v.push(next(&format!(
                        "coordinate {} of dimension {}",
                        k + 1,
                        d + 1
                    ))?);
                }
                Axis::Listed(v)
            } else {
                if m > 1 && beg == end {
                    bail!("{name}: dimension {} starts and ends at {beg}", d + 1);
                }
                Axis::Even { beg, end, m }
            };
            total = total
                .checked_mul(m)
                .filter(|&t| t <= 1 << 28)
                .ok_or_else(|| anyhow!("{name}: data grid too large"))?;
            axes.push(axis);
        }
        let mut values = Vec::with_capacity(total);
        for k in 0..total {
            values.push(next(&format!("data value {} of {total}", k + 1))?);
        }
        Ok(DataGrid { axes, values })
    }

    /// Whether two grids share their axes (one location serves both).
    pub fn same_axes(&self, other: &DataGrid) -> bool {
        self.axes == other.axes
    }

    /// Where 2-D coordinates fall: the lower indices and fractions per axis.
    pub fn locate2(&self, x: [f64; 2]) -> ([usize; 2], [f64; 2]) {
        let (l0, f0) = self.axes[0].locate(x[0]);
        let (l1, f1) = self.axes[1].locate(x[1]);
        ([l0, l1], [f0, f1])
    }

    /// Bilinear interpolation of a 2-D grid at a location from [`Self::locate2`] (the same
    /// arithmetic, in the same order, as [`Self::value`]).
    pub fn value_at2(&self, lo: [usize; 2], fr: [f64; 2]) -> f64 {
        let (m0, m1) = (self.axes[0].len(), self.axes[1].len());
        let mut sum = 0.0;
        for corner in 0..4usize {
            let (h0, h1) = (corner & 2 != 0, corner & 1 != 0);
            if (h0 && m0 < 2) || (h1 && m1 < 2) {
                continue;
            }
            let w0 = if h0 { fr[0] } else { 1.0 - fr[0] };
            let w1 = if h1 { fr[1] } else { 1.0 - fr[1] };
            let w = 1.0 * w0 * w1;
            if w != 0.0 {
                let idx = (lo[0] + usize::from(h0)) * m1 + lo[1] + usize::from(h1);
                sum += w * self.values[idx];
            }
        }
        sum
    }

    /// Multilinear interpolation at `x` (one coordinate per dimension).
    pub fn value(&self, x: &[f64]) -> f64 {
        let n = self.axes.len();
        let mut lo = [0usize; 16];
        let mut fr = [0f64; 16];
        for d in 0..n {
            (lo[d], fr[d]) = self.axes[d].locate(x[d]);
        }
        let mut sum = 0.0;
        for corner in 0..(1usize << n) {
            let mut w = 1.0;
            let mut idx = 0usize;
            let mut skip = false;
            for d in 0..n {
                let hi = corner >> (n - 1 - d) & 1 == 1;
                let m = self.axes[d].len();
                if hi && m < 2 {
                    skip = true;
                    break;
                }
                let k = lo[d] + usize::from(hi);
                w *= if hi { fr[d] } else { 1.0 - fr[d] };
                idx = idx * m + k;
            }
            if !skip && w != 0.0 {
                sum += w * self.values[idx];
            }
        }
        sum
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bilinear_on_even_and_listed_axes() {
        let g = DataGrid::parse("2\n1 0 3\n0 0 2 10 20\n1 2\n3 4\n5 6\n", "t").unwrap();
        // first axis descends 1 -> 0 over 3 points: x = .75 is halfway between rows 0 and 1
        assert!((g.value(&[0.75, 10.0]) - 2.0).abs() < 1e-12);
        assert!((g.value(&[0.75, 15.0]) - 2.5).abs() < 1e-12);
        assert!((g.value(&[0.0, 20.0]) - 6.0).abs() < 1e-12);
        // linear extension beyond the last row
        assert!((g.value(&[-0.5, 10.0]) - 7.0).abs() < 1e-12);
    }

    #[test]
    fn listed_axes_find_their_interval_either_way() {
        // values equal to the coordinate times 10: interpolation and extension are exact
        let up = DataGrid::parse("1\n0 0 4 0 1 3 6\n0 10 30 60\n", "t").unwrap();
        let down = DataGrid::parse("1\n0 0 4 6 3 1 0\n60 30 10 0\n", "t").unwrap();
        for x in [-1.0, 0.0, 0.5, 1.0, 2.0, 3.0, 4.5, 6.0, 7.0] {
            assert!((up.value(&[x]) - 10.0 * x).abs() < 1e-12, "up {x}");
            assert!((down.value(&[x]) - 10.0 * x).abs() < 1e-12, "down {x}");
        }
    }

    #[test]
    fn bad_files_name_the_line() {
        let e = DataGrid::parse("1\n0 1 3\n1 x 3\n", "d.dat").unwrap_err();
        assert!(e.to_string().contains("d.dat:3"), "{e}");
        let e = DataGrid::parse("1\n0 1 3\n1 2\n", "d.dat").unwrap_err();
        assert!(e.to_string().contains("end of data"), "{e}");
    }
}
