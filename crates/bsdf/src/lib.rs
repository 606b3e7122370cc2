//! fenestra-bsdf: Klems angle bases and BSDF data (LBNL/WINDOW 6 XML, Klems matrices and
//! tensor trees), as Radiance reads and uses them.

pub mod klems;

pub use klems::{Frame, KlemsBasis};
