//! fenestra-cli (skeleton; see docs/architecture.md).
