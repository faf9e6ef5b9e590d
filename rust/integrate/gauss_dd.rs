//! Gauss–Legendre order 16 for Frahm's equations (1) on so(4) in
//! double-double: the integration that certifies the closed form where a
//! double integration cannot.
//!
//! Why: on states whose components span many orders of magnitude (near an
//! unstable rotation, where the small components grow and decay again along
//! the motion) every step of a double integration perturbs the small
//! components by `~1e-16 |l0|`, which is a large relative change of them, and
//! the motion's sensitivity carries it to the whole state: on such states of a
//! harsh random draw the Gauss–Legendre method in double is off by 1e-9 … 1
//! and heyoka in 80-bit long double by up to 0.5, while the closed form, which
//! takes the components as they are, agrees with a 113-bit (quad precision)
//! Taylor integration to ~1e-12 (`docs/degenerate.md`). In double-double the
//! rounding of a step is `~1e-32 |l0|`.
//!
//! The method is the 8-stage Gauss collocation method (order 16) of
//! [`super::gauss`], with the coefficients `a_ij`, `b_j` in double-double
//! ([`super::gauss_tables::A8_DD`]); its stage equations are solved by
//! fixed-point iteration until the increments reach double-double rounding.

use crate::error::{Error, Result};
use crate::numeric::cancel::Cancel;
use crate::numeric::dd::Dd;

use super::gauss_tables::{A8_DD, B8_DD};

const S: usize = 8;

/// Most fixed-point iterations per step: at the default step the
/// contraction ratio is ~0.2, and 106 bits take ~45 iterations.
const MAX_ITER: usize = 120;

/// The stage iteration has converged once every component's increment is
/// below this fraction of that component (double-double rounding is
/// ~1e-32). Per component: on states whose components span many orders of
/// magnitude, an increment small next to the largest component can still be
/// a large change of a small one, and the motion amplifies exactly those.
const STAGE_TOL: f64 = 1e-32;

/// Components below this fraction of the largest count as this fraction of
/// it in the convergence test (a component crossing zero has no relative
/// precision to reach).
const STAGE_FLOOR: f64 = 1e-12;

/// Where the increments stop shrinking (rounding), the iteration has
/// converged if they are below this: double-double's rounding of the field,
/// `~1e-32` of its largest terms, is at most `1e-20` of a component at the
/// floor.
const STAGE_STALL: f64 = 1e-18;

fn dd(p: [f64; 2]) -> Dd {
    Dd { hi: p[0], lo: p[1] }
}

/// The differences of the `c_ij` that (1) on so(4) needs
/// (as [`crate::so4::vector_field4_lanes`]), in double-double.
pub(crate) fn diffs(c: &[Dd; 6]) -> [Dd; 12] {
    let [c12, c13, c14, c23, c24, c34] = *c;
    [
        c23.sub(c13),
        c24.sub(c14),
        c23.sub(c12),
        c34.sub(c14),
        c24.sub(c12),
        c34.sub(c13),
        c13.sub(c12),
        c34.sub(c24),
        c14.sub(c12),
        c34.sub(c23),
        c14.sub(c13),
        c24.sub(c23),
    ]
}

/// (1) on so(4): `l̇_ij = Σ_{k ∉ {i,j}} l_ik l_kj (c_kj − c_ik)` in
/// double-double, `d` from [`diffs`].
pub(crate) fn field(d: &[Dd; 12], l: &[Dd; 6]) -> [Dd; 6] {
    let [l12, l13, l14, l23, l24, l34] = *l;
    let t = |x: Dd, y: Dd, c: Dd| x.mul(y).mul(c);
    [
        t(l13, l23, d[0]).add(t(l14, l24, d[1])).neg(),
        t(l12, l23, d[2]).sub(t(l14, l34, d[3])),
        t(l12, l24, d[4]).add(t(l13, l34, d[5])),
        t(l12, l13, d[6]).add(t(l24, l34, d[7])).neg(),
        t(l23, l34, d[9]).sub(t(l12, l14, d[8])),
        t(l13, l14, d[10]).add(t(l23, l24, d[11])).neg(),
    ]
}

