//! Reading BSDF XML files (LBNL/WINDOW 6 schema) with quick-xml.

use std::path::Path;

use crate::dom::{self, line_of, Element};
use crate::klems::KlemsBasis;
use crate::model::{
    Block, BlockData, Bsdf, DataStructure, Direction, Geometry, KlemsMatrix, Wavelength,
};
use crate::tree::{TensorTree, ValueCheck};

/// An error reading a BSDF XML file, with the 1-based line where it was found.
#[derive(Debug, thiserror::Error)]
#[error("{file}, line {line}: {message}")]
pub struct XmlError {
    /// File name (as given).
    pub file: String,
    /// 1-based line.
    pub line: usize,
    /// What is wrong and what was expected.
    pub message: String,
}

/// Reads and parses a BSDF XML file.
pub fn read_file(path: &Path) -> Result<Bsdf, XmlError> {
    let text = std::fs::read_to_string(path).map_err(|e| XmlError {
        file: path.display().to_string(),
        line: 0,
        message: format!("cannot read: {e}"),
    })?;
    parse(&text, &path.display().to_string())
}

/// Parses BSDF XML text; `file` names it in error messages.
pub fn parse(text: &str, file: &str) -> Result<Bsdf, XmlError> {
    let err = |pos: usize, message: String| XmlError {
        file: file.to_string(),
        line: line_of(text, pos),
        message,
    };
    let root = dom::parse(text).map_err(|(m, p)| err(p, m))?;
    if root.name != "WindowElement" {
        return Err(err(
            root.pos,
            format!("root element is <{}>, expected <WindowElement>", root.name),
        ));
    }
    let mut bsdf = Bsdf {
        comments: leading_comments(text),
        ..Default::default()
    };
    if let Some(ft) = root.child("FileType") {
        if !ft.text.trim().eq_ignore_ascii_case("BSDF") {
            return Err(err(
                ft.pos,
                format!("FileType is '{}', expected 'BSDF'", ft.text.trim()),
            ));
        }
    }
    let layer = root
        .child("Optical")
        .and_then(|o| o.child("Layer"))
        .ok_or_else(|| err(root.pos, "missing <Optical><Layer>".into()))?;
    if let Some(m) = layer.child("Material") {
        bsdf.name = m.child_text("Name").unwrap_or("").to_string();
        bsdf.manufacturer = m.child_text("Manufacturer").unwrap_or("").to_string();
        bsdf.device_type = m.child_text("DeviceType").unwrap_or("").to_string();
        bsdf.width = length(m, "Width").map_err(|(p, m)| err(p, m))?;
        bsdf.height = length(m, "Height").map_err(|(p, m)| err(p, m))?;
        bsdf.thickness = length(m, "Thickness").map_err(|(p, m)| err(p, m))?;
    }
    if let Some(g) = layer.child("Geometry") {
        if let Some(f) = g.attr("format") {
            if !f.eq_ignore_ascii_case("MGF") {
                return Err(err(
                    g.pos,
                    format!("Geometry format '{f}' is not supported (expected MGF)"),
                ));
            }
        }
        if let Some(b) = g.child("MGFblock") {
            if !b.text.trim().is_empty() {
                bsdf.geometry = Some(Geometry {
                    unit: b.attr("unit").unwrap_or("").to_string(),
                    mgf: b.text.clone(),
                });
            }
        }
    }
    if let Some(dd) = layer.child("DataDefinition") {
        if let Some(s) = dd.child("IncidentDataStructure") {
            bsdf.structure = Some(match s.text.trim().to_ascii_lowercase().as_str() {
                "columns" => DataStructure::Columns,
                "rows" => DataStructure::Rows,
                "tensortree3" => DataStructure::TensorTree3,
                "tensortree4" => DataStructure::TensorTree4,
                o => return Err(err(s.pos, format!("unknown IncidentDataStructure '{o}'"))),
            });
        }
        for ab in dd.children_named("AngleBasis") {
            bsdf.bases
                .push(angle_basis(ab).map_err(|(p, m)| err(p, m))?);
        }
    }
    for wd in layer.children_named("WavelengthData") {
        let wl = wd
            .child("Wavelength")
            .ok_or_else(|| err(wd.pos, "WavelengthData without <Wavelength>".into()))?;
        let wavelength = Wavelength::parse(&wl.text);
        for blk in wd.children_named("WavelengthDataBlock") {
            let dir_el = blk
                .child("WavelengthDataDirection")
                .ok_or_else(|| err(blk.pos, "missing <WavelengthDataDirection>".into()))?;
            let Some(direction) = Direction::parse(&dir_el.text) else {
                // Radiance skips blocks with an unknown direction; so do we.
                continue;
            };
            let sd = blk
                .child("ScatteringData")
                .ok_or_else(|| err(blk.pos, "missing <ScatteringData>".into()))?;
            let structure = bsdf.structure.ok_or_else(|| {
                err(
                    blk.pos,
                    "missing <IncidentDataStructure> in <DataDefinition>".into(),
                )
            })?;
            let data = match structure {
                DataStructure::TensorTree3 | DataStructure::TensorTree4 => {
                    let rank = if structure == DataStructure::TensorTree3 {
                        3
                    } else {
                        4
                    };
                    let check: ValueCheck = if wavelength == Wavelength::CieV {
                        &chroma_v
                    } else {
                        &|_| Ok(())
                    };
                    let t = TensorTree::parse_checked(rank, &sd.text, check).map_err(|e| {
                        err(
                            sd.text_pos + e.offset,
                            format!(
                                "ScatteringData ({} {}): {}",
                                wavelength.xml_name(),
                                direction.xml_name(),
                                e.message
                            ),
                        )
                    })?;
                    BlockData::Tree(t)
                }
                DataStructure::Columns | DataStructure::Rows => {
                    let basis = |tag: &str| -> Result<KlemsBasis, XmlError> {
                        let el = blk
                            .child(tag)
                            .ok_or_else(|| err(blk.pos, format!("missing <{tag}>")))?;
                        find_basis(&bsdf.bases, el.text.trim()).ok_or_else(|| {
                            err(
                                el.pos,
                                format!("undefined angle basis '{}'", el.text.trim()),
                            )
                        })
                    };
                    let incident = basis("ColumnAngleBasis")?;
                    let outgoing = basis("RowAngleBasis")?;
                    let values = numbers(text, sd, incident.len() * outgoing.len(), &err)?;
                    let (ni, no) = (incident.len(), outgoing.len());
                    let values = if structure == DataStructure::Rows {
                        let mut v = vec![0.0; ni * no];
                        for (k, x) in values.into_iter().enumerate() {
                            v[(k % no) * ni + k / no] = x;
                        }
                        v
                    } else {
                        values
                    };
                    BlockData::Klems(KlemsMatrix {
                        incident,
                        outgoing,
                        values,
                    })
                }
            };
            let data_type = blk
                .child_text("ScatteringDataType")
                .unwrap_or("")
                .to_string();
            bsdf.blocks.push(Block {
                wavelength: wavelength.clone(),
                direction,
                data_type,
                data,
            });
        }
    }
    Ok(bsdf)
}

