//! fenestra-bsdf: Klems angle bases and BSDF data (LBNL/WINDOW 6 XML, Klems matrices and
//! tensor trees), as Radiance reads and uses them.

pub mod check;
mod dom;
pub mod klems;
pub mod model;
pub mod radiance;
pub mod read;
pub mod tree;
pub mod tree_klems;
pub(crate) mod tree_load;
pub mod tree_render;
pub mod write;

pub use klems::{Frame, KlemsBasis};
pub use model::{
    Block, BlockData, Bsdf, DataStructure, Direction, Geometry, KlemsMatrix, Wavelength,
};
pub use read::{parse, read_file, XmlError};
pub use tree::TensorTree;
