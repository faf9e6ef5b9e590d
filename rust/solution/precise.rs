//! The Theorem (9)–(10) to the floating-point floor: the constants of the
//! quotients polished in double-double against the conditions that define
//! them, and `l(t)` evaluated in double-double (docs/theorem.md, "Precise
//! evaluation").
//!
//! Why: the double set-up leaves each constant a few units of rounding off —
//! `τ` from the double periods, the phase `v0` from the double Abel map, the
//! weights (the `C_L` of (37) by consensus over auxiliary divisors, and the
//! reduction's `α … δ` of (24)) — and the double evaluation adds a few more.
//! Measured against 80-bit references ('wide', 'physical') they make `l(t)`
//! wrong by 1e-15 … 3e-15 `|l0|` at every time from `t = 0` on, while an
//! implicit Gauss–Legendre integration of a slow top stays within an ulp or
//! two for a hundred time units.
//!
//! What fixes the constants, exactly: at points `v(t_k) = v0 + U t_k` of the
//! torus (the lattice rates `X, Y` of `U` are already in DD, from the periods
//! in DD), the quotients `N_q/D` must be real, keep the integrals (6)–(7) of
//! `l0`, and move by Frahm's equations (1) of the unrounded top; at `t = 0`
//! they must give `l0`. Gauss–Newton on the constants — the three entries of
//! `τ`, the four lattice coordinates of `v0` and every nonzero weight of
//! `N_q` and `D` (a complex factor each) — with these residuals in DD, the
//! Jacobian by differences once (the corrections are ~1e-15, so the chord
//! iteration contracts by ~1e-7 a step), and the least-squares step of
//! smallest norm (directions the conditions do not see change no `l`).

use nalgebra::DMatrix;

use super::Solution;
use crate::error::{Error, Result};
use crate::integrate::gauss_dd::{diffs, field};
use crate::numeric::cancel::Cancel;
use crate::numeric::dd::{Cdd, Dd};
use crate::theta::dd::{theta_jet_dd, JetDd};

/// Points of the torus at which the conditions are imposed (`t = 0` and
/// `PRECISE_POINTS − 1` more): 16 conditions each, 6 + 16·12 = 198 for the
/// 30 to 36 constants.
pub const PRECISE_POINTS: usize = 12;

/// Largest residual of the conditions, relative (each scaled by its natural
/// size: `|l0|`, `|l0|²` times powers of `max|a|`, `max|c| |l0|²`), that the
/// polished constants may leave. The double constants leave ~1e-15; the
/// polished ones left median 3.8e-21, max 4.4e-19 on the 104 states of
/// `tests/data/closed_u_long_double.py` (the four shared tops and 100 random
/// ones, a third of them stiff), whose constants the polish moved by up to
/// 1.7e-13. The lattice rates `X, Y` are good to ~1e-19 relative,
/// which bounds how well (1) can hold.
pub const PRECISE_RESIDUAL_RTOL: f64 = 1e-17;

/// The points `t_k = k · POINT_SPACING · 2/max|X, Y|`: an irrational
/// fraction (the golden ratio's conjugate times the plastic number) of the
/// fastest lattice period, so the twelve phases spread over the torus.
const POINT_SPACING: f64 = 0.818_720_723_084_583;

/// Lattice points one DD theta sum may take (~1000 on the shared tops; a
/// nearly singular `Im τ` needs ~1/λ_min of them): at ~0.2 µs a point, at
/// most ~10 ms a time and ~1.5 s for the polish's 140 sums. Beyond, the
/// precise evaluation is refused.
const TERM_BUDGET: usize = 50_000;

/// Relative accuracy assumed of the lattice rates `X, Y` in DD (measured
/// ≤ 1.4e-19 against 60-digit periods, `riemann::periods_dd`): the phase
/// horizon of the precise evaluation.
pub const PRECISE_PHASE_RTOL: f64 = 1e-18;

