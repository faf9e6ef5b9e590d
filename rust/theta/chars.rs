//! Half-integer characteristics `[a; b]`, `a, b ∈ {0,1}^g`, in FLINT's order,
//! and the paper's labelled table (35).

use crate::error::{Error, Result};

/// Largest genus accepted by the theta module (4^g outputs, 4^g·g² Hessian entries).
pub const MAX_GENUS: usize = 6;

/// Index of the characteristic `[a; b]` in FLINT's order (`acb_theta_all`,
/// python-flint `acb_mat.theta`): the bits `a_1 … a_g b_1 … b_g`, most
/// significant first, so for g = 2 the index is `8 a1 + 4 a2 + 2 b1 + b2`.
pub fn char_index(a: &[u8], b: &[u8]) -> Result<usize> {
    let g = a.len();
    if g == 0 || g > MAX_GENUS || b.len() != g {
        return Err(Error::InvalidArgument {
            what: "characteristic",
            reason: format!(
                "a and b must have the same length g in 1..={MAX_GENUS}; got {} and {}",
                a.len(),
                b.len()
            ),
        });
    }
    let mut idx = 0usize;
    for &bit in a.iter().chain(b.iter()) {
        if bit > 1 {
            return Err(Error::InvalidArgument {
                what: "characteristic",
                reason: format!("entries must be 0 or 1, got {bit}"),
            });
        }
        idx = (idx << 1) | bit as usize;
    }
    Ok(idx)
}

/// The characteristic `(a, b)` with FLINT index `idx` in genus `g` (inverse of [`char_index`]).
pub fn char_from_index(g: usize, idx: usize) -> (Vec<u8>, Vec<u8>) {
    let bit = |k: usize| ((idx >> (2 * g - 1 - k)) & 1) as u8;
    ((0..g).map(bit).collect(), (g..2 * g).map(bit).collect())
}

/// Parity `(-1)^{a·b}` of the characteristic with FLINT index `idx`:
/// `θ[a;b](-z) = (-1)^{a·b} θ[a;b](z)`. In genus 2, 10 are even and 6 odd.
pub fn parity(g: usize, idx: usize) -> i32 {
    let mask = (1usize << g) - 1;
    let a = (idx >> g) & mask;
    let b = idx & mask;
    if (a & b).count_ones() % 2 == 0 {
        1
    } else {
        -1
    }
}

/// The paper's table (35) exactly as printed: label and the 2×2 array
/// `[[x1, x2], [y1, y2]]` written under `θ[...]`.
///
/// Reading used by this crate (the usual Weber/Rosenhain one): the top row is
/// `a = (x1, x2)` and the bottom row is `b = (y1, y2)` in
/// `θ[a;b](z, τ) = Σ_n exp(iπ (n+a/2)ᵀτ(n+a/2) + 2πi (n+a/2)ᵀ(z+b/2))`, see
/// [`paper_char_index`]. With that reading θ, θ0, θ12, θ23, θ14, θ34 are even
/// and θ31, θ24 are odd; the table is carried as data and is not verified
/// against the curve here.
pub const PAPER_TABLE_35: [(&str, [[u8; 2]; 2]); 8] = [
    ("theta23", [[0, 0], [1, 1]]),
    ("theta31", [[1, 0], [1, 1]]),
    ("theta12", [[1, 0], [0, 0]]),
    ("theta14", [[1, 1], [1, 1]]),
    ("theta24", [[0, 1], [1, 1]]),
    ("theta34", [[0, 1], [0, 0]]),
    ("theta0", [[1, 1], [0, 0]]),
    ("theta", [[0, 0], [0, 0]]),
];

/// FLINT index of a label of table (35) (top row = a, bottom row = b), or `None`.
pub fn paper_char_index(label: &str) -> Option<usize> {
    PAPER_TABLE_35
        .iter()
        .find(|(l, _)| *l == label)
        .and_then(|(_, m)| char_index(&m[0], &m[1]).ok())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn index_roundtrip_and_flint_order() {
        assert_eq!(char_index(&[1, 0], &[0, 1]).unwrap(), 9);
        assert_eq!(char_index(&[0, 1], &[1, 0]).unwrap(), 6);
        for g in 1..=4 {
            for idx in 0..(1 << (2 * g)) {
                let (a, b) = char_from_index(g, idx);
                assert_eq!(char_index(&a, &b).unwrap(), idx);
            }
        }
        assert!(char_index(&[2, 0], &[0, 0]).is_err());
        assert!(char_index(&[0, 0], &[0]).is_err());
        assert!(char_index(&[], &[]).is_err());
    }

    #[test]
    fn six_odd_ten_even_in_genus_two() {
        let odd = (0..16).filter(|&i| parity(2, i) == -1).count();
        assert_eq!(odd, 6);
        // genus g: 2^{g-1}(2^g - 1) odd characteristics
        assert_eq!((0..64).filter(|&i| parity(3, i) == -1).count(), 28);
    }

    #[test]
    fn paper_table_parities_as_printed() {
        let odd: Vec<&str> = PAPER_TABLE_35
            .iter()
            .filter(|(l, _)| parity(2, paper_char_index(l).unwrap()) == -1)
            .map(|(l, _)| *l)
            .collect();
        assert_eq!(odd, vec!["theta31", "theta24"]);
        assert_eq!(paper_char_index("theta"), Some(0));
        assert_eq!(paper_char_index("theta0"), Some(12));
        assert_eq!(paper_char_index("theta99"), None);
    }
}
