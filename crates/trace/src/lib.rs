//! fenestra-trace (skeleton; see docs/architecture.md).
