//! The Tregenza/Reinhart sky patch basis (subdivision factor MF; MF 1 = Tregenza):
//! one source of truth for patch count, numbering (ground first), centres, solid
//! angles and direction → patch, shared by gendaymtx, genskyvec and bin look-ups.
//!
//! Numbering: patch 0 is the ground (whole lower hemisphere); patches 1..=N run
//! row by row from the horizon up, each row starting at north (+Y) and going
//! east (+X); the last patch is the zenith cap. Rows are `α = 90°/(7·MF + ½)`
//! high; row r holds `MF·[30,30,24,24,18,12,6][r/MF]` patches.

use std::f64::consts::PI;

/// Patches per row for MF = 1, from the horizon up (the zenith cap excluded).
pub const TREGENZA_ROWS: [usize; 7] = [30, 30, 24, 24, 18, 12, 6];

/// A Reinhart basis for one subdivision factor.
#[derive(Debug, Clone)]
pub struct Reinhart {
    mf: usize,
    /// First patch number of each row (sky rows, then the cap).
    row_start: Vec<usize>,
    /// Patches in each row (the cap row has 1).
    row_len: Vec<usize>,
}

impl Reinhart {
    /// The basis for subdivision factor `mf` (≥ 1).
    pub fn new(mf: usize) -> Reinhart {
        let mf = mf.max(1);
        let mut row_start = Vec::new();
        let mut row_len = Vec::new();
        let mut p = 1;
        for r in 0..7 * mf {
            let n = mf * TREGENZA_ROWS[r / mf];
            row_start.push(p);
            row_len.push(n);
            p += n;
        }
        row_start.push(p);
        row_len.push(1);
        Reinhart {
            mf,
            row_start,
            row_len,
        }
    }

    /// Subdivision factor.
    pub fn mf(&self) -> usize {
        self.mf
    }

    /// Number of rows in a sky vector or matrix: sky patches plus the ground.
    pub fn len(&self) -> usize {
        self.row_start[self.row_start.len() - 1] + 1
    }

    /// Never empty (there is always the ground and the zenith).
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Number of sky patches (without the ground): 145, 577, 2305 for MF 1, 2, 4.
    pub fn sky_patches(&self) -> usize {
        self.len() - 1
    }

    /// Altitude step α (radians).
    pub fn row_height(&self) -> f64 {
        (PI / 2.0) / (7.0 * self.mf as f64 + 0.5)
    }

    /// Number of altitude rows including the zenith cap (7·MF + 1).
    pub fn rows(&self) -> usize {
        self.row_len.len()
    }

    /// Patches in row `r`.
    pub fn row_len(&self, r: usize) -> usize {
        self.row_len[r]
    }

    /// First patch number of row `r`.
    pub fn row_start(&self, r: usize) -> usize {
        self.row_start[r]
    }

    /// Row and column of sky patch `p` (1..=N).
    pub fn row_col(&self, p: usize) -> (usize, usize) {
        let r = match self.row_start.binary_search(&p) {
            Ok(r) => r,
            Err(r) => r - 1,
        };
        (r, p - self.row_start[r])
    }

    /// Centre of patch `p` as (altitude, azimuth) in radians, azimuth from north
    /// toward east; the ground's centre is the nadir. These are the centres
    /// gendaymtx uses (row middle, column start offset by nothing: column j is
    /// centred on 360°·j/n).
    pub fn centre(&self, p: usize) -> (f64, f64) {
        if p == 0 {
            return (-PI / 2.0, 0.0);
        }
        let (r, c) = self.row_col(p);
        if r == self.rows() - 1 {
            return (PI / 2.0, 0.0);
        }
        (
            self.row_height() * (r as f64 + 0.5),
            2.0 * PI * c as f64 / self.row_len[r] as f64,
        )
    }

    /// Unit direction of patch `p`'s centre (x east, y north, z up).
    pub fn centre_dir(&self, p: usize) -> [f64; 3] {
        let (alt, azi) = self.centre(p);
        [alt.cos() * azi.sin(), alt.cos() * azi.cos(), alt.sin()]
    }

