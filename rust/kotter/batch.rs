//! Many states at once, as the Python layer hands them over: each row mapped
//! by [`kotter`] (or, along one level set, by [`kotter_along`]), the fields
//! gathered into row-major arrays, and one policy for failing rows — masked
//! (NaN fields, `ok = false`) or the first failure returned with its row.

use super::{kotter, kotter_along_step, kotter_constants, KotterState, C};
use crate::error::{Error, Result};
use crate::numeric::alloc::{check_size, try_with_capacity};
use crate::numeric::cancel::Cancel;

/// Bytes of one row of a [`KotterBatch`]: 4 doubles, 85 complex numbers,
/// 5 branch bytes and the `ok` flag (the sizes of [`KotterBatch::with_capacity`]).
pub const ROW_BYTES: usize = 4 * 8 + 85 * 16 + 5 + 1;

/// The fields of `n` mapped states, row-major with leading axis `n` (the
/// arrays of `manakov.Kotter`); see [`KotterState`] and
/// [`super::KotterConstants`] for each field.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct KotterBatch {
    /// Rows.
    pub n: usize,
    /// `(n, 4)`: the integrals `h`.
    pub h: Vec<f64>,
    /// `(n, 4)`: the roots `s_p`, `σ_p`, `√F'(s_p)`.
    pub s: Vec<C>,
    pub sigma: Vec<C>,
    pub sqrt_fprime: Vec<C>,
    /// `(n, 4, 3)`: `l^(p)` (20).
    pub l_p: Vec<C>,
    /// `(n, 3, 3)`: `Δ_j^(p)` (25).
    pub delta_det: Vec<C>,
    /// `(n, 3)`: `ξ`, `η` (22), `√d_j`, `d_j` (26), `α_j … δ_j` (24), `A_j`, `B_j` (38)–(39).
    pub xi: Vec<C>,
    pub eta: Vec<C>,
    pub sqrt_d: Vec<C>,
    pub d: Vec<C>,
    pub alpha: Vec<C>,
    pub beta: Vec<C>,
    pub gamma: Vec<C>,
    pub delta: Vec<C>,
    pub a_coef: Vec<C>,
    pub b_coef: Vec<C>,
    /// `(n, 4)`: `(α, β, γ, δ)` of (39).
    pub abgd39: Vec<C>,
    /// `(n,)`: `ε`, `K` of (40), `P_0`, `g` and the points.
    pub eps: Vec<C>,
    pub k: Vec<C>,
    pub p0: Vec<C>,
    pub g: Vec<C>,
    pub z1: Vec<C>,
    pub y1: Vec<C>,
    pub z2: Vec<C>,
    pub y2: Vec<C>,
    /// `(n, 2, 5)`: the offsets `z_i − d_j`.
    pub zd: Vec<C>,
    /// `(n, 5)`: the branch of the `P_j` (0 in a masked row).
    pub branch: Vec<i8>,
    /// `(n,)`: the rows that succeeded.
    pub ok: Vec<bool>,
}

impl KotterBatch {
    /// Room for `n` rows, allocated fallibly after the whole batch is checked
    /// against the allocation budget ([`ROW_BYTES`] a row).
    fn with_capacity(n: usize) -> Result<Self> {
        check_size("l", n, ROW_BYTES)?;
        let v = |m: usize| try_with_capacity::<C>("Kotter fields", n * m);
        Ok(KotterBatch {
            n: 0,
            h: try_with_capacity("Kotter fields", 4 * n)?,
            s: v(4)?,
            sigma: v(4)?,
            sqrt_fprime: v(4)?,
            l_p: v(12)?,
            delta_det: v(9)?,
            xi: v(3)?,
            eta: v(3)?,
            sqrt_d: v(3)?,
            d: v(3)?,
            alpha: v(3)?,
            beta: v(3)?,
            gamma: v(3)?,
            delta: v(3)?,
            a_coef: v(3)?,
            b_coef: v(3)?,
            abgd39: v(4)?,
            eps: v(1)?,
            k: v(1)?,
            p0: v(1)?,
            g: v(1)?,
            z1: v(1)?,
            y1: v(1)?,
            z2: v(1)?,
            y2: v(1)?,
            zd: v(10)?,
            branch: try_with_capacity("Kotter fields", 5 * n)?,
            ok: try_with_capacity("Kotter fields", n)?,
        })
    }

