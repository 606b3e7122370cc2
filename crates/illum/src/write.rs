//! mkillum's output: primitives as Radiance's mkillum prints them, the `illum`/`light`
//! material, and the distribution pattern with its data files (a pole extrapolation row,
//! the azimuth wrapped, values relative to the average).

use std::fmt::Write as _;
use std::io::Write as _;

use anyhow::{Context, Result};
use glam::DVec3;

use crate::directives::{Colour, Settings};
use crate::sample::Distribution;

/// A primitive as read from the input.
#[derive(Debug, Clone, PartialEq)]
pub struct Prim {
    /// Modifier.
    pub modifier: String,
    /// Type.
    pub ptype: String,
    /// Identifier.
    pub name: String,
    /// String arguments.
    pub sargs: Vec<String>,
    /// Integer arguments (read, not printed: Radiance prints their count as 0).
    pub iargs: Vec<String>,
    /// Real arguments.
    pub rargs: Vec<f64>,
}

/// Appends a primitive with modifier `modifier`; surfaces modified by `void` are dropped.
pub fn printobj(out: &mut String, modifier: &str, p: &Prim) {
    if fenestra_scene::types::is_surface(&p.ptype) && modifier == "void" {
        return;
    }
    let _ = write!(out, "\n{} {} {}", modifier, p.ptype, p.name);
    let _ = write!(out, "\n{}", p.sargs.len());
    for s in &p.sargs {
        let _ = write!(out, " {s}");
    }
    out.push_str("\n0");
    let _ = write!(out, "\n{}", p.rargs.len());
    for (i, v) in p.rargs.iter().enumerate() {
        if i % 3 == 0 {
            out.push('\n');
        }
        out.push(' ');
        out.push_str(&fenestra_cfmt::g_width(*v, 18, 12));
    }
    out.push('\n');
}

/// The `illum` (or `light`) material and the surface it now modifies.
pub fn illumout(out: &mut String, il: &Settings, altmat: &str, col: [f64; 3], p: &Prim) {
    if il.sampdens <= 0 {
        out.push_str("\nvoid ");
    } else {
        let _ = write!(out, "\n{}.dist ", il.matname);
    }
    let _ = write!(
        out,
        "{} {}",
        if il.light { "light" } else { "illum" },
        il.matname
    );
    if il.light || altmat == "void" {
        out.push_str("\n0");
    } else {
        let _ = write!(out, "\n1 {altmat}");
    }
    let c = if il.colour == Colour::None {
        [crate::bright(col); 3]
    } else {
        col
    };
    let _ = write!(out, "\n0\n3 {:.6} {:.6} {:.6}\n", c[0], c[1], c[2]);
    printobj(out, &il.matname, p);
}

/// The data file name for channel `c` (`R`, `G`, `B` or none).
fn dfname(il: &Settings, c: Option<char>) -> String {
    let mut s = il.datafile.clone();
    if let Some(c) = c {
        s.push(c);
    }
    if il.dfnum > 0 {
        let _ = write!(s, "{}", il.dfnum);
    }
    s.push_str(".dat");
    s
}

/// Writes one data file (a free name unless clobbering is allowed) and returns its name.
fn write_datafile(il: &mut Settings, c: Option<char>, body: &str) -> Result<String> {
    let mut name = dfname(il, c);
    while !il.clobber && std::path::Path::new(&name).exists() {
        il.dfnum += 1;
        name = dfname(il, c);
    }
    let mut f = fenestra_cli::output::AtomicFile::create(&name)
        .with_context(|| format!("cannot open data file \"{name}\""))?;
    f.write_all(body.as_bytes())
        .with_context(|| format!("cannot write data file \"{name}\""))?;
    f.commit()
        .with_context(|| format!("cannot write data file \"{name}\""))?;
    Ok(name)
}

/// Five numbers per line, each `" %11e"`, a newline before every fifth.
struct Numbers {
    text: String,
    count: usize,
}

impl Numbers {
    fn put(&mut self, v: f64) {
        if self.count % 5 == 0 {
            self.text.push('\n');
        }
        self.count += 1;
        let s = fenestra_cfmt::fmt_e(v, 6);
        let _ = write!(self.text, " {s:>11}");
    }

    /// Rows of `m` values, each followed by its first value again (the azimuth wrap).
    fn rows(&mut self, rows: &[Vec<f64>]) {
        for r in rows {
            for v in r {
                self.put(*v);
            }
            self.put(r[0]);
        }
    }
}

/// The extrapolated row beyond a pole: twice the row's mean minus each value.
fn beyond(row: &[f64]) -> Vec<f64> {
    let avg = row.iter().sum::<f64>() / row.len() as f64;
    row.iter().map(|v| 2.0 * avg - v).collect()
}

