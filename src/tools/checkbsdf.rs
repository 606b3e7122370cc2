//! checkBSDF: report what a BSDF XML file holds — Radiance's report (header fields, per
//! component the Lambertian part, largest directional total, angular resolution and
//! reciprocity error), then fenestra's own section (hemispherical totals for normal and
//! diffuse incidence, energy check). Full documentation: fenestra doc checkBSDF (docs/tools/checkBSDF.md in the source).

use std::fmt::Write as _;
use std::io::Write;
use std::path::Path;
use std::process::ExitCode;

use anyhow::{anyhow, bail, Result};
use fenestra_bsdf::check::sampled::{SampledRow, TreeFile};
use fenestra_bsdf::check::{self, ComponentCheck, Reciprocity};
use fenestra_bsdf::radiance::Drand48;
use fenestra_bsdf::{BlockData, Bsdf, Direction};
use fenestra_cli::opts::{Item, Spec};
use fenestra_formats::matrix::format_c_g;

fn spec() -> Spec {
    Spec::new(
        "checkBSDF",
        "Report the contents of BSDF XML files (Radiance's summary, then hemispherical totals and an energy check)",
    )
    .usage("bsdf.xml ..")
}

/// Light gained beyond this fraction (T + R > 1 + this) is reported as not conserved:
/// Monte Carlo BSDFs (genBSDF) carry noise of this order.
const ENERGY_NOISE: f64 = 0.01;

/// Runs checkBSDF.
pub fn run(args: Vec<String>) -> Result<ExitCode> {
    let items = spec().parse(&args)?;
    let files: Vec<String> = items
        .into_iter()
        .filter_map(|i| match i {
            Item::Pos(p) => Some(p),
            Item::Opt(_) => None,
        })
        .collect();
    if files.is_empty() {
        bail!("usage: checkBSDF bsdf.xml ..");
    }
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    // One colour-dither generator for the whole run, as in a Radiance process.
    let mut rng = fenestra_bsdf::radiance::Drand48::new();
    for f in &files {
        let path = fenestra_cli::raypath::find(f).unwrap_or_else(|| Path::new(f).into());
        let b = fenestra_bsdf::read_file(&path).map_err(|e| anyhow!("{e}"))?;
        let colour = fenestra_bsdf::radiance::colour_lambertians(&b, &mut rng);
        let trees = TreeFile::load(&b);
        let text = report(f, &b, &colour, trees, &mut rng)?;
        out.write_all(text.as_bytes())?;
        out.flush()?;
    }
    Ok(ExitCode::SUCCESS)
}

fn g(v: f64, prec: usize) -> String {
    let mut s = String::new();
    format_c_g(&mut s, v, prec);
    s
}

fn data_type(b: &Bsdf) -> String {
    let Some(blk) = b.blocks.first() else {
        return "Unknown".into();
    };
    match &blk.data {
        BlockData::Tree(t) if t.rank() == 4 => "Anisotropic_Tensor_Tree".into(),
        BlockData::Tree(_) => "Isotropic_Tensor_Tree".into(),
        // Radiance 6 names a matrix by its number of incident patches (145, 73, 41): the
        // current 77-patch Klems half basis is reported as Unknown_Matrix there, and here
        BlockData::Klems(m) => match m.incident.len() {
            145 => "Klems_Full".into(),
            73 => "Klems_Half".into(),
            41 => "Klems_Quarter".into(),
            _ => "Unknown_Matrix".into(),
        },
    }
}

/// An angle as Radiance prints it: two decimals (`57.30`), `180` for an absent component.
fn angle(a: f64) -> String {
    if a >= 180.0 {
        "180".into()
    } else {
        format!("{a:.2}")
    }
}

