//! fenestra-calc (skeleton; see docs/architecture.md).
