//! Riemann theta functions with half-integer characteristics, (34)–(36).