/// A CIE v′ value of a colour tree must give a chromaticity: v′ = 0 divides by zero when it is
/// turned into CIE (x, y), and v′ ≥ 0.75 + 0.375·u′ makes the divisor 6u′ − 16v′ + 12 zero or
/// negative (u′ ≥ 0, so v′ < 0.75 keeps it positive for every u′; colours of real light have
/// v′ below 0.6). Radiance 6.0a prints NaN or negative Lambertian XYZ for such files.
fn chroma_v(v: f64) -> Result<(), String> {
    if v > 0.0 && v < 0.75 {
        Ok(())
    } else {
        Err(format!(
            "CIE v' value {v} outside (0, 0.75): no chromaticity (expected v' of a colour, below 0.6)"
        ))
    }
}

fn leading_comments(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(i) = rest.find("<!--") {
        if rest[..i].contains("<WindowElement") {
            break;
        }
        let Some(j) = rest[i..].find("-->") else {
            break;
        };
        out.push(rest[i + 4..i + j].trim().to_string());
        rest = &rest[i + j + 3..];
    }
    out
}

fn find_basis(bases: &[KlemsBasis], name: &str) -> Option<KlemsBasis> {
    if let Some(b) = KlemsBasis::by_name(name) {
        return Some(b.clone());
    }
    bases
        .iter()
        .find(|b| b.name().eq_ignore_ascii_case(name))
        .cloned()
}

fn unit_factor(unit: &str) -> Option<f64> {
    Some(match unit.trim().to_ascii_lowercase().as_str() {
        "" | "meter" | "meters" => 1.0,
        "foot" | "feet" => 0.3048,
        "inch" | "inches" => 0.0254,
        "centimeter" | "centimeters" => 0.01,
        "millimeter" | "millimeters" => 0.001,
        _ => return None,
    })
}