/// The report for one file (`colour`: the coloured Lambertian parts split off on loading;
/// `trees`: a tensor-tree file as Radiance loads it, for its Lambertian parts and reciprocity
/// rows; `rng`: the process's generator).
fn report(
    name: &str,
    b: &Bsdf,
    colour: &[(Direction, [f64; 3])],
    trees: Option<TreeFile>,
    rng: &mut Drand48,
) -> Result<String> {
    let mut s = String::new();
    let comp = |d| match &trees {
        Some(t) => t.component(d),
        None => check::component_with(b, d, colour),
    };
    let (int_refl, ext_refl) = (
        comp(Direction::ReflectionBack),
        comp(Direction::ReflectionFront),
    );
    let (int_ext, ext_int) = (
        comp(Direction::TransmissionBack),
        comp(Direction::TransmissionFront),
    );
    // Radiance drops a component whose largest directional total, its Lambertian part removed,
    // is at most 0.001; the split-off part still prints (as a missing transmission's).
    let dropped = |c: &ComponentCheck| c.max_total - c.lambertian_xyz[1] <= 0.001;
    let kept = |c: &Option<ComponentCheck>| c.as_ref().is_some_and(|c| !dropped(c));
    let all_dropped = [&int_refl, &ext_refl, &int_ext, &ext_int]
        .iter()
        .all(|c| c.as_ref().is_none_or(dropped));
    s.push_str("=====================================================\n");
    writeln!(s, "File: '{name}'")?;
    writeln!(s, "Manufacturer: '{}'", b.manufacturer)?;
    writeln!(s, "BSDF Name: '{}'", b.name)?;
    let cm = |v: Option<f64>| g(v.unwrap_or(0.0) * 100.0, 6);
    writeln!(
        s,
        "Dimensions (W x H x Thickness): {} x {} x {} cm",
        cm(b.width),
        cm(b.height),
        cm(b.thickness)
    )?;
    let kind = if all_dropped {
        "Pure_Lambertian".to_string()
    } else {
        data_type(b)
    };
    writeln!(s, "Type: {kind}")?;
    let colour_flag = trees.as_ref().map_or(b.has_colour(), TreeFile::colour_flag);
    writeln!(s, "Color: {}", u8::from(colour_flag))?;
    let geom = b
        .geometry
        .as_ref()
        .is_some_and(|g| !g.mgf.trim().is_empty());
    writeln!(s, "Has Geometry: {}", u8::from(geom))?;
    s.push_str("Component\tLambertian XYZ (%)\tMax. Tot. Dir\tMin. Angle\n");
    // one component row: Lambertian XYZ, largest directional total, smallest angle
    let line = |s: &mut String, label: &str, l: [f64; 3], m: f64, a: f64| {
        let _ = writeln!(
            s,
            "{label}\t{:4.1} {:4.1} {:4.1}\t\t{:5.1}%\t\t{} deg",
            100.0 * l[0],
            100.0 * l[1],
            100.0 * l[2],
            100.0 * m,
            angle(a)
        );
    };
    let row = |s: &mut String, label: &str, c: &Option<ComponentCheck>| match c {
        Some(c) if dropped(c) => line(
            s,
            label,
            c.lambertian_xyz,
            c.lambertian_xyz[1] / 100.0,
            180.0,
        ),
        Some(c) => line(s, label, c.lambertian_xyz, c.max_total, c.min_angle_deg),
        None => line(s, label, [0.0; 3], 0.0, 180.0),
    };
    row(&mut s, "Interior Refl", &int_refl);
    row(&mut s, "Exterior Refl", &ext_refl);
    // Radiance keeps one Lambertian transmission for both sides: a missing transmission
    // component shows the other's, with that part's Y (a fraction, printed as is) as its largest
    // directional total.
    let shared = |c: &Option<ComponentCheck>| {
        c.as_ref()
            .filter(|c| c.lambertian_xyz[1] > 0.0)
            .map(|c| (c.lambertian_xyz, c.lambertian_xyz[1] / 100.0, 180.0f64))
    };
    let trow =
        |s: &mut String, label: &str, c: &Option<ComponentCheck>, other| match (c, shared(other)) {
            (None, Some((l, m, a))) => line(s, label, l, m, a),
            _ => row(s, label, c),
        };
    trow(&mut s, "Int->Ext Trans", &int_ext, &ext_int);
    if int_ext.is_none() && ext_int.is_none() {
        s.push_str("Ext->Int Trans\t 0    0    0\t\t  0.0%\t\t180 deg\n");
    } else {
        trow(&mut s, "Ext->Int Trans", &ext_int, &int_ext);
    }
    s.push_str("Component\tReciprocity Error (min avg max %)\n");
    let rec = |s: &mut String, label: &str, r: Option<Reciprocity>| {
        let _ = match r {
            Some(r) => writeln!(
                s,
                "{label}\t{:5.1}\t{:5.1}\t{:5.1}",
                100.0 * r.min,
                100.0 * r.mean,
                100.0 * r.max
            ),
            None => writeln!(s, "{label}\t  0\t  0\t  0"),
        };
    };
    if let Some(t) = trees {
        // Tensor trees: Radiance's sampled rows, reproduced (check::sampled).
        for (label, r) in ["Interior Refl", "Exterior Refl", "Transmission"]
            .into_iter()
            .zip(t.rows(rng))
        {
            match r {
                SampledRow::Values(r) => rec(&mut s, label, Some(r)),
                SampledRow::Absent => rec(&mut s, label, None),
                SampledRow::Dropped => {}
                SampledRow::NoColour => bail!(
                    "{name}: {label} reciprocity: a sampled pair met a colour-tree leaf whose \
                     mean CIE (u', v') has no chromaticity (v' = 0: the CIE-u and CIE-v trees \
                     are much coarser than the other tree there)"
                ),
            }
        }
    } else {
        rec(
            &mut s,
            "Interior Refl",
            check::reflection_reciprocity(b, Direction::ReflectionBack).filter(|_| kept(&int_refl)),
        );
        rec(
            &mut s,
            "Exterior Refl",
            check::reflection_reciprocity(b, Direction::ReflectionFront)
                .filter(|_| kept(&ext_refl)),
        );
        let lamb = |c: &Option<ComponentCheck>| c.as_ref().map_or(0.0, |c| c.lambertian_y);
        rec(
            &mut s,
            "Transmission",
            check::transmission_reciprocity_with(b, lamb(&ext_int), lamb(&int_ext))
                .filter(|_| kept(&int_ext) && kept(&ext_int)),
        );
    }

    // fenestra's own section.
    s.push_str("--- fenestra: hemispherical totals (Visible, fractions)\n");
    s.push_str("Component\tNormal\tDiffuse\n");
    for (label, c) in [
        ("Interior Refl", &int_refl),
        ("Exterior Refl", &ext_refl),
        ("Int->Ext Trans", &int_ext),
        ("Ext->Int Trans", &ext_int),
    ] {
        match c {
            Some(c) => writeln!(s, "{label}\t{:.4}\t{:.4}", c.normal_total, c.diffuse_total)?,
            None => writeln!(s, "{label}\t-\t-")?,
        }
    }
    for (exterior, side) in [(true, "exterior"), (false, "interior")] {
        if let Some((v, i)) = check::energy_balance(b, exterior) {
            writeln!(
                s,
                "Light from the {side}: largest T+R = {v:.4} (incident patch {i})"
            )?;
            if v > 1.0 + ENERGY_NOISE {
                fenestra_cli::warn(format!(
                    "{name}: energy not conserved for light from the {side}: T+R = {v:.4} at incident patch {i} (more than 1 + {ENERGY_NOISE})"
                ));
                writeln!(s, "WARNING: energy not conserved for light from the {side}")?;
            }
        }
    }
    Ok(s)
}
