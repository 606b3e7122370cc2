//! fenestra-trace: the ray-tracing core — f64 surfaces under an obvhs BVH, materials,
//! light sources, the Monte Carlo integrator (Radiance's `-aa 0` rules), contribution
//! tracking for rcontrib, and effect selection. See docs/architecture.md and
//! docs/tools/rtrace.md.
//!
//! ```no_run
//! use fenestra_trace::{Tracer, TraceOptions};
//! let scene = fenestra_scene::load(&["room.rad"]).unwrap();
//! let opts = TraceOptions { ab: 2, ..TraceOptions::rtrace() };
//! let tracer = Tracer::new(&scene, &opts).unwrap();
//! let e = tracer.irradiance(0, glam::DVec3::new(1.0, 1.0, 0.8), glam::DVec3::Z);
//! ```

pub mod bsdf_mat;
pub mod bvh;
pub mod clip;
pub mod datafile;
pub mod illum_pattern;
pub mod material;
pub mod options;
pub mod pattern;
pub mod polygon;
pub mod rng;
pub mod shape;
pub mod sobol;
pub mod surface;
pub mod tracer;
pub mod waves;

pub use glam::DVec3;
pub use options::TraceOptions;
pub use tracer::{Contribution, DirectState, Effects, RayCounts, SourceLight, Tracer};