/// Metres per unit for an MGF/dimension `unit` attribute (Radiance's names; None if unknown).
pub fn metres_per_unit(unit: &str) -> Option<f64> {
    unit_factor(unit)
}

fn length(m: &Element, tag: &str) -> Result<Option<f64>, (usize, String)> {
    let Some(el) = m.child(tag) else {
        return Ok(None);
    };
    let t = el.text.trim();
    if t.is_empty() {
        return Ok(None);
    }
    let v: f64 = t
        .parse()
        .map_err(|_| (el.pos, format!("<{tag}> '{t}' is not a number")))?;
    let unit = el.attr("unit").unwrap_or("");
    let f =
        unit_factor(unit).ok_or_else(|| (el.pos, format!("<{tag}> has unknown unit '{unit}'")))?;
    if !(v >= 0.0 && v.is_finite()) {
        return Err((
            el.pos,
            format!("<{tag}> must be a non-negative number, not {t}"),
        ));
    }
    Ok(Some(v * f))
}

fn angle_basis(ab: &Element) -> Result<KlemsBasis, (usize, String)> {
    let name = ab
        .child_text("AngleBasisName")
        .ok_or((ab.pos, "AngleBasis without <AngleBasisName>".to_string()))?;
    if let Some(b) = KlemsBasis::by_name(name) {
        return Ok(b.clone()); // Radiance uses its own definition of the standard bases.
    }
    let mut rings = Vec::new();
    let mut prev_upper = 0.0;
    for blk in ab.children_named("AngleBasisBlock") {
        let num = |el: Option<&Element>, what: &str| -> Result<f64, (usize, String)> {
            let el = el.ok_or((blk.pos, format!("AngleBasisBlock without <{what}>")))?;
            el.text.trim().parse().map_err(|_| {
                (
                    el.pos,
                    format!("<{what}> '{}' is not a number", el.text.trim()),
                )
            })
        };
        let bounds = blk.child("ThetaBounds");
        let upper = num(bounds.and_then(|b| b.child("UpperTheta")), "UpperTheta")?;
        let lower = num(bounds.and_then(|b| b.child("LowerTheta")), "LowerTheta")?;
        if (lower - prev_upper).abs() > 1e-6 * prev_upper.max(1.0) {
            return Err((
                blk.pos,
                format!("LowerTheta {lower} does not equal the previous UpperTheta {prev_upper}"),
            ));
        }
        let n = num(blk.child("nPhis"), "nPhis")?;
        if n < 1.0 || n.fract() != 0.0 {
            return Err((
                blk.pos,
                format!("nPhis must be a positive integer, not {n}"),
            ));
        }
        rings.push((upper, n as usize));
        prev_upper = upper;
    }
    KlemsBasis::from_bounds(name, &rings)
        .map_err(|e| (ab.pos, format!("angle basis '{name}': {e}")))
}

fn numbers<F>(text: &str, sd: &Element, want: usize, err: &F) -> Result<Vec<f64>, XmlError>
where
    F: Fn(usize, String) -> XmlError,
{
    let mut out = Vec::with_capacity(want);
    let s = sd.text.as_bytes();
    let mut i = 0;
    while out.len() < want {
        while i < s.len() && (s[i].is_ascii_whitespace() || s[i] == b',') {
            i += 1;
        }
        if i >= s.len() {
            let _ = text;
            return Err(err(
                sd.text_pos + sd.text.len(),
                format!("ScatteringData has {} values, expected {want}", out.len()),
            ));
        }
        let start = i;
        while i < s.len() && !(s[i].is_ascii_whitespace() || s[i] == b',') {
            i += 1;
        }
        let tok = &sd.text[start..i];
        let v: f64 = tok.parse().map_err(|_| {
            err(
                sd.text_pos + start,
                format!("ScatteringData value '{tok}' is not a number"),
            )
        })?;
        if !v.is_finite() {
            return Err(err(
                sd.text_pos + start,
                format!("ScatteringData value '{tok}' is not finite"),
            ));
        }
        if v < 0.0 {
            return Err(err(
                sd.text_pos + start,
                format!("ScatteringData value {tok} is negative (a BSDF is >= 0)"),
            ));
        }
        out.push(v);
    }
    Ok(out)
}