/// Times per thread between two cancellation checks of the precise
/// evaluation (~13 ms at ~0.2 ms a time).
const PRECISE_CHUNK: usize = 64;

/// Smallest piece of times handed to one thread.
const PRECISE_PIECE: usize = 4;

/// Relative step of the difference Jacobian.
const FD_STEP: f64 = 1e-7;

/// Chord steps after the Jacobian.
const NEWTON_STEPS: usize = 4;

/// Singular values below this fraction of the largest are left out of the
/// least-squares step (directions the conditions do not constrain).
const RCOND: f64 = 1e-10;

/// The polished constants of a [`Solution`] and its precise evaluation.
#[derive(Debug, Clone)]
pub struct Precise {
    /// `τ11, τ12, τ22`.
    tau: [Cdd; 3],
    /// `x0, y0` of `v0 = x0 + τ y0`.
    lat0: [Dd; 4],
    /// `X, Y` of `U = X + τ Y`.
    rate: [Dd; 4],
    num: [[Cdd; 8]; 6],
    den: [Cdd; 8],
    chars: [([u8; 2], [u8; 2]); 8],
    /// The largest scaled residual of the conditions at the polished constants.
    residual: f64,
    /// The largest change the polish made to a constant (absolute for `τ`
    /// and the lattice coordinates of `v0`, relative for the weights).
    correction: f64,
}

/// A nonzero weight: `(Some(q), m)` of `num[q][m]`, `(None, m)` of `den[m]`.
type Slot = (Option<usize>, usize);

/// What the residuals compare with.
struct Target {
    l0: [f64; 6],
    a: [f64; 4],
    /// The differences `c_kj − c_ik` of the unrounded top that (1) needs, in DD.
    d: [Dd; 12],
    h0: [Dd; 4],
    size: f64,
    amax: f64,
    cmax: f64,
    times: Vec<f64>,
}

impl Precise {
    /// The residuals of the conditions (module docs), scaled, at the times of
    /// `tg`; the thetas at those times given (`th[k][m]` for time `k`).
    fn residuals(&self, tg: &Target, th: &[Vec<JetDd>]) -> Vec<f64> {
        let mut r = Vec::with_capacity(6 + 16 * th.len());
        let vel = self.velocity();
        let s2 = tg.size * tg.size;
        for (k, th) in th.iter().enumerate() {
            let (l, im, ld) = self.quotients(th, &vel);
            if k == 0 {
                for (x, y) in l.iter().zip(&tg.l0) {
                    r.push(x.sub(Dd::new(*y)).to_f64() / tg.size);
                }
            }
            for v in im {
                r.push(v.to_f64() / tg.size);
            }
            let h = integrals_dd(&tg.a, &l);
            let hs = [s2, s2, tg.amax * s2, tg.amax * tg.amax * s2];
            for i in 0..4 {
                r.push(h[i].sub(tg.h0[i]).to_f64() / hs[i]);
            }
            let f = field(&tg.d, &l);
            for q in 0..6 {
                r.push(ld[q].sub(f[q]).to_f64() / (tg.cmax * s2));
            }
        }
        r
    }

    /// `dv/dt = X + τ Y`.
    fn velocity(&self) -> [Cdd; 2] {
        self.on_lattice(&self.rate)
    }

    /// `x + τ y` of the lattice coordinates `p = (x, y)`.
    fn on_lattice(&self, p: &[Dd; 4]) -> [Cdd; 2] {
        [
            Cdd::real(p[0])
                .add(self.tau[0].mul_dd(p[2]))
                .add(self.tau[1].mul_dd(p[3])),
            Cdd::real(p[1])
                .add(self.tau[1].mul_dd(p[2]))
                .add(self.tau[2].mul_dd(p[3])),
        ]
    }

