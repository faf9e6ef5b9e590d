//! The Euler top `Ṁ = M × (W∘M)` on `so(3) ≅ R³` in closed form, and its
//! two embeddings into Frahm's equations (1) on so(4) (docs/degenerate.md §3):
//!
//! * an **so(3) block** `{i, j, k}` (`i < j < k`; the other three components of
//!   `l` zero) is invariant and moves as the Euler top with
//!   `M = (l_jk, −l_ik, l_ij)`, `W = −(c_jk, c_ik, c_ij)`;
//! * a **self-dual state** `n = σ m` (`σ = ±1`, `m_j = l_kl`, `n_j = l_j4`,
//!   `(j, k, l)` cyclic) is invariant (one factor of so(4) = so(3) ⊕ so(3) at
//!   rest) and `m` moves as the Euler top with `W_j = −(c_kl + c_j4)`.
//!
//! **The closed form** (the classical solution; e.g. Landau–Lifshitz,
//! *Mechanics*, §37, with `W_j` in place of `1/I_j`). With `b` the axis of the
//! middle `W`, `Δ = Σ_i (W_i − W_b) M_i²` (`E − W_b G` for the integrals
//! `E = Σ W_i M_i²`, `G = |M|²`), `s` the axis of the largest `W` if `Δ > 0` and
//! of the smallest if `Δ < 0` (the axis the motion circulates around), `r` the
//! third, `A = |W_s − W_b|`, `B = |W_b − W_r|`, `C = A + B`:
//!
//! ```text
//! M_b = X sn(u | m),   M_r = R̃ cn(u | m),   M_s = S̃ dn(u | m),   u = ω t + u0,
//! X² = M_b² + (C/A) M_r²,   R² = M_r² + (A/C) M_b²,   S² = M_s² + (B/C) M_b²,
//! ω² = A (B M_b² + C M_s²),   m = A B X²/ω²,   1 − m = |Δ| C/ω²,
//! ```
//!
//! every one a sum of non-negative terms, so nothing cancels as `B → 0` (the
//! axisymmetric limit, `m → 0`) or `Δ → 0` (the separatrix, `m → 1`; `1 − m`
//! carries `|Δ|`, evaluated in double-double). `S̃ = sign(M_s) S`,
//! `R̃ = −χ sign(W_s − W_b) sign(S̃) R` with `χ = +1` if `(b, s, r)` is a cyclic
//! order and `−1` otherwise, and `u0` the argument with `sn u0 = M_b/X`,
//! `cn u0 = M_r/R̃`, `dn u0 = M_s/S̃` ([`Jacobi::arg_from`]). The period
//! of `M` is `4K(m)/ω`, its frequency `ν = ω/(4K)`.
//!
//! The other regimes: two equal `W` (axisymmetric): `M_z` constant and
//! `(M_{z+1}, M_{z+2})` rotating at `Ω = (W_z − W_⊥) M_z`; `Δ = 0` (the
//! separatrix, `m = 1`): `sn → tanh`, `cn, dn → sech`, no period; three equal
//! `W` (spherical) or `M` on an axis: at rest.

use super::jacobi::Jacobi;
use crate::error::{Error, Result};
use crate::numeric::dd::Dd;

/// Sign of the double-double `hi + lo` (`0` for an exact zero).
fn signum0(x: Dd) -> f64 {
    let v = if x.hi != 0.0 { x.hi } else { x.lo };
    if v > 0.0 {
        1.0
    } else if v < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// `|Δ|` at or below this fraction of `Σ_i |W_i − W_b| M_i²` counts as zero:
/// the double-double evaluation of `Δ` from the doubles `W`, `M` errs by a few
/// units of `2^-104` relative to that sum, so only a state *on* the separatrix
/// (to that precision) is taken for one; a state `1e-20` off it is an
/// elliptic motion with `1 − m ~ 1e-20`, which the elliptic form represents.
pub const SEPARATRIX_RTOL: f64 = 1e-29;

/// The regime of an Euler motion.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EulerRegime {
    /// `M` constant: on an axis, `M = 0`, or a spherical top.
    Rest,
    /// Two equal `W`: a uniform rotation of the two components across the axis.
    Axisymmetric,
    /// Three distinct `W`, off the separatrix: `sn, cn, dn` of parameter `m < 1`.
    Elliptic,
    /// Three distinct `W`, `Δ = 0`: the asymptotic motion (`tanh`, `sech`).
    Separatrix,
}

