//! fenestra-trace: the ray-tracing core — f64 surfaces under an obvhs BVH, materials,
//! light sources, the Monte Carlo integrator (Radiance's `-aa 0` rules), contribution
//! tracking for rcontrib, and effect selection. See docs/architecture.md.

pub mod bvh;
pub mod polygon;
pub mod shape;
