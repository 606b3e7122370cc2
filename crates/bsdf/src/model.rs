//! The contents of a BSDF XML file (LBNL/WINDOW 6 schema), named as the file names them.

use crate::klems::KlemsBasis;
use crate::tree::TensorTree;

/// `WavelengthDataDirection`, as the XML file names it (WINDOW's front = exterior side).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Direction {
    /// `Transmission Front`: light from the XML front (exterior) to the back (Radiance `tb`).
    TransmissionFront,
    /// `Transmission Back` (Radiance `tf`).
    TransmissionBack,
    /// `Reflection Front` (Radiance `rb`).
    ReflectionFront,
    /// `Reflection Back` (Radiance `rf`).
    ReflectionBack,
}

impl Direction {
    /// Parses the XML text (case-insensitive, surrounding white space ignored).
    pub fn parse(s: &str) -> Option<Self> {
        let s = s.trim().to_ascii_lowercase();
        let s: Vec<&str> = s.split_whitespace().collect();
        match s.as_slice() {
            ["transmission", "front"] => Some(Direction::TransmissionFront),
            ["transmission", "back"] => Some(Direction::TransmissionBack),
            ["reflection", "front"] => Some(Direction::ReflectionFront),
            ["reflection", "back"] => Some(Direction::ReflectionBack),
            _ => None,
        }
    }

    /// The XML spelling.
    pub fn xml_name(self) -> &'static str {
        match self {
            Direction::TransmissionFront => "Transmission Front",
            Direction::TransmissionBack => "Transmission Back",
            Direction::ReflectionFront => "Reflection Front",
            Direction::ReflectionBack => "Reflection Back",
        }
    }

    /// All four, in the order Radiance's tools list them.
    pub const ALL: [Direction; 4] = [
        Direction::TransmissionFront,
        Direction::TransmissionBack,
        Direction::ReflectionFront,
        Direction::ReflectionBack,
    ];
}

/// The `Wavelength` of a data block.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Wavelength {
    /// `Visible` (also `CIE-Y`): photopic, CIE Y.
    Visible,
    /// `CIE-X`.
    CieX,
    /// `CIE-Z`.
    CieZ,
    /// `CIE-u` (tensor trees: u′ chromaticity).
    CieU,
    /// `CIE-v` (tensor trees: v′ chromaticity).
    CieV,
    /// `Solar`.
    Solar,
    /// `NIR`.
    Nir,
    /// Anything else, as written.
    Other(String),
}

impl Wavelength {
    /// Parses the XML text (case-insensitive).
    pub fn parse(s: &str) -> Self {
        match s.trim().to_ascii_lowercase().as_str() {
            "visible" | "cie-y" => Wavelength::Visible,
            "cie-x" => Wavelength::CieX,
            "cie-z" => Wavelength::CieZ,
            "cie-u" => Wavelength::CieU,
            "cie-v" => Wavelength::CieV,
            "solar" => Wavelength::Solar,
            "nir" => Wavelength::Nir,
            _ => Wavelength::Other(s.trim().to_string()),
        }
    }

    /// The XML spelling.
    pub fn xml_name(&self) -> &str {
        match self {
            Wavelength::Visible => "Visible",
            Wavelength::CieX => "CIE-X",
            Wavelength::CieZ => "CIE-Z",
            Wavelength::CieU => "CIE-u",
            Wavelength::CieV => "CIE-v",
            Wavelength::Solar => "Solar",
            Wavelength::Nir => "NIR",
            Wavelength::Other(s) => s,
        }
    }
}

/// `IncidentDataStructure`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DataStructure {
    /// Klems matrix, one text row per outgoing direction (what WINDOW and Radiance write).
    Columns,
    /// Klems matrix, one text row per incident direction.
    Rows,
    /// Isotropic tensor tree (rank 3).
    TensorTree3,
    /// Anisotropic tensor tree (rank 4).
    TensorTree4,
}

