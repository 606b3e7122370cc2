//! fenestra-bsdf (skeleton; see docs/architecture.md).