#[derive(Debug, Clone)]
enum Motion {
    Rest,
    Rotation {
        p: usize,
        q: usize,
        /// `Ω/(2π)`, cycles per unit time (signed).
        nu: f64,
        mp: f64,
        mq: f64,
    },
    Elliptic {
        idx: [usize; 3],
        amp: [f64; 3],
        jac: Box<Jacobi>,
        nu: f64,
        x0: f64,
    },
    Separatrix {
        idx: [usize; 3],
        amp: [f64; 3],
        omega: f64,
        u0: f64,
    },
}

/// An Euler top `Ṁ = M × (W∘M)`, i.e.
/// `Ṁ_1 = (W_3 − W_2) M_2 M_3` and cyclically, through `M(0) = m0`.
#[derive(Debug, Clone)]
pub struct EulerTop {
    m0: [f64; 3],
    w: [Dd; 3],
    motion: Motion,
    regime: EulerRegime,
    /// `m`, `1 − m`, `ω` of the elliptic form (NaN where undefined).
    params: [f64; 3],
}

/// `x0 + ν t` reduced modulo 1, with `ν t` split error-free (fma), so that the
/// phase keeps its digits at large `t`.
#[inline]
pub fn phase_mod1(x0: f64, nu: f64, t: f64) -> f64 {
    let p = nu * t;
    let e = nu.mul_add(t, -p);
    let r = p - p.round();
    let x = x0 + r + e;
    x - x.round()
}

/// The axes of a triaxial Euler top through `m0` and the constants of its
/// closed form (module docs).
struct TriaxialAxes {
    /// `b` the middle axis, `s` the axis the motion circulates around, `r` the third.
    b: usize,
    r: usize,
    s: usize,
    /// `χ`: `+1` if `(b, s, r)` is a cyclic order, else `−1`.
    chi: f64,
    /// `W_s − W_b`.
    dsb: f64,
    /// `A = |W_s − W_b|`, `B = |W_b − W_r|`, `C = |W_s − W_r|`.
    a_: f64,
    b_: f64,
    c_: f64,
    /// The power of two `μ` and `Δ' = Δ/μ²`.
    mu: f64,
    delta: Dd,
    /// `|Δ'|` at or below [`SEPARATRIX_RTOL`] of its terms.
    on_separatrix: bool,
}

impl TriaxialAxes {
    /// The axes and `Δ` of the top `w` through `m0` (three distinct `W`).
    fn of(w: [Dd; 3], m0: [f64; 3]) -> Self {
        let diff = |i: usize, j: usize| w[i].sub(w[j]);
        // b the middle axis.
        let mut order = [0usize, 1, 2];
        // The exact order of the double-double W (their sums may round alike).
        order.sort_by(|&i, &j| signum0(diff(i, j)).total_cmp(&0.0));
        let (lo, b, hi) = (order[0], order[1], order[2]);
        // Δ with the two outer components scaled by a power of two μ (exact),
        // so that their squares do not underflow when they are tiny beside
        // M_b (a state within 1e-154 of the middle axis): Δ = μ² Δ'.
        let big = m0[hi].abs().max(m0[lo].abs());
        let mu = big.log2().floor().max(-1074.0).exp2();
        let sq = |i: usize| {
            let v = m0[i] / mu;
            Dd::prod(v, v)
        };
        let t_hi = diff(hi, b).mul(sq(hi));
        let t_lo = diff(lo, b).mul(sq(lo));
        let delta = t_hi.add(t_lo);
        let scale = t_hi.to_f64().abs() + t_lo.to_f64().abs();
        let on_separatrix = delta.to_f64().abs() <= SEPARATRIX_RTOL * scale;
        let (s, r) = if on_separatrix || signum0(delta) > 0.0 {
            (hi, lo)
        } else {
            (lo, hi)
        };
        let chi = if s == (b + 1) % 3 { 1.0 } else { -1.0 };
        let dsb = diff(s, b).to_f64();
        let a_ = dsb.abs();
        let b_ = diff(b, r).to_f64().abs();
        let c_ = diff(s, r).to_f64().abs();
        TriaxialAxes {
            b,
            r,
            s,
            chi,
            dsb,
            a_,
            b_,
            c_,
            mu,
            delta,
            on_separatrix,
        }
    }

