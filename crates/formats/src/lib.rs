//! fenestra-formats (skeleton; see docs/architecture.md).