    /// `Re(N_q/D)`, `Im(N_q/D)` and `Re d(N_q/D)/dt` for the velocity `vel`
    /// (zero: the derivative is not formed).
    fn quotients(&self, th: &[JetDd], vel: &[Cdd; 2]) -> ([Dd; 6], [Dd; 6], [Dd; 6]) {
        let moving = *vel != [Cdd::ZERO; 2];
        let comb = |w: &[Cdd; 8]| {
            let mut v = Cdd::ZERO;
            let mut d = Cdd::ZERO;
            for m in 0..8 {
                if w[m] == Cdd::ZERO {
                    continue;
                }
                v = v.add(w[m].mul(th[m].0));
                if moving {
                    let g = th[m].1[0].mul(vel[0]).add(th[m].1[1].mul(vel[1]));
                    d = d.add(w[m].mul(g));
                }
            }
            (v, d)
        };
        let (dv, dd) = comb(&self.den);
        let inv = dv.recip();
        let mut l = [Dd::ZERO; 6];
        let mut im = [Dd::ZERO; 6];
        let mut ld = [Dd::ZERO; 6];
        for q in 0..6 {
            let (nv, nd) = comb(&self.num[q]);
            let ratio = nv.mul(inv);
            l[q] = ratio.re;
            im[q] = ratio.im;
            // (N' D − N D')/D² = (N' − ratio D')/D
            ld[q] = nd.sub(ratio.mul(dd)).mul(inv).re;
        }
        (l, im, ld)
    }

    /// `z = x + τ y` at time `t`, the lattice coordinates reduced modulo 2
    /// (an even lattice vector multiplies every theta by one factor).
    fn z_at(&self, t: f64) -> [Cdd; 2] {
        let p: [Dd; 4] = std::array::from_fn(|k| {
            let x = self.lat0[k].add(self.rate[k].mul(Dd::new(t)));
            let n = 2.0 * (0.5 * x.hi).round();
            x.sub(Dd::new(n))
        });
        self.on_lattice(&p)
    }

    fn thetas_at(&self, t: f64) -> Result<Vec<JetDd>> {
        theta_jet_dd(&self.chars, &self.tau, &self.z_at(t), TERM_BUDGET).ok_or_else(|| {
            Error::Unverified {
                what: "precise l(t)",
                reason: format!(
                    "the theta series in double-double would need more than {TERM_BUDGET} \
                     terms at one point (Im tau nearly singular)"
                ),
            }
        })
    }

    /// `l(t)` in the solution's frame, in DD rounded to double.
    pub fn l(&self, t: f64) -> Result<[f64; 6]> {
        let (l, _, _) = self.quotients(&self.thetas_at(t)?, &[Cdd::ZERO; 2]);
        Ok(l.map(|x| x.to_f64()))
    }

    /// The largest scaled residual of the conditions left by the polish.
    pub fn residual(&self) -> f64 {
        self.residual
    }

    /// The largest change the polish made to a constant (absolute for `τ`
    /// and the lattice coordinates of `v0`, relative for the weights).
    pub fn correction(&self) -> f64 {
        self.correction
    }

    /// The weights' nonzero slots.
    fn slots(&self) -> Vec<Slot> {
        let mut s: Vec<Slot> = (1..8)
            .filter(|&m| self.den[m] != Cdd::ZERO)
            .map(|m| (None, m))
            .collect();
        for q in 0..6 {
            s.extend(
                (0..8)
                    .filter(|&m| self.num[q][m] != Cdd::ZERO)
                    .map(|m| (Some(q), m)),
            );
        }
        s
    }

