//! fenestra-formats (skeleton; see docs/architecture.md).
pub mod picture;
pub mod picture_rle;
pub mod resolution;
pub mod rgbe;
pub mod view;
pub mod view_print;
