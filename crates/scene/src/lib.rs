//! fenestra-scene: the scene model shared by every tracing tool, parsers for Radiance
//! scene descriptions (`.rad`, with `!command` lines, aliases and `void`) and MGF, the
//! `xform` transforms, and fenestra's compiled-scene format (written by `oconv`).

pub mod cfmt;
pub mod compiled;
mod mgf;
mod model;
mod rad;
pub mod radoct;
mod source;
pub mod transform;
pub mod types;
mod words;
pub mod xform;

pub use model::{Loc, Primitive, Scene};
pub use rad::{load, parse_str, Parser};
pub use source::{decode_text, decode_text_latin1, encode_text};
pub use words::parse_real;
