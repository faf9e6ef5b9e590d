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
