//! Small dense linear algebra on `Im τ` (`g ≤ 6`): the `LDLᵀ` factorisation
//! eliminating from the last coordinate, the inverse from it, the shortest
//! lattice vector by enumeration, and the smallest eigenvalue (messages).

/// `Q(u) = uᵀYu = Σ_i d_i (u_i + Σ_{k<i} l_ik u_k)²`: eliminate from the last
/// coordinate down (Schur complements), so that enumerating `u_1, …, u_{g-1}`
/// first leaves the last coordinate innermost. `None` if `Y` is not positive definite.
pub(super) fn ldl_reversed(y: &[f64], g: usize) -> Option<(Vec<f64>, Vec<f64>)> {
    let mut a = y.to_vec();
    let mut d = vec![0.0; g];
    let mut l = vec![0.0; g * g];
    for i in (0..g).rev() {
        let di = a[i * g + i];
        if di.is_nan() || di <= 0.0 {
            return None;
        }
        d[i] = di;
        for k in 0..i {
            l[i * g + k] = a[i * g + k] / di;
        }
        for k in 0..i {
            for m in 0..i {
                a[k * g + m] -= a[k * g + i] * a[i * g + m] / di;
            }
        }
    }
    Some((d, l))
}

/// Inverse of `Y` from its factorisation: solve `Y x = e_k` column by column.
pub(super) fn invert_spd(d: &[f64], l: &[f64], g: usize) -> Vec<f64> {
    // Y = Mᵀ D M with M unit lower triangular (M_ik = l_ik for k < i): Q(u) = Σ d_i (Mu)_i².
    let mut inv = vec![0.0; g * g];
    for col in 0..g {
        // solve Mᵀ v = e_col (upper triangular), then D w = v, then M x = w
        let mut v = vec![0.0; g];
        for i in (0..g).rev() {
            let mut s = if i == col { 1.0 } else { 0.0 };
            for k in i + 1..g {
                s -= l[k * g + i] * v[k];
            }
            v[i] = s;
        }
        for i in 0..g {
            v[i] /= d[i];
        }
        let mut x = vec![0.0; g];
        for i in 0..g {
            let mut s = v[i];
            for k in 0..i {
                s -= l[i * g + k] * x[k];
            }
            x[i] = s;
        }
        for i in 0..g {
            inv[i * g + col] = x[i];
        }
    }
    inv
}

/// Gram–Schmidt data of the Gram matrix `gm` (row-major `g×g`, basis
/// `b_0, …, b_{g-1}` in this order): `mu` (unit lower triangular) and the
/// squared lengths `bstar` of the orthogonalised vectors.
fn gram_schmidt(gm: &[f64], g: usize, mu: &mut [f64], bstar: &mut [f64]) {
    for i in 0..g {
        for j in 0..i {
            let s: f64 = (0..j)
                .map(|k| mu[j * g + k] * mu[i * g + k] * bstar[k])
                .sum();
            mu[i * g + j] = (gm[i * g + j] - s) / bstar[j];
        }
        mu[i * g + i] = 1.0;
        bstar[i] = gm[i * g + i]
            - (0..i)
                .map(|k| mu[i * g + k].powi(2) * bstar[k])
                .sum::<f64>();
    }
}

/// Most basis operations of [`lll_gram`]: for `g ≤ 6` an LLL reduction takes a
/// few dozen; the cap only keeps a degenerate (rounding-driven) cycle finite.
const LLL_MAX_OPS: usize = 10_000;

/// The Gram matrix `Bᵀ Y B` of an LLL-reduced basis `B` of `Z^g` for the form
/// `Y` (Lenstra, Lenstra and Lovász 1982, δ = 3/4, on the Gram matrix):
/// the same lattice, so the same shortest vector, but with nearly orthogonal
/// basis vectors, so that the enumeration of [`shortest_vector`] visits a few
/// points instead of the ~`Y_ii^{g/2}/√det Y` of an ill-conditioned `Y`
/// (`Y = 1 1ᵀ + 1e-12 I` at genus 4: ~1e18). `None` when the Gram–Schmidt
/// lengths stop being positive in double precision.
pub(super) fn lll_gram(y: &[f64], g: usize) -> Option<Vec<f64>> {
    let mut gm = y.to_vec();
    let (mut mu, mut bstar) = (vec![0.0; g * g], vec![0.0; g]);
    let mut k = 1;
    let mut ops = 0;
    while k < g {
        ops += 1;
        if ops > LLL_MAX_OPS {
            break;
        }
        // Size reduction of b_k against b_{k-1}, …, b_0: b_k -= q b_j.
        for j in (0..k).rev() {
            gram_schmidt(&gm, g, &mut mu, &mut bstar);
            let q = mu[k * g + j].round();
            if q != 0.0 && q.is_finite() {
                let (gkj, gjj) = (gm[k * g + j], gm[j * g + j]);
                for i in 0..g {
                    if i != k {
                        gm[k * g + i] -= q * gm[j * g + i];
                        gm[i * g + k] = gm[k * g + i];
                    }
                }
                gm[k * g + k] += q * q * gjj - 2.0 * q * gkj;
            }
        }
        gram_schmidt(&gm, g, &mut mu, &mut bstar);
        if !bstar.iter().all(|&b| b > 0.0 && b.is_finite()) {
            return None;
        }
        let m = mu[k * g + k - 1];
        if bstar[k] < (0.75 - m * m) * bstar[k - 1] {
            // Lovász condition fails: swap b_k and b_{k-1}.
            for i in 0..g {
                gm.swap(k * g + i, (k - 1) * g + i);
            }
            for i in 0..g {
                gm.swap(i * g + k, i * g + k - 1);
            }
            k = (k - 1).max(1);
        } else {
            k += 1;
        }
    }
    Some(gm)
}

