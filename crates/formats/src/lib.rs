//! fenestra-formats: Radiance file formats — the information header, matrices
//! (ascii, float, double, RGBE) with streaming readers and Radiance-exact writers,
//! pictures, resolution strings and views.

pub mod dimensions;
pub mod exr;
pub mod header;
pub mod matrix;
pub mod picture;
pub mod picture_rle;
pub mod png;
pub mod resolution;
pub mod rgbe;
pub mod view;
pub mod view_print;
pub mod view_rays;

pub use header::Header;
pub use matrix::{DataFormat, Matrix, MatrixInfo, MatrixReader, MatrixWriter, WriteOptions};
