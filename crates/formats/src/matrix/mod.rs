//! Radiance matrix files: header + data in `ascii`, `float`, `double` or RGBE
//! (`32-bit_rle_rgbe`/`xyze`), read row by row ([`MatrixReader`]), whole
//! ([`Matrix`]), and written in Radiance's layouts ([`MatrixWriter`]).

mod ascii;
mod dense;
mod reader;
pub mod rgbe;
mod writer;

pub use ascii::{format_c_e, format_c_g};
pub use dense::Matrix;
pub use reader::{read_full, MatrixInfo, MatrixReader};
pub use writer::{header_bytes, AsciiLayout, MatrixWriter, WriteOptions};

/// How the numbers of a matrix are stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DataFormat {
    /// White-space separated text (`FORMAT=ascii`).
    Ascii,
    /// IEEE binary32 (`FORMAT=float`).
    Float,
    /// IEEE binary64 (`FORMAT=double`).
    Double,
    /// RGBE common-exponent pixels, one scanline per row (`FORMAT=32-bit_rle_rgbe`).
    Rgbe,
    /// Same encoding holding XYZ (`FORMAT=32-bit_rle_xyze`).
    Xyze,
}

impl DataFormat {
    /// The `FORMAT=` identifier.
    pub fn as_str(self) -> &'static str {
        match self {
            DataFormat::Ascii => "ascii",
            DataFormat::Float => "float",
            DataFormat::Double => "double",
            DataFormat::Rgbe => "32-bit_rle_rgbe",
            DataFormat::Xyze => "32-bit_rle_xyze",
        }
    }

    /// Parses a `FORMAT=` identifier (exact spelling, as Radiance requires).
    pub fn from_header(s: &str) -> Option<DataFormat> {
        Some(match s.trim() {
            "ascii" => DataFormat::Ascii,
            "float" => DataFormat::Float,
            "double" => DataFormat::Double,
            "32-bit_rle_rgbe" => DataFormat::Rgbe,
            "32-bit_rle_xyze" => DataFormat::Xyze,
            _ => return None,
        })
    }

    /// Bytes per number for binary IEEE formats (`None` for ascii and RGBE).
    pub fn value_size(self) -> Option<usize> {
        match self {
            DataFormat::Float => Some(4),
            DataFormat::Double => Some(8),
            _ => None,
        }
    }

    /// Whether this is a common-exponent picture encoding.
    pub fn is_picture(self) -> bool {
        matches!(self, DataFormat::Rgbe | DataFormat::Xyze)
    }

    /// Data alignment Radiance pads the header to when writing to a seekable file.
    pub fn alignment(self) -> usize {
        match self {
            DataFormat::Float => 4,
            DataFormat::Double => 8,
            _ => 1,
        }
    }
}

impl std::fmt::Display for DataFormat {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Whether this machine stores numbers big-endian.
pub const NATIVE_BIG_ENDIAN: bool = cfg!(target_endian = "big");

#[cfg(test)]
mod tests;
