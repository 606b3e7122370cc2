//! The `-f` letters of number streams (rays in, values out, rcalc's and vwrays' records).

/// The format of a stream of numbers, as the `-f` letters name it (`a`, `f`, `d`): rays in
/// (`-fi`), values out (`-fo`), rcalc's and vwrays' records. One type for every tool that reads
/// or writes such streams; matrices and pictures have `fenestra_formats::DataFormat`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RayFormat {
    /// Text: six numbers per ray.
    Ascii,
    /// Six 32-bit floats.
    Float,
    /// Six 64-bit floats.
    Double,
}

impl RayFormat {
    /// The format of a `-f` letter (`a`, `f`, `d`).
    pub fn from_letter(c: char) -> Option<RayFormat> {
        match c {
            'a' => Some(RayFormat::Ascii),
            'f' => Some(RayFormat::Float),
            'd' => Some(RayFormat::Double),
            _ => None,
        }
    }

    /// The format's `-f` letter.
    pub fn letter(self) -> char {
        match self {
            RayFormat::Ascii => 'a',
            RayFormat::Float => 'f',
            RayFormat::Double => 'd',
        }
    }
}
