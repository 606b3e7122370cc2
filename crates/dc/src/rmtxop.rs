//! rmtxop's evaluation: its inputs with their own options (`-t -s -c -rf -rb -R`),
//! loaded whole, combined left to right (a run of products multiplied as one chain,
//! cheapest pair first), and the standard errors carried from replicas (`-E`).

use anyhow::{bail, Context, Result};

use crate::ops::{is_xml, multiply_chain, prefer_right_to_left, Mtx, Source, XmlPart};
use crate::ops_errors::Tracked;

/// What joins a matrix to the result so far.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Op {
    /// `.`: matrix product (the default).
    Product,
    /// `+`: sum.
    Sum,
    /// `*`: element-wise product.
    ElemProduct,
    /// `/`: element-wise division.
    ElemQuotient,
}

/// One input with the options given before it.
#[derive(Debug)]
pub struct Input {
    /// File, `-`, `!command` or BSDF XML.
    pub name: String,
    /// What joins it to the result so far.
    pub op: Op,
    /// `-t`: transpose it.
    pub transpose: bool,
    /// `-s`: scale factors (one, or one per output component).
    pub scale: Option<Vec<f64>>,
    /// `-c`: component transform coefficients.
    pub cmat: Option<Vec<f64>>,
    /// `-rf`/`-rb`: which part of a BSDF XML.
    pub part: XmlPart,
    /// `-R`: the file of its replicas.
    pub replicas: Option<String>,
}

/// Loads one input without its own options (`-t -s -c`).
fn load_raw(inp: &Input, verbose: bool) -> Result<Mtx> {
    let m = if is_xml(&inp.name) {
        Mtx::load(&inp.name, inp.part)?
    } else {
        Mtx::read_source(Source::open(&inp.name)?)?
    };
    report(inp, &m, verbose);
    Ok(m)
}

fn report(inp: &Input, m: &Mtx, verbose: bool) {
    if verbose {
        eprintln!(
            "rmtxop: loaded {} ({}×{}, {} components)",
            inp.name, m.nrows, m.ncols, m.ncomp
        );
    }
}

/// Applies an input's own options (`-s`/`-c`, then `-t`) to a matrix of it.
pub fn apply_own(inp: &Input, m: &mut Mtx) -> Result<()> {
    if inp.cmat.is_some() || inp.scale.is_some() {
        m.transform(inp.cmat.as_deref(), inp.scale.as_deref())
            .with_context(|| inp.name.clone())?;
    }
    if inp.transpose {
        m.transpose();
    }
    Ok(())
}

/// Loads one input and applies its own options.
pub fn load(inp: &Input, verbose: bool) -> Result<Mtx> {
    let mut m = load_raw(inp, verbose)?;
    apply_own(inp, &mut m)?;
    Ok(m)
}

/// Reads an opened input whole and applies its own options.
pub fn load_from(inp: &Input, src: Source, verbose: bool) -> Result<Mtx> {
    let mut m = Mtx::read_source(src)?;
    report(inp, &m, verbose);
    apply_own(inp, &mut m)?;
    Ok(m)
}