    /// The constants moved by `p` (parameters in the order of the module
    /// docs; the weights' as relative complex factors `1 + p`).
    fn moved(&self, slots: &[Slot], p: &[f64]) -> Precise {
        let mut o = self.clone();
        for k in 0..3 {
            o.tau[k] = o.tau[k].add(Cdd::new(num_complex::Complex64::new(
                p[2 * k],
                p[2 * k + 1],
            )));
        }
        for k in 0..4 {
            o.lat0[k] = o.lat0[k].add(Dd::new(p[6 + k]));
        }
        for (s, &(q, m)) in slots.iter().enumerate() {
            let f = num_complex::Complex64::new(p[10 + 2 * s], p[11 + 2 * s]);
            let w = match q {
                Some(q) => &mut o.num[q][m],
                None => &mut o.den[m],
            };
            *w = w.add(w.mul_c(f));
        }
        o
    }
}

/// `[H0, H1, H2, H3]` (6)–(7) in DD, as [`crate::so4::integrals4`].
fn integrals_dd(a: &[f64; 4], l: &[Dd; 6]) -> [Dd; 4] {
    const PAIRS: [(usize, usize); 6] = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];
    let h0 = l[0].mul(l[5]).add(l[3].mul(l[2])).sub(l[1].mul(l[4]));
    let (mut h1, mut h2, mut h3) = (Dd::ZERO, Dd::ZERO, Dd::ZERO);
    for p in 0..6 {
        let (u, v) = PAIRS[5 - p];
        let x2 = l[p].mul(l[p]);
        h1 = h1.add(x2);
        h2 = h2.add(x2.mul(Dd::sum(a[u], a[v])));
        h3 = h3.add(x2.mul(Dd::prod(a[u], a[v])));
    }
    [h0, h1, h2, h3]
}

impl Solution {
    /// The constants polished in DD ([`Precise`]), computed on the first call
    /// and kept.
    ///
    /// Errors: [`Error::Unverified`] where the solution is certified at every
    /// call (its constants fail the self-check), where its `U` is the
    /// quotients' fit rather than the closed form (then `X, Y` are not known
    /// beyond double), or where the polish leaves a residual above
    /// [`PRECISE_RESIDUAL_RTOL`]; [`Error::Interrupted`].
    pub fn precise(&self, cancel: &Cancel) -> Result<&Precise> {
        if let Some(p) = self.precise.get() {
            return p.as_deref().map_err(Clone::clone);
        }
        let p = self.polish(cancel).map(Box::new);
        if matches!(p, Err(Error::Interrupted)) {
            return Err(Error::Interrupted);
        }
        self.precise
            .get_or_init(|| p)
            .as_deref()
            .map_err(Clone::clone)
    }

