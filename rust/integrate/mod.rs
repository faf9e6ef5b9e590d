//! Time integration: Gauss–Legendre collocation (symplectic, preserves every
//! quadratic invariant), an explicit adaptive reference method, trajectories.
