//! fenestra-dc: daylight-coefficient algebra (V·T·D·s time stepping) and the matrix operations behind rmtxop.

pub mod errors;
pub mod metrics;
pub mod metrics_input;
pub mod ops;
pub mod ops_errors;
pub mod replicas;
pub mod rmtxop;
pub mod steps;
pub mod timestep;