    fn polish(&self, cancel: &Cancel) -> Result<Precise> {
        let refuse = |reason: String| Error::Unverified {
            what: "precise l(t)",
            reason,
        };
        if let Some(why) = &self.certify_every {
            return Err(refuse(format!(
                "the closed form is certified by an integration at every call ({why})"
            )));
        }
        if !self.closed_u {
            return Err(refuse(
                "the velocity U is the theta quotients' fit, not the closed form, so the \
                 phase is not known beyond double precision"
                    .into(),
            ));
        }
        let mut chars = [([0u8; 2], [0u8; 2]); 8];
        for (m, &i) in self.idx.iter().enumerate() {
            let (a, b) = crate::theta::char_from_index(2, i);
            chars[m] = ([a[0], a[1]], [b[0], b[1]]);
        }
        let cdd = |z: &num_complex::Complex64| Cdd::new(*z);
        let mut cur = Precise {
            tau: [cdd(&self.tau[0]), cdd(&self.tau[1]), cdd(&self.tau[3])],
            lat0: self.lat0.map(Dd::new),
            rate: std::array::from_fn(|k| Dd::sum(self.lat_rate[k], self.lat_rate_lo[k])),
            num: self.num.map(|row| row.map(|w| cdd(&w))),
            den: self.den.map(|w| cdd(&w)),
            chars,
            residual: f64::INFINITY,
            correction: 0.0,
        };
        let l0 = self.l0;
        let l0dd = l0.map(Dd::new);
        // Times spread over the torus: steps of an irrational fraction of the
        // fastest lattice period.
        let rmax = self.lat_rate.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let step = if rmax > 0.0 {
            POINT_SPACING * 2.0 / rmax
        } else {
            1.0
        };
        let tg = Target {
            l0,
            a: self.a,
            d: diffs(&super::verify::c_dd(&self.c4, &self.c4_lo, 1.0)),
            h0: integrals_dd(&self.a, &l0dd),
            size: self.size,
            amax: self
                .a
                .iter()
                .fold(0.0f64, |m, v| m.max(v.abs()))
                .max(f64::MIN_POSITIVE),
            cmax: self
                .c4
                .iter()
                .fold(0.0f64, |m, v| m.max(v.abs()))
                .max(f64::MIN_POSITIVE),
            times: (0..PRECISE_POINTS).map(|k| k as f64 * step).collect(),
        };
        let thetas = |p: &Precise| -> Result<Vec<Vec<JetDd>>> {
            let mut v = Vec::with_capacity(tg.times.len());
            for &t in &tg.times {
                cancel.check()?;
                v.push(p.thetas_at(t)?);
            }
            Ok(v)
        };
        let slots = cur.slots();
        let np = 10 + 2 * slots.len();
        let th0 = thetas(&cur)?;
        let r0 = cur.residuals(&tg, &th0);
        let mut jac = DMatrix::<f64>::zeros(r0.len(), np);
        for j in 0..np {
            let mut p = vec![0.0; np];
            p[j] = FD_STEP;
            let moved = cur.moved(&slots, &p);
            let r = if j < 10 {
                moved.residuals(&tg, &thetas(&moved)?)
            } else {
                moved.residuals(&tg, &th0)
            };
            for (i, (x, y)) in r.iter().zip(&r0).enumerate() {
                jac[(i, j)] = (x - y) / FD_STEP;
            }
        }
        let svd = jac.svd(true, true);
        let smax = svd.singular_values.max();
        let mut r = r0;
        let mut correction = 0.0f64;
        for _ in 0..NEWTON_STEPS {
            let rv = nalgebra::DVector::from_vec(r.iter().map(|x| -x).collect());
            let dp = svd
                .solve(&rv, RCOND * smax)
                .map_err(|e| refuse(format!("the least-squares step failed: {e}")))?;
            let dp: Vec<f64> = dp.iter().copied().collect();
            let size = dp.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            correction = correction.max(size);
            cur = cur.moved(&slots, &dp);
            r = cur.residuals(&tg, &thetas(&cur)?);
            if size < 1e-22 {
                break;
            }
        }
        let worst = r.iter().fold(
            0.0f64,
            |m, v| if v.is_nan() { f64::NAN } else { m.max(v.abs()) },
        );
        cur.residual = worst;
        cur.correction = correction;
        if worst.is_nan() || worst > PRECISE_RESIDUAL_RTOL {
            return Err(refuse(format!(
                "the polished constants leave a residual {worst:e} > \
                 {PRECISE_RESIDUAL_RTOL:e} in the conditions that define them"
            )));
        }
        Ok(cur)
    }

