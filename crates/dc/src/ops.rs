//! Matrix operations for rmtxop (being written).