    /// Appends the fields of one state.
    fn push(&mut self, st: &KotterState) {
        let k = &st.constants;
        self.h.extend_from_slice(&k.h);
        self.s.extend_from_slice(&k.s);
        self.sigma.extend_from_slice(&k.sigma);
        self.sqrt_fprime.extend_from_slice(&k.sqrt_fprime);
        self.l_p.extend(st.l_p.iter().flatten());
        self.delta_det.extend(k.delta_det.iter().flatten());
        self.xi.extend_from_slice(&st.xi);
        self.eta.extend_from_slice(&st.eta);
        self.sqrt_d.extend_from_slice(&k.sqrt_d);
        self.d.extend_from_slice(&k.d);
        self.alpha.extend_from_slice(&k.alpha);
        self.beta.extend_from_slice(&k.beta);
        self.gamma.extend_from_slice(&k.gamma);
        self.delta.extend_from_slice(&k.delta);
        self.a_coef.extend_from_slice(&k.a_coef);
        self.b_coef.extend_from_slice(&k.b_coef);
        self.abgd39.extend_from_slice(&k.abgd39);
        let p = &st.points;
        self.eps.push(k.eps);
        self.k.push(k.k);
        self.p0.push(st.p0);
        self.g.push(p.g);
        self.z1.push(p.z1);
        self.y1.push(p.y1);
        self.z2.push(p.z2);
        self.y2.push(p.y2);
        self.zd.extend(p.zd1.iter().chain(&p.zd2));
        self.branch.extend_from_slice(&p.eps);
        self.ok.push(true);
        self.n += 1;
    }

    /// Appends a masked row: every field NaN, the branch 0, `ok = false`.
    fn push_masked(&mut self) {
        let nan = C::new(f64::NAN, f64::NAN);
        self.h.extend([f64::NAN; 4]);
        for (v, m) in [
            (&mut self.s, 4),
            (&mut self.sigma, 4),
            (&mut self.sqrt_fprime, 4),
            (&mut self.l_p, 12),
            (&mut self.delta_det, 9),
            (&mut self.xi, 3),
            (&mut self.eta, 3),
            (&mut self.sqrt_d, 3),
            (&mut self.d, 3),
            (&mut self.alpha, 3),
            (&mut self.beta, 3),
            (&mut self.gamma, 3),
            (&mut self.delta, 3),
            (&mut self.a_coef, 3),
            (&mut self.b_coef, 3),
            (&mut self.abgd39, 4),
            (&mut self.eps, 1),
            (&mut self.k, 1),
            (&mut self.p0, 1),
            (&mut self.g, 1),
            (&mut self.z1, 1),
            (&mut self.y1, 1),
            (&mut self.z2, 1),
            (&mut self.y2, 1),
            (&mut self.zd, 10),
        ] {
            v.extend(std::iter::repeat_n(nan, m));
        }
        self.branch.extend([0i8; 5]);
        self.ok.push(false);
        self.n += 1;
    }
}