/// The relative value rows of one channel (`Some(k)`) or of the brightness (`None`).
fn channel_rows(d: &Distribution, col: [f64; 3], ch: Option<usize>) -> Vec<Vec<f64>> {
    let norm = match ch {
        Some(k) => col[k],
        None => crate::bright(col),
    };
    // a channel whose average is zero has no relative distribution: zeros, not NaN
    let mult = if norm > 0.0 {
        1.0 / d.nsamps.max(1) as f64 / norm
    } else {
        0.0
    };
    d.sums
        .chunks(d.nazi)
        .map(|r| {
            r.iter()
                .map(|v| {
                    mult * match ch {
                        Some(k) => v[k],
                        None => crate::bright(*v),
                    }
                })
                .collect()
        })
        .collect()
}

fn file_body(first: (f64, f64, usize), m: usize, rows: &[Vec<f64>]) -> String {
    let mut n = Numbers {
        text: format!(
            "2\n{:.6} {:.6} {}\n{:.6} {:.6} {}\n",
            first.0,
            first.1,
            first.2,
            0.0,
            std::f64::consts::TAU,
            m + 1
        ),
        count: 0,
    };
    n.rows(rows);
    n.text.push('\n');
    n.text
}

/// The distribution pattern of a hemisphere (`axes` = u, v, w) or of a sphere (`None`),
/// with its data files. Increments the data-file number.
pub fn distribution(
    out: &mut String,
    il: &mut Settings,
    d: &Distribution,
    col: [f64; 3],
    axes: Option<[DVec3; 3]>,
) -> Result<()> {
    let (n, m) = (d.nalt, d.nazi);
    let first = match axes {
        Some(_) => (1.0 + 0.5 / n as f64, 0.5 / n as f64, n + 1),
        None => (1.0 + 1.0 / n as f64, -1.0 - 1.0 / n as f64, n + 2),
    };
    let with_poles = |rows: Vec<Vec<f64>>| -> Vec<Vec<f64>> {
        let mut all = vec![beyond(&rows[0])];
        if axes.is_none() {
            let south = beyond(&rows[rows.len() - 1]);
            all.extend(rows);
            all.push(south);
        } else {
            all.extend(rows);
        }
        all
    };
    if il.colour == Colour::Distribution {
        let _ = write!(out, "\nvoid colordata {}.dist", il.matname);
        out.push_str("\n9 red green blue");
        for (k, c) in ['R', 'G', 'B'].into_iter().enumerate() {
            let rows = with_poles(channel_rows(d, col, Some(k)));
            let name = write_datafile(il, Some(c), &file_body(first, m, &rows))?;
            let _ = write!(out, " {name}");
        }
    } else {
        let _ = write!(out, "\nvoid brightdata {}.dist", il.matname);
        out.push_str("\n5 noneg");
        let rows = with_poles(channel_rows(d, col, None));
        let name = write_datafile(il, None, &file_body(first, m, &rows))?;
        let _ = write!(out, " {name}");
    }
    match axes {
        Some([u, v, w]) => {
            out.push_str("\n\tillum.cal il_alth il_azih\n0\n9\n");
            for a in [u, v, w] {
                let _ = writeln!(out, "\t{:.6}\t{:.6}\t{:.6}", a.x, a.y, a.z);
            }
        }
        None => out.push_str("\n\tillum.cal il_alt il_azi\n0\n0\n"),
    }
    il.dfnum += 1;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn primitives_print_as_radiance_s_mkillum() {
        let p = Prim {
            modifier: "m".into(),
            ptype: "polygon".into(),
            name: "w".into(),
            sargs: vec![],
            iargs: vec![],
            rargs: vec![1.0, 0.01, 0.9, 1.0, 0.01, 2.4],
        };
        let mut s = String::new();
        printobj(&mut s, "illum_mat", &p);
        assert_eq!(
            s,
            "\nillum_mat polygon w\n0\n0\n6\n                  1               0.01                0.9\n                  1               0.01                2.4\n"
        );
        let mut v = String::new();
        printobj(&mut v, "void", &p);
        assert!(v.is_empty(), "void surfaces are dropped");
    }

    #[test]
    fn numbers_wrap_five_per_line() {
        let mut n = Numbers {
            text: String::new(),
            count: 0,
        };
        n.rows(&[vec![1.0, -0.5, 2.0]]);
        assert_eq!(
            n.text,
            "\n 1.000000e+00 -5.000000e-01 2.000000e+00 1.000000e+00"
        );
    }
}
