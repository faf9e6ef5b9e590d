//! The genus-2 curve (8), Weierstrass' Wurzelfunktionen (27)–(28), periods and Abel map.