    /// The amplitudes `X`, `R̃`, `S̃` and the rate `ω` of the closed form at `m0`.
    fn amplitudes(&self, w: [Dd; 3], m0: [f64; 3]) -> Result<Amplitudes> {
        let (a_, b_, c_) = (self.a_, self.b_, self.c_);
        let (mb, mr, ms) = (m0[self.b], m0[self.r], m0[self.s]);
        // Amplitudes as hypotenuses: no square underflows or overflows.
        let x = mb.hypot((c_ / a_).sqrt() * mr);
        let r_abs = mr.hypot((a_ / c_).sqrt() * mb);
        let s_abs = ms.hypot((b_ / c_).sqrt() * mb);
        let omega = a_.sqrt() * (b_.sqrt() * mb).hypot(c_.sqrt() * ms);
        let s_amp = if ms < 0.0 { -s_abs } else { s_abs };
        let r_amp = -self.chi * self.dsb.signum() * s_amp.signum() * r_abs;
        if !(omega > 0.0 && x > 0.0 && r_abs > 0.0 && s_abs > 0.0) {
            let wv = w.map(|x| x.to_f64());
            // Unreachable for finite M off the axes: each amplitude is at
            // least one non-zero |M_i| (off the axes two are non-zero).
            return Err(Error::InvalidArgument {
                what: "Euler top",
                reason: format!(
                    "degenerate amplitudes (omega = {omega:e}, X = {x:e}) for M0 = {m0:?}, W = {wv:?}"
                ),
            });
        }
        Ok(Amplitudes {
            x,
            r_abs,
            s_abs,
            omega,
            s_amp,
            r_amp,
        })
    }
}

/// The amplitudes of a triaxial Euler motion ([`TriaxialAxes::amplitudes`]):
/// `X`, `|R̃|`, `|S̃|`, `ω`, and `S̃`, `R̃` with their signs.
#[derive(Clone, Copy)]
struct Amplitudes {
    x: f64,
    r_abs: f64,
    s_abs: f64,
    omega: f64,
    s_amp: f64,
    r_amp: f64,
}

impl EulerTop {
    /// The Euler top with coefficients `w` (double-doubles: a self-dual top's
    /// `W_j = −(c_kl + c_j4)` is a sum that the separatrix test needs exactly)
    /// through `m0`.
    ///
    /// Errors: non-finite input, or an elliptic parameter outside `[0, 1]`
    /// (not reachable for finite input; a guard).
    pub(crate) fn new(w: [Dd; 3], m0: [f64; 3]) -> Result<Self> {
        crate::error::check_finite("M0", &m0)?;
        let wv = w.map(|x| x.to_f64());
        crate::error::check_finite("W", &wv)?;
        let nonzero = m0.iter().filter(|v| **v != 0.0).count();
        if nonzero <= 1 {
            return Ok(Self::rest(w, m0));
        }
        let diff = |i: usize, j: usize| w[i].sub(w[j]);
        let eq = |i: usize, j: usize| signum0(diff(i, j)) == 0.0;
        let n_equal = [(0, 1), (1, 2), (0, 2)]
            .iter()
            .filter(|&&(i, j)| eq(i, j))
            .count();
        if n_equal == 3 {
            return Ok(Self::rest(w, m0));
        }
        if n_equal == 1 {
            return Ok(Self::axisymmetric(w, m0));
        }
        Self::triaxial(w, m0)
    }

