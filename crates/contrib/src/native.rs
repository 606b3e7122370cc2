//! Native evaluation of the two bin expressions three-phase runs spend their time in:
//! `kbin(...)`/`kbinN|E|S|W|D` of fenestra's `lib/klems_full.cal` and `rbin` of
//! `lib/reinhart.cal`. They are used only when the loaded file is byte-identical to
//! fenestra's own and no other definition touches the names involved. `rbin` follows
//! the file's arithmetic (the file tests the ground before the altitude and takes a
//! row's constants from a select over the rows); `kbin` computes the polar angle with `acos`
//! where klems_full.cal compares D.N with cosine thresholds derived from that angle
//! test, so the bins are the same numbers the .cal evaluator gives (checked over many
//! directions, ring boundaries included, by the tests below).

use fenestra_trace::DVec3;

/// fenestra's klems_full.cal, as shipped.
pub const KLEMS_FULL_CAL: &str = include_str!("../../../lib/klems_full.cal");
/// fenestra's reinhart.cal, as shipped.
pub const REINHART_CAL: &str = include_str!("../../../lib/reinhart.cal");

/// Names whose (re)definition outside the shipped file disables the native path.
pub const KLEMS_NAMES: [&str; 24] = [
    "kf_deg",
    "kf_c5",
    "kf_c15",
    "kf_c25",
    "kf_c35",
    "kf_c45",
    "kf_c55",
    "kf_c65",
    "kf_c75",
    "kf_c90",
    "kf_t",
    "kf_dot",
    "kf_nz",
    "kf_dotu",
    "kf_wrapped",
    "kf_p",
    "kf_bin",
    "kbin",
    "kbinN",
    "kbinE",
    "kbinS",
    "kbinW",
    "kbinD",
    "Nkbins",
];
/// As [`KLEMS_NAMES`] for reinhart.cal.
pub const REINHART_NAMES: [&str; 16] = [
    "rh_deg",
    "rh_alpha",
    "rh_tnaz",
    "rh_tsum",
    "rh_naz",
    "rh_accum",
    "rh_alt",
    "rh_row",
    "rh_azi",
    "rh_wrapped",
    "rh_col",
    "rh_q",
    "rh_first",
    "rh_inc",
    "rbin",
    "Nrbins",
];
/// Built-ins the files use (a user definition of one of these disables the native path).
pub const BUILTINS_USED: [&str; 6] = ["if", "select", "acos", "asin", "atan2", "floor"];

/// A natively evaluated bin expression.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum NativeBin {
    /// `kbin(N, U)` with the `RHS` in effect.
    Klems {
        /// Receiver normal.
        n: [f64; 3],
        /// Up vector.
        u: [f64; 3],
        /// Handedness (`RHS`).
        rhs: f64,
    },
    /// `rbin` with the `MF` in effect.
    Reinhart {
        /// Subdivision.
        mf: f64,
    },
}

/// The receiver frame of a recognised Klems bin expression (`kbinS`, `kbin(0,1,0,0,0,1)`…).
pub fn klems_frame(expr: &str) -> Option<([f64; 3], [f64; 3])> {
    let e: String = expr.chars().filter(|c| !c.is_whitespace()).collect();
    let fixed = match e.as_str() {
        "kbinN" => Some(([0.0, -1.0, 0.0], [0.0, 0.0, 1.0])),
        "kbinE" => Some(([-1.0, 0.0, 0.0], [0.0, 0.0, 1.0])),
        "kbinS" => Some(([0.0, 1.0, 0.0], [0.0, 0.0, 1.0])),
        "kbinW" => Some(([1.0, 0.0, 0.0], [0.0, 0.0, 1.0])),
        "kbinD" => Some(([0.0, 0.0, -1.0], [0.0, 1.0, 0.0])),
        _ => None,
    };
    if fixed.is_some() {
        return fixed;
    }
    let inner = e.strip_prefix("kbin(")?.strip_suffix(')')?;
    let v: Vec<f64> = inner
        .split(',')
        .map(|w| w.parse::<f64>().ok())
        .collect::<Option<_>>()?;
    (v.len() == 6).then(|| ([v[0], v[1], v[2]], [v[3], v[4], v[5]]))
}

fn clamp(z: f64) -> f64 {
    if z - 1.0 > 0.0 {
        1.0
    } else if -1.0 - z > 0.0 {
        -1.0
    } else {
        z
    }
}

const KF_BOUND: [f64; 9] = [5.0, 15.0, 25.0, 35.0, 45.0, 55.0, 65.0, 75.0, 90.0];
const KF_NAZ: [f64; 9] = [1.0, 8.0, 16.0, 20.0, 24.0, 24.0, 24.0, 16.0, 12.0];
const KF_BEFORE: [f64; 9] = [0.0, 1.0, 9.0, 25.0, 45.0, 69.0, 93.0, 117.0, 133.0];
const RH_TNAZ: [f64; 8] = [30.0, 30.0, 24.0, 24.0, 18.0, 12.0, 6.0, 1.0];
const RH_TSUM: [f64; 8] = [0.0, 30.0, 60.0, 84.0, 108.0, 126.0, 138.0, 144.0];

/// `select(k, table…)` for an integral k ≥ 1 (0 outside the table, as the built-in).
fn sel(table: &[f64], k: f64) -> f64 {
    let i = (k + 0.5) as i64;
    if i >= 1 && (i as usize) <= table.len() {
        table[i as usize - 1]
    } else if i == 0 {
        table.len() as f64
    } else {
        0.0
    }
}

