//! Numbers in input words as C's `atof` reads them (fenestra_cfmt's).

pub use fenestra_cfmt::atof;
