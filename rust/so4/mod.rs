//! The Euler–Frahm top on so(4) and so(n): vector field (1), Poisson bracket (3),
//! Hamiltonian (4), integrals (6)–(7), Manakov's coefficients (2).
