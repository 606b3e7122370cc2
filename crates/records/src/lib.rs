//! Records of numbers evaluated one by one, as Radiance's rcalc, total and pcomb do: the
//! number scanner (`scan`), rcalc's engine (`rcalc`), total's (`total`) and pcomb's
//! (`pcomb`: pixels of pictures), called by the tools after they have parsed their options.

#![warn(missing_docs)]

pub mod pcomb;
pub mod rcalc;
mod scan;
pub mod total;
