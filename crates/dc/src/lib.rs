//! fenestra-dc (skeleton; see docs/architecture.md).