    /// Solid angle of patch `p` (sr); the ground counts 2π.
    pub fn solid_angle(&self, p: usize) -> f64 {
        if p == 0 {
            return 2.0 * PI;
        }
        let (r, _) = self.row_col(p);
        let a = self.row_height();
        if r == self.rows() - 1 {
            return 2.0 * PI * (1.0 - (a * 0.5).cos());
        }
        2.0 * PI * ((a * (r + 1) as f64).sin() - (a * r as f64).sin()) / self.row_len[r] as f64
    }

    /// Patch containing direction `d` (x east, y north, z up; unit length), with
    /// the arithmetic of reinhart.cal's `rbin`: 0 below the horizon (the exact
    /// horizon is sky row 0), azimuth from north toward east, and its quirk that an
    /// azimuth within 1e-4° below 360° minus half a patch wraps to the row's first patch.
    /// Divisions by the constants DEGREE and alpha are multiplications by their
    /// reciprocals, as the .cal compiler folds them (this decides directions lying
    /// exactly on a row boundary).
    pub fn patch_of(&self, d: [f64; 3]) -> usize {
        let degree = PI / 180.0;
        let alt = cal_asin(d[2]) * (1.0 / degree);
        if -alt > 0.0 {
            return 0;
        }
        let mut azi = d[0].atan2(d[1]);
        if -azi > 0.0 {
            azi += 2.0 * PI;
        }
        let azi = azi * (1.0 / degree);
        let alpha = 90.0 / (self.mf as f64 * 7.0 + 0.5);
        let r = ((alt * (1.0 / alpha)).floor() as usize).min(self.rows() - 1);
        let inc = 360.0 / self.row_len[r] as f64;
        let c = if 359.9999 - 0.5 * inc - azi > 0.0 {
            ((azi + 0.5 * inc) / inc).floor() as usize
        } else {
            0
        };
        self.row_start[r] + c
    }
    /// Sky patch index (0..N−1, no ground) of direction `d` in the default frame
    /// (+Z up, +Y north) as `reinhartb.cal` (the library version used by rfluxmtx)
    /// computes it: `None` for the ground **and the exact horizon**, the 1e-4°
    /// azimuth wrap quirk kept, and a true division by the row height (which that
    /// file defines as a variable, not a constant).
    pub fn sky_index_b(&self, d: [f64; 3]) -> Option<usize> {
        let degree = PI / 180.0;
        let alt = cal_asin(d[2]) * (1.0 / degree);
        if alt <= 0.0 {
            return None;
        }
        let mut azi = d[0].atan2(d[1]);
        if -azi > 0.0 {
            azi += 2.0 * PI;
        }
        let azi = azi * (1.0 / degree);
        let alpha = 90.0 / (self.mf as f64 * 7.0 + 0.5);
        let r = ((alt / alpha).floor() as usize).min(self.rows() - 1);
        let inc = 360.0 / self.row_len[r] as f64;
        let c = if 359.9999 - 0.5 * inc - azi > 0.0 {
            ((azi + 0.5 * inc) / inc).floor() as usize
        } else {
            0
        };
        Some(self.row_start[r] - 1 + c)
    }
}

/// The .cal library's `asin` with its argument clamped to [−1, 1] (Radiance's `Asin`).
fn cal_asin(z: f64) -> f64 {
    if z - 1.0 > 0.0 {
        PI / 2.0
    } else if -1.0 - z > 0.0 {
        -PI / 2.0
    } else {
        z.asin()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts() {
        assert_eq!(Reinhart::new(1).len(), 146);
        assert_eq!(Reinhart::new(2).len(), 578);
        assert_eq!(Reinhart::new(4).len(), 2306);
        assert_eq!(Reinhart::new(1).row_start(7), 145);
    }

    #[test]
    fn solid_angles_sum_to_hemisphere() {
        for mf in [1, 2, 4] {
            let b = Reinhart::new(mf);
            let s: f64 = (1..b.len()).map(|p| b.solid_angle(p)).sum();
            assert!((s - 2.0 * PI).abs() < 1e-9, "mf {mf}: {s}");
        }
    }

    #[test]
    fn centres_map_to_themselves() {
        for mf in [1, 2, 4] {
            let b = Reinhart::new(mf);
            for p in 1..b.len() {
                assert_eq!(b.patch_of(b.centre_dir(p)), p);
            }
            assert_eq!(b.patch_of([0.0, 0.0, -1.0]), 0);
        }
    }
}
