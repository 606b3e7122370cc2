//! C `printf("%.Ng")` formatting of numbers, as rcalc prints them (fenestra_cfmt's).

pub use fenestra_cfmt::{fmt_g, push_g_bytes as push_g};
