//! fenestra-dc: daylight-coefficient algebra (V·T·D·s time stepping) and the matrix operations behind rmtxop.

pub mod errors;
pub mod metrics;
pub mod ops;
pub mod ops_errors;
pub mod rmtxop;
pub mod steps;
pub mod timestep;
