//! fenestra-sky (skeleton; see docs/architecture.md).