/// A Klems BSDF matrix (sr⁻¹), stored `[outgoing][incident]`.
#[derive(Clone, Debug, PartialEq)]
pub struct KlemsMatrix {
    /// Basis of the incident directions (`ColumnAngleBasis`).
    pub incident: KlemsBasis,
    /// Basis of the outgoing directions (`RowAngleBasis`).
    pub outgoing: KlemsBasis,
    /// Values, row-major: `values[o * incident.len() + i]`.
    pub values: Vec<f64>,
}

impl KlemsMatrix {
    /// BSDF value for outgoing patch `o`, incident patch `i`.
    pub fn get(&self, o: usize, i: usize) -> f64 {
        self.values[o * self.incident.len() + i]
    }

    /// Directional-hemispherical total for incident patch `i`: Σ_o BSDF·λ_out(o).
    pub fn hemispherical(&self, i: usize) -> f64 {
        (0..self.outgoing.len())
            .map(|o| self.get(o, i) * self.outgoing.projected_solid_angle(o).unwrap_or(0.0))
            .sum()
    }
}

/// The data of one block.
#[derive(Clone, Debug, PartialEq)]
pub enum BlockData {
    /// Klems matrix.
    Klems(KlemsMatrix),
    /// Tensor tree.
    Tree(TensorTree),
}

/// One `WavelengthDataBlock` (with its `Wavelength`).
#[derive(Clone, Debug, PartialEq)]
pub struct Block {
    /// Spectral channel.
    pub wavelength: Wavelength,
    /// Which side and scattering.
    pub direction: Direction,
    /// `ScatteringDataType` as written (informative).
    pub data_type: String,
    /// The values.
    pub data: BlockData,
}

/// Embedded geometry (`<Geometry format="MGF">`).
#[derive(Clone, Debug, PartialEq)]
pub struct Geometry {
    /// `MGFblock unit` attribute (empty if absent: metres).
    pub unit: String,
    /// The MGF text, unchanged.
    pub mgf: String,
}

/// A BSDF XML file.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Bsdf {
    /// `Material/Name`.
    pub name: String,
    /// `Material/Manufacturer`.
    pub manufacturer: String,
    /// `Material/DeviceType`.
    pub device_type: String,
    /// `Material/Width` in metres.
    pub width: Option<f64>,
    /// `Material/Height` in metres.
    pub height: Option<f64>,
    /// `Material/Thickness` in metres.
    pub thickness: Option<f64>,
    /// `IncidentDataStructure` (None only for a file with no data definition).
    pub structure: Option<DataStructure>,
    /// Angle bases defined in the file (built-in names resolve to Radiance's definitions).
    pub bases: Vec<KlemsBasis>,
    /// The embedded geometry, if any.
    pub geometry: Option<Geometry>,
    /// All data blocks in file order, including ones Radiance ignores (Solar, NIR).
    pub blocks: Vec<Block>,
    /// Comments found before the root element (e.g. `Created by: genBSDF …`).
    pub comments: Vec<String>,
}

impl Bsdf {
    /// The block for a direction and wavelength.
    pub fn block(&self, direction: Direction, wavelength: &Wavelength) -> Option<&Block> {
        self.blocks
            .iter()
            .find(|b| b.direction == direction && &b.wavelength == wavelength)
    }

    /// The Klems matrix for a direction and wavelength.
    pub fn klems(&self, direction: Direction, wavelength: &Wavelength) -> Option<&KlemsMatrix> {
        match &self.block(direction, wavelength)?.data {
            BlockData::Klems(m) => Some(m),
            BlockData::Tree(_) => None,
        }
    }

    /// True if the file holds CIE-X and CIE-Z (or CIE-u/v) blocks besides Visible.
    pub fn has_colour(&self) -> bool {
        self.blocks
            .iter()
            .any(|b| matches!(b.wavelength, Wavelength::CieX | Wavelength::CieU))
    }
}