/// The result of the loaded inputs `mats` (their own options applied): left to right, as
/// Radiance's rmtxop, except that a command of products alone (three or more) is multiplied
/// from the right where Radiance's rule prefers that ([`prefer_right_to_left`]).
pub fn evaluate(inputs: &[Input], mats: Vec<Mtx>, verbose: bool) -> Result<Mtx> {
    let right_to_left =
        inputs.iter().skip(1).all(|i| i.op == Op::Product) && prefer_right_to_left(&mats);
    let mut chain: Vec<(Mtx, String)> = Vec::new();
    for (inp, m) in inputs.iter().zip(mats) {
        if inp.op == Op::Product || chain.is_empty() {
            chain.push((m, inp.name.clone()));
            continue;
        }
        let mut acc = reduce_chain(std::mem::take(&mut chain), verbose, false)?;
        match inp.op {
            Op::Sum => acc
                .add(&m)
                .with_context(|| format!("{}: matrix sum failed", inp.name))?,
            Op::ElemQuotient => {
                let zeros = acc
                    .elem_div(&m)
                    .with_context(|| format!("{}: element-wise division failed", inp.name))?;
                if zeros > 0 {
                    acc.info
                        .push("WARNING: zero divide(s) corrupted results".into());
                    fenestra_cli::warn(format!("{}: error during element-wise division", inp.name));
                }
            }
            _ => acc
                .elem_mul(&m)
                .with_context(|| format!("{}: element-wise product failed", inp.name))?,
        }
        if verbose {
            eprintln!("rmtxop: {:?} with {} done", inp.op, inp.name);
        }
        chain.push((acc, String::new()));
    }
    reduce_chain(chain, verbose, right_to_left)
}

/// One input with its replicas (`-R`) as a tracked matrix, its own options applied to the
/// value and to every replica deviation.
pub fn load_tracked(inp: &Input, verbose: bool) -> Result<Tracked> {
    let value = load_raw(inp, verbose)?;
    let mut t = match &inp.replicas {
        None => Tracked::exact(value),
        Some(name) => {
            if is_xml(name) {
                bail!("{name}: replicas are a matrix file (rtcontrib -E -Er K), not a BSDF");
            }
            let (raw, k) = crate::replicas::read(name)?;
            let reps = Mtx {
                nrows: raw.nrows,
                ncols: raw.ncols,
                ncomp: raw.ncomp,
                data: raw.data.iter().map(|&x| x as f32).collect(),
                info: Vec::new(),
                format: raw.format,
            };
            Tracked::with_replicas(value, &reps, k, name)?
        }
    };
    t.map(|m| apply_own(inp, m))?;
    Ok(t)
}

/// The standard errors of the result: the tracked inputs combined left to right (products
/// too), each operation applied to the value and to every replica deviation, then the
/// `trailing` options (`-t -s -c` after the last matrix), if any.
pub fn propagate(inputs: &[Input], tracked: Vec<Tracked>, trailing: Option<&Input>) -> Result<Mtx> {
    let mut acc: Option<Tracked> = None;
    for (inp, t) in inputs.iter().zip(tracked) {
        acc = Some(match acc {
            None => t,
            Some(a) => match inp.op {
                Op::Product => a
                    .multiply(&t)
                    .with_context(|| format!("{}: matrix product failed", inp.name))?,
                Op::Sum => a
                    .sum(t)
                    .with_context(|| format!("{}: matrix sum failed", inp.name))?,
                Op::ElemQuotient => {
                    bail!(
                        "{}: -E carries errors through '.', '+' and '*', not '/'",
                        inp.name
                    )
                }
                Op::ElemProduct => a
                    .elem_mul(&t)
                    .with_context(|| format!("{}: element-wise product failed", inp.name))?,
            },
        });
    }
    let mut t = acc.context("no input matrix")?;
    if let Some(tr) = trailing {
        t.map(|m| apply_own(tr, m))?;
    }
    Ok(t.standard_errors())
}

/// Multiplies a chain of loaded matrices (a single matrix is returned as is).
fn reduce_chain(chain: Vec<(Mtx, String)>, verbose: bool, right_to_left: bool) -> Result<Mtx> {
    let names: Vec<String> = chain.iter().map(|c| c.1.clone()).collect();
    let mats: Vec<Mtx> = chain.into_iter().map(|c| c.0).collect();
    if mats.len() > 1 {
        if verbose {
            eprintln!("rmtxop: multiplying {} matrices", mats.len());
        }
        let last = names.last().cloned().unwrap_or_default();
        return multiply_chain(mats, right_to_left)
            .with_context(|| format!("{last}: matrix product failed"));
    }
    mats.into_iter().next().context("no input matrix")
}
