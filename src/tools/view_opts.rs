//! The view options every viewing tool accepts (`-vt? -vp -vd -vu -vh -vv -vo -va -vs
//! -vl -vf`), declared once for option tables and applied to a
//! [`fenestra_formats::view::View`] in command-line order.

use anyhow::{bail, Context, Result};
use fenestra_cli::opts::{Kind, Opt, OptHit};
use fenestra_formats::view::View;

/// Option declarations for a tool's [`fenestra_cli::opts::Spec`].
pub fn options() -> Vec<Opt> {
    vec![
        Opt::new(
            "vt",
            Kind::Attached,
            "view type: v perspective, l parallel, a angular fisheye, h hemispherical, s planisphere, c cylindrical",
        ),
        Opt::new("vp", Kind::Vec3, "view point"),
        Opt::new("vd", Kind::Vec3, "view direction (its length is the focal distance)"),
        Opt::new("vu", Kind::Vec3, "view up vector"),
        Opt::new("vh", Kind::Real, "horizontal view size (degrees; world units for -vtl)"),
        Opt::new("vv", Kind::Real, "vertical view size"),
        Opt::new("vo", Kind::Real, "fore clipping distance"),
        Opt::new("va", Kind::Real, "aft clipping distance (0: none)"),
        Opt::new("vs", Kind::Real, "view shift (image fractions)"),
        Opt::new("vl", Kind::Real, "view lift (image fractions)"),
        Opt::new("vf", Kind::Word, "read view options from a file (view file or picture)"),
    ]
}

/// Applies `hit` to `view` if it is a view option; `Ok(false)` when it is not one.
pub fn apply(view: &mut View, hit: &OptHit, prog: &str) -> Result<bool> {
    let words: Vec<String> = match hit.key {
        "vt" => vec![format!("-vt{}", hit.word())],
        "vp" | "vd" | "vu" => {
            let v = hit.vec3();
            vec![
                format!("-{}", hit.key),
                v[0].to_string(),
                v[1].to_string(),
                v[2].to_string(),
            ]
        }
        "vh" | "vv" | "vo" | "va" | "vs" | "vl" => {
            vec![format!("-{}", hit.key), hit.real().to_string()]
        }
        "vf" => {
            let file = hit.word();
            let data =
                std::fs::read(file).with_context(|| format!("cannot open view file '{file}'"))?;
            let text = String::from_utf8_lossy(&data);
            if !view.apply_file_text(&text, prog) {
                bail!("no view in file '{file}'");
            }
            return Ok(true);
        }
        _ => return Ok(false),
    };
    view.apply_option(&words)
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    Ok(true)
}
