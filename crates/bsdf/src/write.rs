//! Writing BSDF XML (Klems matrices, or tensor trees) in the layout Radiance's `wrapBSDF`
//! produces.

use std::fmt::Write;

use crate::klems::KlemsBasis;
use crate::model::{Block, BlockData, Bsdf, DataStructure, Wavelength};

/// Why a BSDF cannot be written as Klems XML.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum WriteError {
    /// A block holds tensor-tree data.
    #[error("block {0} holds tensor-tree data; only Klems matrices can be written")]
    TensorTree(usize),
    /// A tensor-tree file with a block of another kind.
    #[error("block {0} is not a tensor tree in a tensor-tree file")]
    Mixed(usize),
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// The detector spectrum of a block of wavelength `w` (Y but for the X and Z blocks).
fn detector_spectrum(w: &Wavelength) -> &'static str {
    match w {
        Wavelength::CieX => "ASTM E308 1931 X.dsp",
        Wavelength::CieZ => "ASTM E308 1931 Z.dsp",
        _ => "ASTM E308 1931 Y.dsp",
    }
}

/// Opens the `WavelengthData` of block `blk` through its `<ScatteringData>` line: `detector`
/// names its detector spectrum (None: no such line) and `bases` holds its angle-basis lines.
fn open_block(out: &mut String, blk: &Block, detector: Option<&str>, bases: &str) {
    let _ = write!(
        out,
        "\t<WavelengthData>\n\t\t<LayerNumber>System</LayerNumber>\n\t\t<Wavelength unit=\"Integral\">{}</Wavelength>\n\t\t<SourceSpectrum>CIE Illuminant D65 1nm.ssp</SourceSpectrum>\n",
        escape(blk.wavelength.xml_name())
    );
    if let Some(d) = detector {
        let _ = writeln!(out, "\t\t<DetectorSpectrum>{d}</DetectorSpectrum>");
    }
    let _ = writeln!(
        out,
        "\t\t<WavelengthDataBlock>\n\t\t\t<WavelengthDataDirection>{}</WavelengthDataDirection>\n{bases}\t\t\t<ScatteringDataType>{}</ScatteringDataType>\n\t\t\t<ScatteringData>",
        blk.direction.xml_name(),
        if blk.data_type.is_empty() { "BTDF" } else { &blk.data_type }
    );
}

/// Closes a block [`open_block`] opened, after its data.
const CLOSE_BLOCK: &str =
    "\t\t\t</ScatteringData>\n\t\t</WavelengthDataBlock>\n\t</WavelengthData>\n";

fn basis_xml(out: &mut String, b: &KlemsBasis) {
    let _ = writeln!(
        out,
        "\t\t<AngleBasis>\n\t\t\t<AngleBasisName>{}</AngleBasisName>",
        escape(b.name())
    );
    for (i, r) in b.rings().iter().enumerate() {
        let theta = if i == 0 {
            0.0
        } else {
            0.5 * (r.theta_lo + r.theta_hi)
        };
        let _ = writeln!(
            out,
            "\t\t\t<AngleBasisBlock>\n\t\t\t\t<Theta>{theta}</Theta>\n\t\t\t\t<nPhis>{}</nPhis>\n\t\t\t\t<ThetaBounds>\n\t\t\t\t\t<LowerTheta>{}</LowerTheta>\n\t\t\t\t\t<UpperTheta>{}</UpperTheta>\n\t\t\t\t</ThetaBounds>\n\t\t\t</AngleBasisBlock>",
            r.nphi, r.theta_lo, r.theta_hi
        );
    }
    out.push_str("\t\t</AngleBasis>\n");
}