    /// `l(t_k)` with the polished constants, evaluated in DD (~0.2 ms a
    /// time; rayon over the times), into `out` (row-major `(N, 6)`). `t = 0`
    /// gives `l0` to rounding.
    pub fn l_precise_batch(&self, t: &[f64], out: &mut [f64], cancel: &Cancel) -> Result<()> {
        super::check_rows(t, out)?;
        // The phase horizon of the lattice rates in DD (as `check_drift` for
        // the double ones)
        let t_max = t.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let drift = PRECISE_PHASE_RTOL * t_max * self.speed_bound / self.size;
        if drift > super::HORIZON_RTOL {
            return Err(super::check::beyond_horizon(
                t_max,
                drift,
                "the lattice rates in DD",
            ));
        }
        let p = self.precise(cancel)?;
        super::rows_in_parallel(t, out, cancel, PRECISE_CHUNK, PRECISE_PIECE, |tp, op| {
            for (&tk, o) in tp.iter().zip(op.chunks_exact_mut(6)) {
                o.copy_from_slice(&p.l(tk)?);
            }
            Ok(())
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const A: [f64; 4] = [0.3, 1.1, 2.0, 3.7];
    const B: [f64; 4] = [0.5, -0.2, 1.4, 0.9];
    const L0: [f64; 6] = [0.8, -0.3, 0.5, 1.1, -0.7, 0.2];

    /// `l(10)` and `l(100)` of the generic top, mpmath's `odefun` at 38 digits
    /// (`tests/data/reference_generic.json`, `gen_reference_trajectory.py`),
    /// each as the double nearest to it and the double of the rest.
    const REF: [(f64, [(f64, f64); 6]); 2] = [
        (
            10.0,
            [
                (-0.061_748_159_959_680_936, 1.573_989_161_279_094_6e-18),
                (-1.234_886_120_644_113_5, 1.072_639_929_316_464_4e-16),
                (-0.289_668_756_052_214_54, 2.048_447_980_598_095_4e-17),
                (0.734_372_571_156_728_9, 4.031_509_237_859_704_6e-17),
                (0.599_967_177_468_662_6, 5.891_170_475_668_637e-18),
                (0.456_148_833_432_937_83, -4.735_416_663_253_586e-18),
            ],
        ),
        (
            100.0,
            [
                (0.195_891_815_621_296_62, 3.032_410_120_410_156e-20),
                (-1.175_141_779_944_089, -2.192_525_196_515_109_6e-17),
                (-0.474_337_200_199_596_2, -7.874_047_776_003_637e-18),
                (0.717_413_967_154_420_1, 1.180_092_443_668_042_7e-17),
                (0.737_162_359_116_012_6, -1.269_285_820_555_185_8e-17),
                (-0.132_594_382_020_921_14, -3.457_643_753_857_068_2e-18),
            ],
        ),
    ];

    /// The precise `l(t)` is the correctly rounded value of the 38-digit
    /// reference (none of these lies within 0.02 ulp of a tie), where the
    /// double evaluation is off by up to 47 ulp.
    #[test]
    fn precise_l_is_the_correctly_rounded_state() {
        let sol = Solution::new(&A, &B, &L0).unwrap();
        let cancel = Cancel::never();
        let times = [REF[0].0, REF[1].0];
        let mut out = [0.0; 12];
        sol.l_precise_batch(&times, &mut out, &cancel).unwrap();
        let mut worst_double = 0.0f64;
        for (k, (t, want)) in REF.iter().enumerate() {
            let double = sol.l(*t).unwrap();
            for q in 0..6 {
                assert_eq!(out[6 * k + q], want[q].0, "t = {t}, component {q}");
                let ulp = want[q].0.abs() * f64::EPSILON;
                worst_double = worst_double.max((double[q] - want[q].0).abs() / ulp);
            }
        }
        // what the polish and the DD evaluation are for
        assert!(worst_double > 4.0, "{worst_double}");
    }

    /// The polish moves the constants by rounding-level amounts and leaves
    /// their defining conditions at DD level; `l(0)` is `l0` to the bit.
    #[test]
    fn the_polish_satisfies_the_defining_conditions() {
        let sol = Solution::new(&A, &B, &L0).unwrap();
        let p = sol.precise(&Cancel::never()).unwrap();
        assert!(p.residual() <= PRECISE_RESIDUAL_RTOL, "{}", p.residual());
        assert!(
            p.correction() > 1e-17 && p.correction() < 1e-13,
            "{}",
            p.correction()
        );
        assert_eq!(p.l(0.0).unwrap(), L0);
        // the second call is the kept one
        assert!(std::ptr::eq(p, sol.precise(&Cancel::never()).unwrap()));
    }
}
