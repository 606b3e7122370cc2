//! fenestra-illum: mkillum's engine. A scene description is filtered: surfaces selected by
//! `#@mkillum` directives are sampled from their front (the room side) through to their
//! back with the library tracer, and replaced by an `illum` (or `light`) material whose
//! `brightdata`/`colordata` distribution over `illum.cal` holds the radiance seen through
//! them; everything else passes through.

pub mod bsdf_mode;
pub mod directives;
pub mod filter;
pub mod geometry;
pub mod sample;
pub mod write;

pub use directives::Settings;
pub use filter::Filter;

/// Radiance's luminance weights of its RGB primaries (`bright()`).
pub fn bright(c: [f64; 3]) -> f64 {
    0.265_074_126 * c[0] + 0.670_114_631 * c[1] + 0.064_811_243 * c[2]
}
