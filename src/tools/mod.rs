//! Tool entry points (one module per tool).
