//! fenestra-scene (skeleton; see docs/architecture.md).
