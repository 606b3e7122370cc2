//! A receiver group as rcontrib options: the `.cal` file of its basis (each added once),
//! the `-p` parameters, `-bn`, `-b` and `-m`, and its `-o` output.

use anyhow::{bail, Result};
use glam::DVec3;

use super::directive::{Basis, KlemsSize};
use super::surfaces::Group;

/// Which `.cal` files the arguments so far have loaded.
#[derive(Debug, Default)]
pub struct CalFiles {
    loaded: Vec<&'static str>,
}

fn g(v: f64) -> String {
    fenestra_cfmt::fmt_g(v, 6)
}

/// The frame parameters shared by the Reinhart, Shirley–Chiu and CIE files.
fn frame_params(n: DVec3, u: DVec3, left: bool) -> String {
    format!(
        "rNx={},rNy={},rNz={},Ux={},Uy={},Uz={},RHS={}1",
        g(n.x),
        g(n.y),
        g(n.z),
        g(u.x),
        g(u.y),
        g(u.z),
        if left { '-' } else { '+' }
    )
}

/// Appends the rcontrib options for one receiver group; `jitter` is `-bj`'s value.
pub fn push_args(
    group: &Group,
    jitter: Option<&str>,
    cals: &mut CalFiles,
    args: &mut Vec<String>,
) -> Result<()> {
    if let Some(o) = &group.params.out {
        args.push("-o".into());
        args.push(o.clone());
    }
    let Some(basis) = group.params.basis()? else {
        bail!(
            "missing hemisphere sampling type! (receiver '{}' needs #@rfluxmtx h=…)",
            group.modifier
        );
    };
    let Some(n) = group.normal() else {
        bail!(
            "undefined normal for hemisphere sampling (receiver '{}': its surfaces' normals cancel)",
            group.modifier
        );
    };
    let u = group.up(n);
    if basis != Basis::Uniform && u.cross(n).length() < 1e-9 * u.length() {
        bail!(
            "up vector coincides with receiver normal (receiver '{}'; give u= across the surface)",
            group.modifier
        );
    }
    let left = group.params.left;
    let jtr = |mut s: String| {
        if let Some(j) = jitter {
            s.push_str(",JTR=");
            s.push_str(j);
        }
        s
    };
    let (cal, params, nbins, bin): (Option<&'static str>, Option<String>, String, String) =
        match basis {
            Basis::Uniform => {
                let bin = if group.surfaces.first().is_some_and(|s| s.is_source()) {
                    "0".to_string()
                } else {
                    format!("if(-Dx*{}-Dy*{}-Dz*{},0,-1)", g(n.x), g(n.y), g(n.z))
                };
                (None, None, "1".into(), bin)
            }
            Basis::ShirleyChiu(k) => (
                Some("disk2square.cal"),
                Some(jtr(format!("SCdim={k},{}", frame_params(n, u, left)))),
                "SCdim*SCdim".into(),
                "scbin".into(),
            ),
            Basis::Reinhart(mf) => (
                Some("reinhartb.cal"),
                Some(jtr(format!("MF={mf},{}", frame_params(n, u, left)))),
                "Nrbins".into(),
                "rbin".into(),
            ),
            Basis::Klems(size) => {
                let (cal, f, nb) = match size {
                    KlemsSize::Full => ("klems_full.cal", "kbin", "Nkbins"),
                    KlemsSize::Half => ("klems_half.cal", "khbin", "Nkhbins"),
                    KlemsSize::Quarter => ("klems_quarter.cal", "kqbin", "Nkqbins"),
                };
                (
                    Some(cal),
                    Some(jtr(format!("RHS={}1", if left { '-' } else { '+' }))),
                    nb.into(),
                    format!(
                        "{f}({},{},{},{},{},{})",
                        g(n.x),
                        g(n.y),
                        g(n.z),
                        g(u.x),
                        g(u.y),
                        g(u.z)
                    ),
                )
            }
            Basis::Cie => (
                Some("cieskyscan.cal"),
                Some(jtr(frame_params(n, u, left))),
                "Ncbins".into(),
                "cbin".into(),
            ),
        };
    if basis != Basis::Uniform {
        if let Some(s) = group
            .surfaces
            .iter()
            .find(|s| s.is_source() && (s.area - std::f64::consts::PI).abs() > 1e-3)
        {
            bail!("source '{}' must be 180-degrees", s.name);
        }
    }
    if let Some(c) = cal {
        if !cals.loaded.contains(&c) {
            cals.loaded.push(c);
            args.push("-f".into());
            args.push(c.into());
        }
    }
    if let Some(p) = params {
        args.push("-p".into());
        args.push(p);
    }
    args.push("-bn".into());
    args.push(nbins);
    args.push("-b".into());
    args.push(bin);
    args.push("-m".into());
    args.push(group.modifier.clone());
    Ok(())
}
