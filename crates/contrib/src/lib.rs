//! fenestra-contrib: the contribution tracer behind rtcontrib/rcontrib (bins through .cal
//! expressions, `-c` accumulation, output streams and headers, Monte Carlo standard errors)
//! and the Klems window sampler behind genklemsamp.

pub mod bins;
pub mod budget;
pub mod engine;
pub mod klemsamp;
pub mod native;
pub mod output;
pub mod rflux;
pub mod run;