    /// At rest: `M(t) = M0` (at most one non-zero component, or a spherical top).
    fn rest(w: [Dd; 3], m0: [f64; 3]) -> Self {
        EulerTop {
            m0,
            w,
            motion: Motion::Rest,
            regime: EulerRegime::Rest,
            params: [f64::NAN; 3],
        }
    }

    /// Two equal `W`: a uniform rotation about the distinct axis.
    fn axisymmetric(w: [Dd; 3], m0: [f64; 3]) -> Self {
        let diff = |i: usize, j: usize| w[i].sub(w[j]);
        let eq = |i: usize, j: usize| signum0(diff(i, j)) == 0.0;
        // z the distinct axis.
        let z = (0..3).find(|&z| eq((z + 1) % 3, (z + 2) % 3)).unwrap_or(0);
        let (p, q) = ((z + 1) % 3, (z + 2) % 3);
        let omega = diff(z, p).to_f64() * m0[z];
        let nu = omega / (2.0 * std::f64::consts::PI);
        if nu == 0.0 || (m0[p] == 0.0 && m0[q] == 0.0) {
            return Self::rest(w, m0);
        }
        EulerTop {
            m0,
            w,
            motion: Motion::Rotation {
                p,
                q,
                nu,
                mp: m0[p],
                mq: m0[q],
            },
            regime: EulerRegime::Axisymmetric,
            params: [0.0, 1.0, omega.abs()],
        }
    }

    /// Three distinct `W`: Jacobi's elliptic functions, or the separatrix.
    fn triaxial(w: [Dd; 3], m0: [f64; 3]) -> Result<Self> {
        let ax = TriaxialAxes::of(w, m0);
        let amp = ax.amplitudes(w, m0)?;
        // k' = √(1 − m) = (μ/ω) √(|Δ'| C): no underflow down to μ ~ 1e-308.
        let kc = (ax.mu / amp.omega) * (ax.delta.to_f64().abs() * ax.c_).sqrt();
        // A k' below the double range (μ subnormal): the separatrix to the
        // last bit; its period would exceed ~1400/ω.
        if ax.on_separatrix || kc == 0.0 {
            return Ok(Self::separatrix(w, m0, &ax, &amp));
        }
        Self::elliptic(w, m0, &ax, &amp, kc)
    }

    /// On the separatrix (`Δ = 0`, `m = 1`): `sn → tanh`, `cn, dn → sech`.
    fn separatrix(w: [Dd; 3], m0: [f64; 3], ax: &TriaxialAxes, amp: &Amplitudes) -> Self {
        let (mb, mr, ms) = (m0[ax.b], m0[ax.r], m0[ax.s]);
        let Amplitudes {
            x,
            r_abs,
            s_abs,
            omega,
            s_amp,
            ..
        } = *amp;
        // sech > 0: M_r and M_s keep their signs, so R̃ takes the sign of
        // M_r and the equations fix the direction of the motion instead:
        // −R̃ ω = χ (W_s − W_b) S̃ X gives the sign of ω.
        let r_amp = if mr < 0.0 { -r_abs } else { r_abs };
        let omega = -ax.chi * ax.dsb.signum() * (s_amp * r_amp).signum() * omega;
        // tanh u0 = M_b/X, sech u0 = |M_s|/S: sinh u0 = (M_b/X)(S/|M_s|).
        let u0 = (mb / x * (s_abs / ms.abs())).asinh();
        EulerTop {
            m0,
            w,
            motion: Motion::Separatrix {
                idx: [ax.b, ax.r, ax.s],
                amp: [x, r_amp, s_amp],
                omega,
                u0,
            },
            regime: EulerRegime::Separatrix,
            params: [1.0, 0.0, omega.abs()],
        }
    }