/// One step of length `h` from `y`; `k` holds the stage derivatives (the
/// start of the iteration on entry, those of the step on return).
fn step(d: &[Dd; 12], y: &mut [Dd; 6], h: Dd, k: &mut [[Dd; 6]; S]) -> Result<()> {
    let ha: [[Dd; S]; S] = std::array::from_fn(|i| std::array::from_fn(|j| h.mul(dd(A8_DD[i][j]))));
    let ymax = y.iter().fold(0.0f64, |m, v| m.max(v.hi.abs()));
    let scale: [f64; 6] = std::array::from_fn(|q| y[q].hi.abs().max(STAGE_FLOOR * ymax));
    let mut last = f64::INFINITY;
    for iteration in 1..=MAX_ITER {
        let mut dmax = 0.0f64;
        let mut next = [[Dd::ZERO; 6]; S];
        for (i, ni) in next.iter_mut().enumerate() {
            let mut yi = *y;
            for (j, kj) in k.iter().enumerate() {
                for (v, kv) in yi.iter_mut().zip(kj) {
                    *v = v.add(ha[i][j].mul(*kv));
                }
            }
            *ni = field(d, &yi);
            for ((a, b), s) in ni.iter().zip(&k[i]).zip(&scale) {
                let inc = a.sub(*b).hi.abs() / s;
                // NaN is not skipped: it must fail the convergence test
                if inc > dmax || inc.is_nan() {
                    dmax = inc;
                }
            }
        }
        *k = next;
        let dmax = dmax * h.hi.abs();
        if !dmax.is_finite() {
            break;
        }
        // Converged, or stalled at rounding (the increments stopped shrinking
        // once they are far below double precision next to the state's size).
        if dmax <= STAGE_TOL || (dmax >= last && dmax <= STAGE_STALL) {
            for (bj, kj) in B8_DD.iter().zip(k.iter()) {
                let hb = h.mul(dd(*bj));
                for (v, kv) in y.iter_mut().zip(kj) {
                    *v = v.add(hb.mul(*kv));
                }
            }
            return Ok(());
        }
        last = dmax;
        if iteration == MAX_ITER {
            break;
        }
    }
    Err(Error::NoConvergence {
        what: "Gauss stage iteration in double-double (step too large)",
        tol: STAGE_TOL,
        reached: last,
        iterations: MAX_ITER,
    })
}

/// One step of length `h` from `y` for the differences `d` ([`diffs`]), the
/// stage iteration started from the field at `y`.
pub(crate) fn advance(d: &[Dd; 12], y: &mut [Dd; 6], h: Dd) -> Result<()> {
    let f0 = field(d, y);
    let mut k = [f0; S];
    step(d, y, h, &mut k)
}

/// Steps [`gauss16_dd_so4`] takes to reach the sorted times `times` from 0 at
/// steps of at most `dt`, each split in `split`.
pub(crate) fn gauss16_dd_steps(times: &[f64], dt: f64, split: u32) -> f64 {
    let mut prev = 0.0;
    let mut n = 0.0;
    for &t in times {
        n += ((t - prev) / dt).ceil();
        prev = t;
    }
    n * f64::from(split.max(1))
}

