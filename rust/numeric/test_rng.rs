//! A deterministic generator for tests (xorshift64*), without a `rand`
//! dependency: the same stream on every machine.

/// xorshift64* from a nonzero seed.
pub struct Rng(pub u64);

impl Rng {
    /// Uniform in `[0, 1)` (53 bits).
    pub fn next01(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in `[-1, 1)`.
    pub fn uniform(&mut self) -> f64 {
        2.0 * self.next01() - 1.0
    }

    /// `N` values uniform in `[-1, 1)`.
    pub fn vec<const N: usize>(&mut self) -> [f64; N] {
        std::array::from_fn(|_| self.uniform())
    }
}