impl NativeBin {
    /// The bin value for a ray direction (the value the .cal expression gives).
    pub fn eval(&self, d: DVec3) -> f64 {
        let (dx, dy, dz) = (d.x, d.y, d.z);
        match *self {
            NativeBin::Klems { n, u, rhs } => {
                let deg = 180.0 / std::f64::consts::PI;
                let [nx, ny, nz] = n;
                let [ux, uy, uz] = u;
                let dn = dx * nx + dy * ny + dz * nz;
                let pol = deg * clamp(-dn).acos();
                let y = dn * (nx * ux + ny * uy + nz * uz) - (dx * ux + dy * uy + dz * uz);
                let x = -rhs
                    * (dx * (uy * nz - uz * ny)
                        + dy * (uz * nx - ux * nz)
                        + dz * (ux * ny - uy * nx));
                let a = deg * y.atan2(x);
                let azi = if a > 0.0 { a } else { a + 360.0 };
                if pol - 90.0 > 0.0 {
                    return -1.0;
                }
                let mut r = 1.0f64;
                loop {
                    if r - 8.5 > 0.0 {
                        r = 9.0;
                        break;
                    }
                    if pol - sel(&KF_BOUND, r) > 0.0 {
                        r += 1.0;
                    } else {
                        break;
                    }
                }
                let inc = 360.0 / sel(&KF_NAZ, r);
                let col = if 360.0 - inc / 2.0 - azi > 0.0 {
                    ((azi + inc / 2.0) / inc).floor()
                } else {
                    0.0
                };
                sel(&KF_BEFORE, r) + col
            }
            NativeBin::Reinhart { mf } => {
                let deg = 180.0 / std::f64::consts::PI;
                let alpha = 90.0 / (mf * 7.0 + 0.5);
                let alt = deg * clamp(dz).asin();
                if -alt > 0.0 {
                    return 0.0;
                }
                let a0 = deg * dx.atan2(dy);
                let azi = if a0 > 0.0 { a0 } else { a0 + 360.0 };
                let row = (alt / alpha).floor();
                let t = ((row + 0.5) / mf).floor();
                let naz = if row - (7.0 * mf - 0.5) > 0.0 {
                    1.0
                } else {
                    mf * sel(&RH_TNAZ, t + 1.0)
                };
                let accum =
                    mf * (mf * sel(&RH_TSUM, t + 1.0) + (row - mf * t) * sel(&RH_TNAZ, t + 1.0));
                let inc = 360.0 / naz;
                let col = if 359.9999 - 0.5 * inc - azi > 0.0 {
                    ((azi + 0.5 * inc) / inc).floor()
                } else {
                    0.0
                };
                accum + col + 1.0
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fenestra_calc::Program;

    fn dirs() -> Vec<DVec3> {
        let mut v = Vec::new();
        // a fine grid plus the exact ring/row boundaries and the axes
        for i in 0..=180 {
            for j in 0..=360 {
                let th = (i as f64) * std::f64::consts::PI / 180.0;
                let ph = (j as f64) * std::f64::consts::PI / 180.0 + 1e-3 * (i % 3) as f64;
                v.push(DVec3::new(
                    th.sin() * ph.cos(),
                    th.sin() * ph.sin(),
                    th.cos(),
                ));
            }
        }
        let mut s = 12345u64;
        for _ in 0..20000 {
            let mut r = || {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((s >> 11) as f64) / ((1u64 << 53) as f64) * 2.0 - 1.0
            };
            let d = DVec3::new(r(), r(), r());
            if d.length() > 1e-3 {
                v.push(d.normalize());
            }
        }
        v.extend([
            DVec3::X,
            DVec3::Y,
            DVec3::Z,
            -DVec3::X,
            -DVec3::Y,
            -DVec3::Z,
        ]);
        v
    }

    fn check(cal: &str, pre: &str, expr: &str, nb: NativeBin) {
        let mut p = Program::for_renderer();
        p.load_str("-e", pre).unwrap();
        p.load_str("file", cal).unwrap();
        let vars = p.bind_vars(&["Dx", "Dy", "Dz"]);
        let id = p.add_expr("-b", expr).unwrap();
        let c = p.compile().unwrap();
        let mut st = c.state();
        for d in dirs() {
            st.set_all(&vars, &d.to_array());
            let want = c.eval_expr(&mut st, id).unwrap();
            let got = nb.eval(d);
            assert!(
                want == got || (want.is_nan() && got.is_nan()),
                "{expr} at {d:?}: cal {want} native {got}"
            );
        }
    }

    #[test]
    fn klems_native_equals_cal() {
        for (e, rhs) in [
            ("kbinS", 1.0),
            ("kbinN", 1.0),
            ("kbinD", 1.0),
            ("kbin(0,0,1,0,1,0)", -1.0),
        ] {
            let (n, u) = klems_frame(e).unwrap();
            let pre = "";
            let mut cal = KLEMS_FULL_CAL.to_string();
            if rhs < 0.0 {
                cal.push_str("RHS = -1;");
            }
            check(&cal, pre, e, NativeBin::Klems { n, u, rhs });
        }
    }

    #[test]
    fn reinhart_native_equals_cal() {
        for mf in [1.0, 2.0, 4.0] {
            check(
                REINHART_CAL,
                &format!("MF:{mf}"),
                "rbin",
                NativeBin::Reinhart { mf },
            );
        }
    }

    #[test]
    fn frames() {
        assert_eq!(
            klems_frame(" kbinS "),
            Some(([0.0, 1.0, 0.0], [0.0, 0.0, 1.0]))
        );
        assert_eq!(
            klems_frame("kbin(0,0,-1, 0,1,0)"),
            Some(([0.0, 0.0, -1.0], [0.0, 1.0, 0.0]))
        );
        assert_eq!(klems_frame("kbin(Nx,0,0,0,0,1)"), None);
    }
}
