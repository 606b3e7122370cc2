//! fenestra: Radiance-compatible daylighting tools. Each tool's logic lives in
//! [`tools`]; `src/bin/*.rs` only call [`fenestra_cli::main_with`].

pub mod docs;
pub mod tools;