/// Klems BSDF XML text for `b` (IncidentDataStructure `Columns`: one text line per outgoing
/// direction). Values are printed with `%.6e`-style precision; lengths in metres.
pub fn klems_xml(b: &Bsdf, comment: Option<&str>) -> Result<String, WriteError> {
    let mut out = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    if let Some(c) = comment {
        let _ = writeln!(out, "<!-- {} -->", c.replace("--", "- -"));
    }
    out.push_str("<WindowElement xmlns=\"http://windows.lbl.gov\" xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\" xsi:schemaLocation=\"http://windows.lbl.gov/BSDF-v1.4.xsd\">\n");
    out.push_str("<WindowElementType>System</WindowElementType>\n<FileType>BSDF</FileType>\n<Optical>\n<Layer>\n\t<Material>\n");
    let _ = writeln!(out, "\t\t<Name>{}</Name>", escape(&b.name));
    let _ = writeln!(
        out,
        "\t\t<Manufacturer>{}</Manufacturer>",
        escape(&b.manufacturer)
    );
    let dt = if b.device_type.is_empty() {
        "Other"
    } else {
        &b.device_type
    };
    let _ = writeln!(out, "\t\t<DeviceType>{}</DeviceType>", escape(dt));
    for (tag, v) in [
        ("Thickness", b.thickness),
        ("Width", b.width),
        ("Height", b.height),
    ] {
        if let Some(v) = v {
            let _ = writeln!(out, "\t\t<{tag} unit=\"meter\">{v}</{tag}>");
        }
    }
    out.push_str("\t</Material>\n");
    match &b.geometry {
        Some(g) => {
            let unit = if g.unit.is_empty() { "meter" } else { &g.unit };
            let _ = writeln!(
                out,
                "\t<Geometry format=\"MGF\"><MGFblock unit=\"{unit}\">{}</MGFblock></Geometry>",
                escape(&g.mgf)
            );
        }
        None => out.push_str("\t<Geometry></Geometry>\n"),
    }
    // tensor trees (genBSDF -t3/-t4): the structure, then each block's tree as its text
    if let Some(s @ (DataStructure::TensorTree3 | DataStructure::TensorTree4)) = b.structure {
        let name = if s == DataStructure::TensorTree3 {
            "TensorTree3"
        } else {
            "TensorTree4"
        };
        let _ = writeln!(
            out,
            "\t<DataDefinition>\n\t\t<IncidentDataStructure>{name}</IncidentDataStructure>\n\t</DataDefinition>"
        );
        for (k, blk) in b.blocks.iter().enumerate() {
            let BlockData::Tree(t) = &blk.data else {
                return Err(WriteError::Mixed(k));
            };
            // wrapBSDF writes no detector for the u′ and v′ trees
            let detector = match blk.wavelength {
                Wavelength::CieU | Wavelength::CieV => None,
                _ => Some(detector_spectrum(&blk.wavelength)),
            };
            let bases = "\t\t\t<AngleBasis>LBNL/Shirley-Chiu</AngleBasis>\n";
            open_block(&mut out, blk, detector, bases);
            t.write_text(&mut out);
            out.push_str(CLOSE_BLOCK);
        }
        out.push_str("</Layer>\n</Optical>\n</WindowElement>\n");
        return Ok(out);
    }
    out.push_str(
        "\t<DataDefinition>\n\t\t<IncidentDataStructure>Columns</IncidentDataStructure>\n",
    );
    let mut seen: Vec<&KlemsBasis> = Vec::new();
    for (k, blk) in b.blocks.iter().enumerate() {
        let BlockData::Klems(m) = &blk.data else {
            return Err(WriteError::TensorTree(k));
        };
        for basis in [&m.incident, &m.outgoing] {
            if !seen.iter().any(|s| s.name() == basis.name()) {
                seen.push(basis);
            }
        }
    }
    for basis in &seen {
        basis_xml(&mut out, basis);
    }
    out.push_str("\t</DataDefinition>\n");
    for blk in &b.blocks {
        let BlockData::Klems(m) = &blk.data else {
            continue;
        };
        let bases = format!(
            "\t\t\t<ColumnAngleBasis>{}</ColumnAngleBasis>\n\t\t\t<RowAngleBasis>{}</RowAngleBasis>\n",
            escape(m.incident.name()),
            escape(m.outgoing.name()),
        );
        let detector = detector_spectrum(&blk.wavelength);
        open_block(&mut out, blk, Some(detector), &bases);
        let ni = m.incident.len();
        for row in m.values.chunks(ni) {
            for v in row {
                let _ = write!(out, " {v:.6e}");
            }
            out.push('\n');
        }
        out.push_str(CLOSE_BLOCK);
    }
    out.push_str("</Layer>\n</Optical>\n</WindowElement>\n");
    Ok(out)
}

/// Convenience: the structure a written file declares.
pub const WRITTEN_STRUCTURE: DataStructure = DataStructure::Columns;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Block, Direction, KlemsMatrix};

    #[test]
    fn round_trip() {
        let inc = KlemsBasis::half().clone();
        let out = KlemsBasis::full().clone();
        let values: Vec<f64> = (0..inc.len() * out.len())
            .map(|k| (k % 97) as f64 * 0.125)
            .collect();
        let b = Bsdf {
            name: "a<b".into(),
            width: Some(0.5),
            blocks: vec![Block {
                wavelength: Wavelength::Visible,
                direction: Direction::TransmissionFront,
                data_type: "BTDF".into(),
                data: BlockData::Klems(KlemsMatrix {
                    incident: inc,
                    outgoing: out,
                    values,
                }),
            }],
            ..Default::default()
        };
        let text = klems_xml(&b, Some("test")).unwrap();
        let back = crate::read::parse(&text, "mem").unwrap();
        assert_eq!(back.blocks, b.blocks);
        assert_eq!(back.name, "a<b");
        assert_eq!(back.width, Some(0.5));
    }
}