    /// Off the separatrix: `sn, cn, dn` of parameter `m < 1`, `k' = kc`.
    fn elliptic(
        w: [Dd; 3],
        m0: [f64; 3],
        ax: &TriaxialAxes,
        amp: &Amplitudes,
        kc: f64,
    ) -> Result<Self> {
        let (mb, mr, ms) = (m0[ax.b], m0[ax.r], m0[ax.s]);
        let Amplitudes {
            x,
            omega,
            s_amp,
            r_amp,
            ..
        } = *amp;
        let q = (ax.a_ * ax.b_).sqrt() * x / omega;
        let m = (q * q).min(1.0);
        let jac = Jacobi::with_kc(m, kc.min(1.0))?;
        let m1 = kc * kc;
        // The initial point from its own sn, cn, dn (not from an amplitude,
        // which near ±K loses ε/dn; see Jacobi::arg_from).
        let u0 = jac.arg_from(
            (mb / x).clamp(-1.0, 1.0),
            (mr / r_amp).clamp(-1.0, 1.0),
            (ms / s_amp).clamp(0.0, 1.0),
        )?;
        let period = 4.0 * jac.quarter_period();
        let nu = omega / period;
        Ok(EulerTop {
            m0,
            w,
            motion: Motion::Elliptic {
                idx: [ax.b, ax.r, ax.s],
                amp: [x, r_amp, s_amp],
                jac: Box::new(jac),
                nu,
                x0: u0 / period,
            },
            regime: EulerRegime::Elliptic,
            params: [m, m1, omega],
        })
    }

    /// The regime of the motion.
    pub fn regime(&self) -> EulerRegime {
        self.regime
    }

    /// The initial `M`.
    pub fn m0(&self) -> [f64; 3] {
        self.m0
    }

    /// The coefficients `W` (rounded to doubles).
    pub fn w(&self) -> [f64; 3] {
        self.w.map(|x| x.to_f64())
    }

    /// `(m, 1 − m, ω)` of the elliptic form (`m = 0`, `ω = |Ω|` when
    /// axisymmetric; `m = 1` on the separatrix; NaN at rest).
    pub fn parameters(&self) -> [f64; 3] {
        self.params
    }

    /// The frequency of `M(t)` in cycles per unit time: `ω/(4K)` (elliptic),
    /// `|Ω|/(2π)` (axisymmetric), `0` on the separatrix (its period is
    /// infinite; `ω/(4K) → 0` as `m → 1`) and at rest.
    pub fn frequency(&self) -> f64 {
        match &self.motion {
            Motion::Rest | Motion::Separatrix { .. } => 0.0,
            Motion::Rotation { nu, .. } => nu.abs(),
            Motion::Elliptic { nu, .. } => *nu,
        }
    }

    /// `M(t)`. Non-finite `t` gives NaN (callers check `t`).
    #[inline]
    pub fn m(&self, t: f64) -> [f64; 3] {
        match &self.motion {
            Motion::Rest => self.m0,
            Motion::Rotation { p, q, nu, mp, mq } => {
                let ang = 2.0 * std::f64::consts::PI * phase_mod1(0.0, *nu, t);
                let (sn, cs) = ang.sin_cos();
                let mut out = self.m0;
                out[*p] = mp * cs + mq * sn;
                out[*q] = mq * cs - mp * sn;
                out
            }
            Motion::Elliptic {
                idx,
                amp,
                jac,
                nu,
                x0,
            } => {
                let (sn, cn, dn) = jac.sncndn_phase(phase_mod1(*x0, *nu, t));
                let mut out = [0.0; 3];
                out[idx[0]] = amp[0] * sn;
                out[idx[1]] = amp[1] * cn;
                out[idx[2]] = amp[2] * dn;
                out
            }
            Motion::Separatrix {
                idx,
                amp,
                omega,
                u0,
            } => {
                let u = omega.mul_add(t, *u0);
                let sech = 1.0 / u.cosh();
                let mut out = [0.0; 3];
                out[idx[0]] = amp[0] * u.tanh();
                out[idx[1]] = amp[1] * sech;
                out[idx[2]] = amp[2] * sech;
                out
            }
        }
    }
}

