//! pcomb's engine: inputs read (`input`), expressions over them (`expr`), the output
//! pixels computed and written (`combine`); the tool parses options and builds the header.

pub mod combine;
pub mod expr;
pub mod input;
