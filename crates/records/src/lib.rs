//! Records of numbers as Radiance's rcalc and total read them: the number scanner
//! (`scan`), rcalc's engine (`rcalc`) and total's (`total`), called by the tools after
//! they have parsed their options.

pub mod rcalc;
mod scan;
pub mod total;
