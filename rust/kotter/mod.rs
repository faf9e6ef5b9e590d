//! Schottky's l(s), f(s) (12)–(17) and Kötter's reduction (18)–(26), (37)–(41).
