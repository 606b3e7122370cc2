//! rfluxmtx's model: senders and receivers marked with `#@rfluxmtx` directives, receivers
//! turned into rcontrib bin options, and sender-mode sample rays. The rfluxmtx tool runs
//! the contribution engine on these in one process (no child process, no pipe, no octree).

pub mod directive;
pub mod receiver;
pub mod sender;
pub mod surfaces;

pub use directive::{Basis, KlemsSize, Params};
pub use sender::{RayStream, Sampler};
pub use surfaces::{Group, Shape, Surface};