/// The states `rows` in Kötter's coordinates: with `l0`, every row mapped
/// with the constants of `l0`'s level set ([`kotter_along`]), otherwise each
/// row with its own ([`kotter`]).
///
/// Failing rows: with `mask`, their fields are NaN (branch 0) and `ok` is
/// false; without, the first failure is returned as
/// [`Error::InRow`] naming the row (a single row's error as it is).
///
/// Errors: those of [`kotter_constants`] for `l0` (whatever `mask`);
/// [`Error::TooLarge`] or [`Error::OutOfMemory`] for a batch whose fields
/// cannot be held (checked before the first row); [`Error::Interrupted`]
/// once `cancel` is cancelled (checked before every row, ~30–70 µs of work).
pub fn kotter_batch(
    a: &[f64; 4],
    rows: &[[f64; 6]],
    l0: Option<&[f64; 6]>,
    mask: bool,
    cancel: &Cancel,
) -> Result<KotterBatch> {
    let n = rows.len();
    let mut out = KotterBatch::with_capacity(n)?;
    let constants = l0.map(|l0| kotter_constants(a, l0)).transpose()?;
    let mut prev = None;
    for (row, l) in rows.iter().enumerate() {
        cancel.check()?;
        let r = match &constants {
            Some(k) => kotter_along_step(k, l, &mut prev),
            None => kotter(a, l),
        };
        match r {
            Ok(st) => out.push(&st),
            Err(_) if mask => out.push_masked(),
            Err(e) if n == 1 => return Err(e),
            Err(e) => {
                return Err(Error::InRow {
                    row,
                    rows: n,
                    source: Box::new(e),
                })
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    const A: [f64; 4] = [0.3, 1.1, 2.0, 3.7];
    const L0: [f64; 6] = [0.8, -0.3, 0.5, 1.1, -0.7, 0.2];

    /// A row that fails the reduction: m = n, self-dual.
    const SELF_DUAL: [f64; 6] = [1.0, -2.0, 3.0, 3.0, 2.0, 1.0];

    #[test]
    fn the_batch_holds_each_rows_state() {
        let rows = [L0, L0.map(|v| 0.9 * v)];
        let never = Cancel::never();
        let b = kotter_batch(&A, &rows, None, false, &never).unwrap();
        assert_eq!((b.n, b.ok.clone()), (2, vec![true, true]));
        for (i, r) in rows.iter().enumerate() {
            let st = kotter(&A, r).unwrap();
            assert_eq!(b.xi[3 * i..3 * i + 3], st.xi);
            assert_eq!(b.d[3 * i..3 * i + 3], st.constants.d);
            assert_eq!(b.g[i], st.points.g);
            assert_eq!(b.zd[10 * i..10 * i + 5], st.points.zd1);
            assert_eq!(b.branch[5 * i..5 * i + 5], st.points.eps);
            assert_eq!(b.l_p[12 * i + 3], st.l_p[1][0]);
        }
        // Along l0's level set: the states of kotter_along.
        let along = kotter_batch(&A, &rows[..1], Some(&L0), false, &never).unwrap();
        let st = super::super::kotter_along(&kotter_constants(&A, &L0).unwrap(), &rows[..1]);
        assert_eq!(along.z1[0], st[0].as_ref().unwrap().points.z1);
    }

    #[test]
    fn failing_rows_are_masked_or_named() {
        assert_eq!(SELF_DUAL.iter().map(|v| v * v).sum::<f64>(), 28.0);
        assert!(kotter(&A, &SELF_DUAL).is_err());
        let rows = [L0, SELF_DUAL, L0];
        let never = Cancel::never();
        let b = kotter_batch(&A, &rows, None, true, &never).unwrap();
        assert_eq!(b.ok, vec![true, false, true]);
        assert!(b.h[4..8].iter().all(|v| v.is_nan()));
        assert!(b.xi[3..6].iter().all(|v| v.re.is_nan() && v.im.is_nan()));
        assert_eq!(b.branch[5..10], [0; 5]);
        assert_eq!(b.xi[6..9], b.xi[0..3]);
        // Without the mask: the row and the reduction's own error.
        let own = kotter(&A, &SELF_DUAL).unwrap_err();
        let e = kotter_batch(&A, &rows, None, false, &never).unwrap_err();
        assert_eq!(e.to_string(), format!("row 1 of 3: {own}"));
        assert!(matches!(
            e,
            Error::InRow {
                row: 1,
                rows: 3,
                ..
            }
        ));
        // A single row: its error as it is.
        assert_eq!(kotter_batch(&A, &rows[1..2], None, false, &never), Err(own));
    }

    #[test]
    fn a_batch_stops_once_cancelled_and_refuses_sizes_over_the_budget() {
        let cancelled = Cancel::never();
        cancelled.cancel();
        let rows = [L0; 3];
        assert_eq!(
            kotter_batch(&A, &rows, None, false, &cancelled),
            Err(Error::Interrupted)
        );
        let n = crate::numeric::alloc::MAX_BYTES / ROW_BYTES + 1;
        assert!(matches!(
            KotterBatch::with_capacity(n),
            Err(Error::TooLarge { what: "l", .. })
        ));
    }
}