/// How an Euler top sits in so(4) (state order `(l12, l13, l14, l23, l24, l34)`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Embedding {
    /// The so(3) block on the indices `{i, j, k}` (0-based, increasing).
    Block([usize; 3]),
    /// `n = σ m` with `σ = +1` (self-dual) or `−1` (anti-self-dual).
    SelfDual(i8),
}

/// Position of `l_ij` (`i < j`, 0-based) in the so(4) state.
fn pos(i: usize, j: usize) -> usize {
    match (i, j) {
        (0, 1) => 0,
        (0, 2) => 1,
        (0, 3) => 2,
        (1, 2) => 3,
        (1, 3) => 4,
        _ => 5,
    }
}

impl Embedding {
    /// The four so(3) blocks.
    pub const BLOCKS: [[usize; 3]; 4] = [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]];

    /// The embedding whose invariant subspace holds `l` exactly (components
    /// compared as doubles, no tolerance), if any. States with at most one
    /// non-zero component, or two that share no index, are equilibria and
    /// are classified before this is asked.
    pub fn of_state(l: &[f64; 6]) -> Option<Embedding> {
        for blk in Self::BLOCKS {
            let [i, j, k] = blk;
            let inside = [pos(i, j), pos(i, k), pos(j, k)];
            if (0..6).all(|q| inside.contains(&q) || l[q] == 0.0) {
                return Some(Embedding::Block(blk));
            }
        }
        let m = [l[3], -l[1], l[0]];
        let n = [l[2], l[4], l[5]];
        if m == n {
            return Some(Embedding::SelfDual(1));
        }
        if m.iter().zip(&n).all(|(x, y)| *x == -*y) {
            return Some(Embedding::SelfDual(-1));
        }
        None
    }

    /// `M` of the state `l` (the inverse of [`Embedding::state`] on the subspace).
    pub fn m_of(&self, l: &[f64; 6]) -> [f64; 3] {
        match *self {
            Embedding::Block([i, j, k]) => [l[pos(j, k)], -l[pos(i, k)], l[pos(i, j)]],
            Embedding::SelfDual(_) => [l[3], -l[1], l[0]],
        }
    }

    /// The state `l` of `M`.
    pub fn state(&self, m: &[f64; 3]) -> [f64; 6] {
        let mut l = [0.0; 6];
        match *self {
            Embedding::Block([i, j, k]) => {
                l[pos(j, k)] = m[0];
                l[pos(i, k)] = -m[1];
                l[pos(i, j)] = m[2];
            }
            Embedding::SelfDual(sg) => {
                let s = f64::from(sg);
                l[0] = m[2];
                l[1] = -m[1];
                l[3] = m[0];
                l[2] = s * m[0];
                l[4] = s * m[1];
                l[5] = s * m[2];
            }
        }
        l
    }

    /// The Euler coefficients `W` of the top with Manakov's `c` (state
    /// order): `−(c_jk, c_ik, c_ij)` for a block, `−(c_kl + c_j4)` (exact, as
    /// double-doubles) for a self-dual state.
    pub(crate) fn w_of(&self, c4: &[f64; 6]) -> [Dd; 3] {
        match *self {
            Embedding::Block([i, j, k]) => [
                Dd::new(-c4[pos(j, k)]),
                Dd::new(-c4[pos(i, k)]),
                Dd::new(-c4[pos(i, j)]),
            ],
            Embedding::SelfDual(_) => [
                Dd::sum(-c4[3], -c4[2]),
                Dd::sum(-c4[1], -c4[4]),
                Dd::sum(-c4[0], -c4[5]),
            ],
        }
    }

    /// A name for messages and the Python API: `"block 123"` … `"block 234"`
    /// (1-based indices), `"self-dual"`, `"anti-self-dual"`.
    pub fn name(&self) -> String {
        match *self {
            Embedding::Block([i, j, k]) => format!("block {}{}{}", i + 1, j + 1, k + 1),
            Embedding::SelfDual(1) => "self-dual".into(),
            Embedding::SelfDual(_) => "anti-self-dual".into(),
        }
    }
}

#[cfg(test)]
mod tests;