/// `l(t)` of (1) on so(4) from `l(0) = l0` at the sorted times `times ≥ 0`,
/// for the coefficients `c` (state order) in double-double, by the 8-stage
/// Gauss method in double-double at steps of at most `dt` (each interval
/// between requested times in equal steps, their length in double-double),
/// each split in `split` equal ones (`split = 2` halves every step, also
/// where the interval is shorter than `dt`). Returns the states rounded to
/// double, 6 per time. The caller checks the step count
/// ([`gauss16_dd_steps`]) against its budget first.
pub(crate) fn gauss16_dd_so4(
    c: &[Dd; 6],
    l0: &[f64; 6],
    times: &[f64],
    dt: f64,
    split: u32,
    cancel: &Cancel,
) -> Result<Vec<f64>> {
    if !(dt > 0.0 && dt.is_finite()) {
        return Err(Error::InvalidArgument {
            what: "dt",
            reason: format!("must be positive and finite, got {dt:e}"),
        });
    }
    let bad = |t: &f64| !t.is_finite() || *t < 0.0;
    if times.iter().any(bad) || times.windows(2).any(|w| w[1] < w[0]) {
        return Err(Error::InvalidArgument {
            what: "times",
            reason: "must be finite, sorted and non-negative".into(),
        });
    }
    let d = diffs(c);
    let mut y = l0.map(Dd::new);
    let mut out = crate::numeric::alloc::try_vec("states", 6 * times.len(), 0.0)?;
    let mut prev = 0.0f64;
    for (row, &t) in out.chunks_exact_mut(6).zip(times) {
        let span = Dd::sum(t, -prev);
        let n = (span.to_f64() / dt).ceil() * f64::from(split.max(1));
        if n > 0.0 {
            let h = span.div(Dd::new(n));
            for _ in 0..n as u64 {
                cancel.check()?;
                advance(&d, &mut y, h)?;
            }
        }
        prev = t;
        for (o, v) in row.iter_mut().zip(&y) {
            *o = v.to_f64();
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::{integrate_with, Method, Options};
    use crate::so4::{FrahmTop, PAIRS4};

    fn top(c4: &[f64; 6]) -> FrahmTop {
        let mut c = [0.0; 16];
        for (q, &(i, j)) in PAIRS4.iter().enumerate() {
            c[4 * i + j] = c4[q];
            c[4 * j + i] = c4[q];
        }
        FrahmTop::new(4, &c).unwrap()
    }

    /// On a well-conditioned state the double-double method agrees with the
    /// double one to the latter's rounding, and keeps the Casimirs of (1)
    /// (`Σ l_ij²` and the Pfaffian `l12 l34 − l13 l24 + l14 l23`) to
    /// double-double rounding, far below what double can.
    #[test]
    fn agrees_with_the_double_method_and_keeps_the_casimirs() {
        // A Manakov top (2), whose motion is quasi-periodic: a generic c would
        // be chaotic, and the two methods' rounding would separate.
        let c = crate::so4::manakov_c(&[0.1, 0.9, 1.7, 3.2], &[0.5, -0.4, 1.1, 0.3]).unwrap();
        let c4 = [c[1], c[2], c[3], c[6], c[7], c[11]];
        let l0 = [0.4, -0.9, 0.25, 0.6, -0.35, 0.8];
        let times: Vec<f64> = (1..=20).map(|k| k as f64 * 2.5).collect();
        let dt = 0.05;
        let cdd = c4.map(Dd::new);
        let dd_out = gauss16_dd_so4(&cdd, &l0, &times, dt, 1, &Cancel::never()).unwrap();
        let opts = Options {
            method: Method::Gauss16,
            dt,
            rtol: 0.0,
            atol: 0.0,
            max_steps: 10_000,
        };
        let tr = integrate_with(&top(&c4), &l0, 0.0, &times, &opts, &Cancel::never()).unwrap();
        let worst = dd_out
            .iter()
            .zip(&tr.y)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(
            worst < 1e-13,
            "double and double-double differ by {worst:e}"
        );
        // The Casimirs in double-double along a second run whose state is kept.
        let d = diffs(&cdd);
        let mut y = l0.map(Dd::new);
        let cas = |y: &[Dd; 6]| {
            let s = y.iter().fold(Dd::ZERO, |a, v| a.add(v.mul(*v)));
            let p = y[0].mul(y[5]).sub(y[1].mul(y[4])).add(y[2].mul(y[3]));
            (s, p)
        };
        let (s0, p0) = cas(&y);
        for _ in 0..1000 {
            let mut k = [field(&d, &y); S];
            step(&d, &mut y, Dd::new(dt), &mut k).unwrap();
        }
        let (s1, p1) = cas(&y);
        let ds = s1.sub(s0).to_f64().abs() / s0.to_f64();
        let dp = p1.sub(p0).to_f64().abs() / s0.to_f64();
        assert!(ds < 1e-28 && dp < 1e-28, "Casimirs drift by {ds:e}, {dp:e}");
    }

    #[test]
    fn a_cancelled_integration_stops() {
        let c = [
            Dd::new(1.0),
            Dd::new(2.0),
            Dd::new(3.0),
            Dd::new(4.0),
            Dd::new(5.0),
            Dd::new(6.0),
        ];
        let cancel = Cancel::never();
        cancel.cancel();
        let got = gauss16_dd_so4(&c, &[1.0; 6], &[10.0], 0.01, 1, &cancel);
        assert!(matches!(got, Err(Error::Interrupted)), "{got:?}");
    }

    #[test]
    fn invalid_steps_and_times_are_refused() {
        let c = [Dd::new(1.0); 6];
        let l0 = [1.0; 6];
        let never = Cancel::never();
        assert!(gauss16_dd_so4(&c, &l0, &[1.0], 0.0, 1, &never).is_err());
        assert!(gauss16_dd_so4(&c, &l0, &[2.0, 1.0], 0.1, 1, &never).is_err());
        assert!(gauss16_dd_so4(&c, &l0, &[-1.0], 0.1, 1, &never).is_err());
        assert_eq!(gauss16_dd_steps(&[0.25, 1.0], 0.1, 1), 3.0 + 8.0);
        assert_eq!(gauss16_dd_steps(&[0.25, 1.0], 0.1, 2), 22.0);
    }
}