/// `min_{n ∈ Z^g \ 0} nᵀYn` of the form `Y` (row-major), by the enumeration
/// of [`shortest_vector`] on an LLL-reduced basis ([`lll_gram`]); on the
/// basis as given (`d`, `l`, its factorisation) if the reduction fails.
pub(super) fn shortest_vector_reduced(y: &[f64], d: &[f64], l: &[f64], g: usize) -> f64 {
    if let Some((dr, lr)) = lll_gram(y, g).and_then(|gm| ldl_reversed(&gm, g)) {
        return shortest_vector(&dr, &lr, g);
    }
    shortest_vector(d, l, g)
}

/// `min_{n ∈ Z^g \ 0} nᵀYn` by enumerating `Q(n) ≤ min_i Y_ii`.
pub(super) fn shortest_vector(d: &[f64], l: &[f64], g: usize) -> f64 {
    // Y_ii = Q(e_i); reconstruct it from the factorisation.
    let q_of = |n: &[f64]| -> f64 {
        (0..g)
            .map(|i| {
                let t: f64 = n[i] + (0..i).map(|k| l[i * g + k] * n[k]).sum::<f64>();
                d[i] * t * t
            })
            .sum()
    };
    let mut best = f64::INFINITY;
    for i in 0..g {
        let mut e = vec![0.0; g];
        e[i] = 1.0;
        best = best.min(q_of(&e));
    }
    let mut n = vec![0i64; g];
    fn rec(
        i: usize,
        partial: f64,
        n: &mut Vec<i64>,
        d: &[f64],
        l: &[f64],
        g: usize,
        best: &mut f64,
    ) {
        let t: f64 = (0..i).map(|k| l[i * g + k] * n[k] as f64).sum();
        let rem = *best * (1.0 + 1e-12) - partial;
        if rem < 0.0 {
            return;
        }
        let h = (rem / d[i]).sqrt();
        let lo = (-t - h).ceil() as i64;
        let hi = (-t + h).floor() as i64;
        for v in lo..=hi {
            n[i] = v;
            let dv = v as f64 + t;
            let part = partial + d[i] * dv * dv;
            if i + 1 < g {
                rec(i + 1, part, n, d, l, g, best);
            } else if n.iter().any(|&c| c != 0) && part < *best {
                *best = part;
            }
        }
        n[i] = 0;
    }
    rec(0, 0.0, &mut n, d, l, g, &mut best);
    best
}

/// Smallest eigenvalue of the symmetric `g×g` matrix `y` (for error messages).
pub(super) fn min_eigenvalue(y: &[f64], g: usize) -> f64 {
    let m = nalgebra::DMatrix::from_row_slice(g, g, y);
    let m = 0.5 * (&m + m.transpose());
    m.symmetric_eigenvalues()
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `Y = 1 1ᵀ + ε I`: shortest vector `e_i − e_j`, `Q = 2ε`.
    fn ones_plus(g: usize, eps: f64) -> Vec<f64> {
        (0..g * g)
            .map(|k| 1.0 + if k / g == k % g { eps } else { 0.0 })
            .collect()
    }

    #[test]
    fn the_reduced_enumeration_finds_the_same_shortest_vector() {
        // Well-conditioned forms: the plain enumeration is cheap and exact.
        let forms: [(usize, Vec<f64>); 3] = [
            (2, vec![1.1, 0.4, 0.4, 1.3]),
            (3, vec![2.0, 0.9, -0.3, 0.9, 1.5, 0.2, -0.3, 0.2, 0.7]),
            (3, ones_plus(3, 1e-3)),
        ];
        for (g, y) in forms {
            let (d, l) = ldl_reversed(&y, g).unwrap();
            let plain = shortest_vector(&d, &l, g);
            let reduced = shortest_vector_reduced(&y, &d, &l, g);
            assert!(
                (plain - reduced).abs() <= 1e-12 * plain,
                "{plain} vs {reduced}"
            );
        }
    }

    #[test]
    fn an_ill_conditioned_form_is_reduced_in_microseconds() {
        // The plain enumeration visits ~1e18 points here (hours).
        for g in [3, 4, 6] {
            let y = ones_plus(g, 1e-12);
            let (d, l) = ldl_reversed(&y, g).unwrap();
            let t = std::time::Instant::now();
            let q = shortest_vector_reduced(&y, &d, &l, g);
            assert!(t.elapsed().as_secs_f64() < 0.1, "{:?}", t.elapsed());
            // 2e-12, to the ~1e-16 absolute rounding of the entries of Y.
            assert!((q - 2e-12).abs() < 1e-15, "g = {g}: {q:e}");
        }
    }
}
