//! The Theorem (9)–(10): the state `l(t)` as a quotient of genus-2 theta
//! functions whose argument moves on a straight line, `v(t) = v0 + U t`.
//!
//! The chain (docs/theorem.md, equation numbers Perelomov's, corrections in
//! docs/errata.md):
//!
//! * the reduction of `l0` ([`crate::kotter`]): the level-set constants
//!   (`d_j`, `α_j … δ_j` of the corrected (24), `K`, `ε` of the corrected
//!   (40)), the points `(z_i, y_i)`, `g` and the branch of the `P_j`, all fixed
//!   once per solution;
//! * the curve (8) as a [`HyperellipticCurve`] with branch points
//!   `(d_0, …, d_4)`: `τ`, the Abel map `u` (base point ∞) and the Riemann
//!   constant `K_R`; `v = u(P1) + u(P2) + K_R`;
//! * (34): `P_L = C_L θ[χ_L](v)/θ(v)`, `χ_j = η(d_j)`, `χ_jk = χ_j + χ_k`, with
//!   `C_L²` from a well-conditioned auxiliary divisor and the sign of `C_L`
//!   from the initial state;
//! * (37) and the corrected (42): `ξ_j = √c_j g P_kl`, `η_j = √c_j g P_j4`,
//!   `g = G/(1 − ε P_0)`, `G = √(h0/K)`, so `ξ_j = √c_j G C_kl θ_kl/D`,
//!   `η_j = √c_j G C_j4 θ_j4/D` with the common denominator
//!   `D(v) = θ(v) − ε C_0 θ_0(v)`;
//! * (23): `l` is linear in `ξ, η`, hence `l_q(v) = N_q(v)/D(v)` with
//!   `N_q` a fixed combination of six theta functions — (9)–(10) as they truly read;
//! * `U` from the equations of motion: `d l/dt = (1)` at `v0` and
//!   `d l/dt = (∇N_q − l_q ∇D)·U / D`, a 6 × 2 complex linear system solved
//!   by least squares (theta gradients at `v0`).
//!
//! Evaluation at large `t`: `v = x + τ y` with real lattice coordinates
//! `x(t) = x0 + X t`, `y(t) = y0 + Y t`, reduced modulo 2 (an even lattice
//! vector multiplies every `θ[χ]` by one common factor, so the quotients are
//! exact); the products `X t`, `Y t` are split error-free (fma), so the phase
//! keeps its digits at `t = 10^6`.

use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;
use rayon::prelude::*;

use crate::curve::{KotterCurve, CYCLIC};
use crate::error::{Error, Result, SingularKind};
use crate::kotter::{kotter_constants, kotter_with, KotterConstants, KotterState};
use crate::numeric::cancel::Cancel;
use crate::numeric::complex::sqrt_principal;
use crate::numeric::tol::SINGULAR_SET_RTOL;
use crate::riemann::HyperellipticCurve;
use crate::so4;
use crate::theta::{char_index, LatticeLanes, SelectedBlock, ThetaJet, ThetaPlan, BLOCK};

pub mod velocity;

type C = Complex64;

/// Truncation tolerance of the theta sums (absolute, on normalised values):
/// below the rounding of the quotients.
pub const THETA_TOL: f64 = 1e-16;

/// The divisor of `l0` contains ∞ (the `P_L` have poles) when `θ(v0)` is
/// this small relative to the largest `|θ[χ](v0)|`.
pub const DIVISOR_AT_INFINITY_RTOL: f64 = 1e-10;

/// The estimate of the `C_L²` at `v0` takes part in the consensus of
/// [`aux_constants_squared`] when every needed `|θ[χ](v0)|` is at least this
/// fraction of the largest (below, the quotient `P_L θ/θ_L` loses digits).
const AUX_V0_MIN: f64 = 1e-3;

/// Times per work unit between two cancellation checks (~2 ms on one core).
const CHUNK: usize = 8192;

/// Smallest piece handed to one thread.
const PAR_PIECE: usize = 512;

/// Labels of the Wurzelfunktionen that enter (37) and (42), in the order of
/// [`Solution::constants`]: `P_0`, `P_kl` for `j = 1, 2, 3` (`kl = 23, 31, 12`),
/// `P_j4` for `j = 1, 2, 3`.
pub const LABELS: [&str; 7] = ["P0", "P23", "P31", "P12", "P14", "P24", "P34"];

/// An explicit solution of the Manakov top on the level set of `l0`.
#[derive(Debug)]
pub struct Solution {
    a: [f64; 4],
    c4: [f64; 6],
    l0: [f64; 6],
    kotter: KotterConstants,
    state0: KotterState,
    curve: HyperellipticCurve,
    plan: ThetaPlan,
    tau: [C; 4],
    rc: [C; 2],
    u0: [C; 2],
    rate: [C; 2],
    /// `x0, y0` of `v0 = x0 + τ y0`.
    lat0: [f64; 4],
    /// `X, Y` of `U = X + τ Y`.
    lat_rate: [f64; 4],
    /// Theta indices (FLINT order): `θ`, then the seven labels.
    idx: [usize; 8],
    /// Characteristics `(a, b)` of the seven labels.
    chars: [([u8; 2], [u8; 2]); 7],
    cl: [C; 7],
    /// `l_q = Re(Σ_m num[q][m] θ_idx[m] / Σ_m den[m] θ_idx[m])`.
    num: [[C; 8]; 6],
    den: [C; 8],
    calibration: [f64; 7],
}

fn singular(kind: SingularKind, reason: String) -> Error {
    Error::Singular {
        what: "state l0",
        kind,
        reason,
    }
}

/// `x + X t` reduced to `[−1, 1]` modulo 2 with `X t` split error-free.
#[inline(always)]
fn phase_mod2(x0: f64, rate: f64, t: f64) -> f64 {
    let p = rate * t;
    let e = rate.mul_add(t, -p);
    // p − 2 round(p/2) is exact (|result| ≤ 1 and both are multiples of ulp(p)).
    let r = crate::theta::rem2(p);
    crate::theta::rem2(x0 + r + e)
}

impl Solution {
    /// Sets up the solution through `l0` for the top with parameters `a, b`.
    ///
    /// Errors ([`Error::InvalidArgument`] naming the reason): `l0 = 0`;
    /// `h0 = 0`; `h1² = 4h0²`; coinciding branch points `d_j`; the divisor of
    /// `l0` at infinity (`θ(v0) = 0`); and those of the reduction.
    pub fn new(a: &[f64; 4], b: &[f64; 4], l0: &[f64; 6]) -> Result<Self> {
        crate::error::check_finite("l0", l0)?;
        let c = so4::manakov_c(a, b)?;
        // State order (12, 13, 14, 23, 24, 34) from the row-major 4 × 4 matrix.
        let c4 = [c[1], c[2], c[3], c[6], c[7], c[11]];
        let LevelSetCurve {
            kotter,
            kcurve: _,
            curve,
            chars,
        } = level_set_curve(a, l0)?;
        let state0 = kotter_with(kotter.clone(), l0).map_err(map_coinciding)?;
        let tau_rm = curve.tau_row_major();
        let tau: [C; 4] = [tau_rm[0], tau_rm[1], tau_rm[2], tau_rm[3]];
        let plan = ThetaPlan::new(&tau, 2, THETA_TOL, 1)?.with_parallel(false);
        let rcv = curve.try_riemann_constant()?;
        let rc = [rcv[0], rcv[1]];

        let mut idx = [0usize; 8];
        idx[0] = char_index(&[0, 0], &[0, 0])?;
        for (m, ch) in chars.iter().enumerate() {
            idx[m + 1] = char_index(&ch.0, &ch.1)?;
        }

        // The divisor of l0 and v0 = u(P1) + u(P2) + K.
        let pts = &state0.points;
        let ua = abel_of_point(&curve, pts.z1, pts.y1, &pts.zd1)?;
        let ub = abel_of_point(&curve, pts.z2, pts.y2, &pts.zd2)?;
        let u0 = [ua[0] + ub[0], ua[1] + ub[1]];
        let v0 = [u0[0] + rc[0], u0[1] + rc[1]];
        let jet = plan.jet(&v0, 1)?;
        let big = jet.values.iter().fold(0.0f64, |m, v| m.max(v.norm()));
        let th0 = jet.values[idx[0]];
        if th0.norm() <= DIVISOR_AT_INFINITY_RTOL * big {
            return Err(singular(
                SingularKind::DivisorAtInfinity,
                format!(
                    "the divisor of l0 contains the point at infinity of the curve (8) \
                 (|theta(v0)| = {:e} of max |theta[chi](v0)|): the P_L (34) have poles there; \
                 the solution exists (take l0 at another time of the same trajectory)",
                    th0.norm() / big
                ),
            ));
        }

        // P_L at l0 in the branch of the reduction: (37) inverted with the
        // reduction's g ((30a), sign fixed by the corrected (42)), P_0 from (31b).
        let sc = state0.curve.c().map(sqrt_principal);
        let eps = eps41(&kotter);
        let g = state0.points.g;
        let mut p_at0 = [C::new(0.0, 0.0); 7];
        p_at0[0] = state0.p0;
        for j in 0..3 {
            p_at0[1 + j] = state0.xi[j] / (sc[j] * g);
            p_at0[4 + j] = state0.eta[j] / (sc[j] * g);
        }
        // C_L² by consensus of auxiliary divisors, in which the estimate at v0
        // votes unless a θ[χ_L](v0) is too small to divide by; the sign from l0.
        let est: [C; 7] = std::array::from_fn(|m| p_at0[m] * th0 / jet.values[idx[m + 1]]);
        let qv0 = idx
            .iter()
            .map(|&i| jet.values[i].norm() / big)
            .fold(f64::INFINITY, f64::min);
        let est0 = (qv0 > AUX_V0_MIN).then(|| est.map(|r| r * r));
        let c2 = aux_constants_squared(&curve, &state0.curve, &plan, &idx, &rc, est0)?;
        let mut cl = [C::new(0.0, 0.0); 7];
        let mut calibration = [0.0; 7];
        for m in 0..7 {
            let root = sqrt_principal(c2[m]);
            let (plus, minus) = ((est[m] - root).norm(), (est[m] + root).norm());
            cl[m] = if plus <= minus { root } else { -root };
            calibration[m] = plus.min(minus) / root.norm();
        }
        // G = g (1 − ε P_0) at v0 from the theta side: the P_L(v0) of the
        // calibrated (34), g by least squares from the six equations (37)
        // `(ξ_j, η_j) = √c_j g P_L(v0)`. The reduction's own g, P_0 ((30a), (31b))
        // are sums that cancel when the |d_j| spread over many orders of
        // magnitude (P_0 loses up to 1e-6 there); the fit keeps l(v0) = l0.
        let p_th: [C; 7] = std::array::from_fn(|m| cl[m] * jet.values[idx[m + 1]] / th0);
        let (mut num_g, mut den_g) = (C::new(0.0, 0.0), 0.0);
        for j in 0..3 {
            for (w, r) in [
                (sc[j] * p_th[1 + j], state0.xi[j]),
                (sc[j] * p_th[4 + j], state0.eta[j]),
            ] {
                num_g += w.conj() * r;
                den_g += w.norm_sqr();
            }
        }
        let g_fit = if den_g > 0.0 { num_g / den_g } else { g };
        let big_g = g_fit * (C::new(1.0, 0.0) - eps * p_th[0]);

        // (37), (42), (23): l_q = N_q / D.
        let mut den = [C::new(0.0, 0.0); 8];
        den[0] = C::new(1.0, 0.0);
        den[1] = -eps * cl[0];
        let mut xi_w = [[C::new(0.0, 0.0); 8]; 3];
        let mut eta_w = [[C::new(0.0, 0.0); 8]; 3];
        for j in 0..3 {
            xi_w[j][2 + j] = sc[j] * big_g * cl[1 + j];
            eta_w[j][5 + j] = sc[j] * big_g * cl[4 + j];
        }
        let mut mw = [[C::new(0.0, 0.0); 8]; 3];
        let mut nw = [[C::new(0.0, 0.0); 8]; 3];
        for j in 0..3 {
            for s in 0..8 {
                mw[j][s] = kotter.alpha[j] * xi_w[j][s] + kotter.beta[j] * eta_w[j][s];
                nw[j][s] = kotter.gamma[j] * xi_w[j][s] + kotter.delta[j] * eta_w[j][s];
            }
        }
        let neg = |w: [C; 8]| w.map(|v| -v);
        // l = (m3, −m2, n1, m1, n2, n3)
        let num = [mw[2], neg(mw[1]), nw[0], mw[0], nw[1], nw[2]];

        // U from (1) by least squares at v0 (see [`VelocitySystem`]); a set-up
        // whose quotients fit (1) for no velocity is refused.
        let (rate, residual) = VelocitySystem::at(&jet, &idx, &num, &den)?.rate(&c4, "U")?;
        check_velocity_fit(residual)?;
        let (x0, y0) = curve.lattice_coordinates(&v0);
        let (xr, yr) = curve.lattice_coordinates(&rate);
        Ok(Solution {
            a: *a,
            c4,
            l0: *l0,
            kotter,
            state0,
            curve,
            plan,
            tau,
            rc,
            u0,
            rate,
            lat0: [x0[0], x0[1], y0[0], y0[1]],
            lat_rate: [xr[0], xr[1], yr[0], yr[1]],
            idx,
            chars,
            cl,
            num,
            den,
            calibration,
        })
    }

    /// The state the solution starts from.
    pub fn l0(&self) -> &[f64; 6] {
        &self.l0
    }

    /// The parameters `a`.
    pub fn a(&self) -> &[f64; 4] {
        &self.a
    }

    /// The Manakov `c_ij` (2), state order.
    pub fn c4(&self) -> &[f64; 6] {
        &self.c4
    }

    /// The level-set constants of the reduction (fixed branches).
    pub fn kotter(&self) -> &KotterConstants {
        &self.kotter
    }

    /// The reduction of `l0`.
    pub fn state0(&self) -> &KotterState {
        &self.state0
    }

    /// The curve (8) with its homology basis, periods and Abel map.
    pub fn curve(&self) -> &HyperellipticCurve {
        &self.curve
    }

    /// The theta plan of `τ` (first derivatives, serial), shared with
    /// callers that evaluate the quotients themselves.
    pub fn plan(&self) -> &ThetaPlan {
        &self.plan
    }

    /// The velocities on this level set of the Manakov flows with
    /// coefficients `c4s` (state order), each with the relative residual of
    /// its least-squares fit: the equations that give [`Solution::rate`], with
    /// other right-hand sides (the curve, the divisor and the quotients depend
    /// on `a` and `l0` only). For the solution's own `c4` this is `U`.
    pub fn rates(&self, c4s: &[[f64; 6]]) -> Result<Vec<([C; 2], f64)>> {
        let v0 = [self.u0[0] + self.rc[0], self.u0[1] + self.rc[1]];
        let jet = self.plan.jet(&v0, 1)?;
        let sys = VelocitySystem::at(&jet, &self.idx, &self.num, &self.den)?;
        c4s.iter().map(|c4| sys.rate(c4, "U'")).collect()
    }

    /// `τ`, row-major.
    pub fn tau(&self) -> [C; 4] {
        self.tau
    }

    /// The vector of Riemann constants `K_R` (`v = u + K_R`).
    pub fn riemann_constant(&self) -> [C; 2] {
        self.rc
    }

    /// `u0 = u(P1) + u(P2)`, the Abel image of the divisor of `l0`.
    pub fn u0(&self) -> [C; 2] {
        self.u0
    }

    /// `U`: `u(t) = u0 + U t`.
    pub fn rate(&self) -> [C; 2] {
        self.rate
    }

    /// The velocities of the flows with coefficients `c4s` on this level set
    /// from the chain rule at auxiliary divisors ([`velocity::algebraic_rates`]),
    /// in the sign convention of this solution: the first flow's velocity is
    /// compared with the theta-side fit of the same flow at `v0`
    /// ([`Solution::rates`]).
    ///
    /// Errors: those of [`velocity::algebraic_rates`], and the two routes
    /// disagreeing on the first flow by more than [`QUOTIENT_RESIDUAL_RTOL`]
    /// relative ([`INCONSISTENT`]). Both use the principal `G` of (42), so no
    /// sign is flipped here: a flipped sign would be such a disagreement.
    pub fn algebraic_rates(&self, c4s: &[[f64; 6]]) -> Result<velocity::AlgebraicRates> {
        let alg = velocity::algebraic_rates(
            &self.kotter,
            &self.state0.curve,
            &a_periods_of(&self.curve),
            c4s,
        )?;
        let reference = self.rates(&c4s[..1])?[0].0;
        let u = alg.rates[0];
        let dev = (u[0] - reference[0])
            .norm()
            .max((u[1] - reference[1]).norm());
        let scale = reference[0].norm().max(reference[1].norm());
        if dev.is_nan() || dev > QUOTIENT_RESIDUAL_RTOL * scale {
            return Err(Error::InvalidArgument {
                what: INCONSISTENT,
                reason: format!(
                    "the velocity by the chain rule at auxiliary divisors differs from the \
                     theta quotients' at v0 by {dev:e} (|U| = {scale:e})"
                ),
            });
        }
        Ok(alg)
    }

    /// Characteristics `(a, b)` of [`LABELS`].
    pub fn characteristics(&self) -> [([u8; 2], [u8; 2]); 7] {
        self.chars
    }

    /// `C_L` of (34) for [`LABELS`]: `P_L = C_L θ[χ_L](v)/θ(v)`.
    pub fn constants(&self) -> [C; 7] {
        self.cl
    }

    /// `|C_L − P_L(l0) θ(v0)/θ[χ_L](v0)| / |C_L|`: the agreement of the
    /// auxiliary-divisor constants with the initial state.
    pub fn calibration(&self) -> [f64; 7] {
        self.calibration
    }

    /// Coefficients of (9)–(10) as they read: `l_q = N_q/D`,
    /// `N_q = Σ_m num[q][m] θ[idx[m]]`, `D = Σ_m den[m] θ[idx[m]]`.
    pub fn quotient(&self) -> ([usize; 8], [[C; 8]; 6], [C; 8]) {
        (self.idx, self.num, self.den)
    }

    /// The Abel image `u(P1) + u(P2)` of a state on the same level set (the
    /// branches of `l0`'s reduction), modulo the lattice.
    pub fn abel(&self, l: &[f64; 6]) -> Result<[C; 2]> {
        let st = kotter_with(self.kotter.clone(), l)?;
        let p = &st.points;
        let ua = abel_of_point(&self.curve, p.z1, p.y1, &p.zd1)?;
        let ub = abel_of_point(&self.curve, p.z2, p.y2, &p.zd2)?;
        Ok([ua[0] + ub[0], ua[1] + ub[1]])
    }

    /// Lattice coordinates `(x, y)` of `v(t) = x + τ y`, reduced modulo 2.
    #[inline]
    pub fn lattice_reduced(&self, t: f64) -> ([f64; 2], [f64; 2]) {
        (
            [
                phase_mod2(self.lat0[0], self.lat_rate[0], t),
                phase_mod2(self.lat0[1], self.lat_rate[1], t),
            ],
            [
                phase_mod2(self.lat0[2], self.lat_rate[2], t),
                phase_mod2(self.lat0[3], self.lat_rate[3], t),
            ],
        )
    }

    /// `v(t) = v0 + U t` reduced modulo twice the lattice.
    #[inline]
    pub fn v_reduced(&self, t: f64) -> [C; 2] {
        let (x, y) = self.lattice_reduced(t);
        [
            C::new(x[0], 0.0) + self.tau[0] * y[0] + self.tau[1] * y[1],
            C::new(x[1], 0.0) + self.tau[2] * y[0] + self.tau[3] * y[1],
        ]
    }

    /// `l_q = Re(N_q/D)` for the points of one theta block (rows `m` of
    /// `blk` are `θ_idx[m]`), written to `out` (row-major, `blk.len` rows);
    /// only real parts are formed: `Re(N/D) = Re(N D̄)/|D|²`. The sums run
    /// over the block's points in its own structure-of-arrays layout, so they
    /// vectorise; each is the complex product and the sum over `m` in the
    /// order of the per-point form, so the bits are the same.
    fn combine(&self, blk: &SelectedBlock, out: &mut [f64]) {
        #[cfg(target_arch = "x86_64")]
        {
            if std::is_x86_feature_detected!("avx2") {
                // SAFETY: the CPU supports AVX2 (checked just above).
                return unsafe { self.combine_avx2(blk, out) };
            }
        }
        self.combine_body(blk, out)
    }

    /// [`Solution::combine`] compiled for AVX2: four points per instruction
    /// (no FMA: the products and sums round as in the baseline, same bits).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn combine_avx2(&self, blk: &SelectedBlock, out: &mut [f64]) {
        self.combine_body(blk, out)
    }

    #[inline(always)]
    fn combine_body(&self, blk: &SelectedBlock, out: &mut [f64]) {
        const P: usize = crate::theta::BLOCK;
        // A function, not a closure, so that it inlines into the AVX2 copy.
        #[inline(always)]
        fn weighted(blk: &SelectedBlock, w: &[C; 8]) -> ([f64; P], [f64; P]) {
            let (mut re, mut im) = ([0.0; P], [0.0; P]);
            for (m, w) in w.iter().enumerate() {
                // Each row of (23) has two nonzero weights of eight (`ξ_j`
                // and `η_j`); an exact zero adds nothing to a finite sum.
                if w.re == 0.0 && w.im == 0.0 {
                    continue;
                }
                let (tr, ti) = (&blk.re[m], &blk.im[m]);
                for p in 0..P {
                    re[p] += w.re * tr[p] - w.im * ti[p];
                    im[p] += w.re * ti[p] + w.im * tr[p];
                }
            }
            (re, im)
        }
        let (dre, dim) = weighted(blk, &self.den);
        let inv: [f64; P] = std::array::from_fn(|p| 1.0 / (dre[p] * dre[p] + dim[p] * dim[p]));
        for (q, w) in self.num.iter().enumerate() {
            let (nre, nim) = weighted(blk, w);
            for (p, o) in out.chunks_exact_mut(6).enumerate().take(blk.len) {
                o[q] = (nre[p] * dre[p] + nim[p] * dim[p]) * inv[p];
            }
        }
    }

    /// [`Solution::lattice_reduced`] for the times `t` of one block (at most
    /// [`BLOCK`]) into lanes `0..t.len()`; the other lanes get those of
    /// `t = 0`, so that every lane is computed and the loops vectorise.
    fn lattice_lanes(&self, t: &[f64], lanes: &mut LatticeLanes) {
        #[cfg(target_arch = "x86_64")]
        {
            if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
                // SAFETY: the CPU supports AVX2 and FMA (checked just above).
                return unsafe { self.lattice_lanes_avx2(t, lanes) };
            }
        }
        self.lattice_lanes_body(t, lanes)
    }

    /// [`Solution::lattice_lanes`] compiled for AVX2 with FMA: the
    /// error-free product of [`phase_mod2`] is one instruction instead of a
    /// library call, and it rounds exactly as that call does (same bits).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn lattice_lanes_avx2(&self, t: &[f64], lanes: &mut LatticeLanes) {
        self.lattice_lanes_body(t, lanes)
    }

    #[inline(always)]
    fn lattice_lanes_body(&self, t: &[f64], lanes: &mut LatticeLanes) {
        let mut tt = [0.0; BLOCK];
        tt[..t.len()].copy_from_slice(t);
        for k in 0..2 {
            for (p, &t) in tt.iter().enumerate() {
                lanes.x[k][p] = phase_mod2(self.lat0[k], self.lat_rate[k], t);
                lanes.y[k][p] = phase_mod2(self.lat0[2 + k], self.lat_rate[2 + k], t);
            }
        }
    }

    fn eval_serial(&self, t: &[f64], out: &mut [f64]) -> Result<()> {
        self.plan.eval_selected_g2_lattice_lanes(
            t.len(),
            |first, m, lanes| self.lattice_lanes(&t[first..first + m], lanes),
            &self.idx,
            |first, blk| self.combine(blk, &mut out[6 * first..6 * (first + blk.len)]),
        )
    }

    /// `l(t_k)` into `out` (row-major `(N, 6)`); rayon for large batches,
    /// `cancel` checked between chunks.
    ///
    /// Errors: non-finite `t`, wrong `out` size, [`Error::Interrupted`].
    pub fn l_batch(&self, t: &[f64], out: &mut [f64], cancel: &Cancel) -> Result<()> {
        if out.len() != 6 * t.len() {
            return Err(Error::Shape {
                what: "out",
                expected: format!("({}, 6)", t.len()),
                got: format!("{} entries", out.len()),
            });
        }
        crate::error::check_finite("t", t)?;
        let threads = rayon::current_num_threads();
        let unit = CHUNK * threads.max(1);
        for (tc, oc) in t.chunks(unit).zip(out.chunks_mut(6 * unit)) {
            cancel.check()?;
            if threads > 1 && tc.len() >= 2 * PAR_PIECE {
                let piece = tc.len().div_ceil(4 * threads).max(PAR_PIECE);
                tc.par_chunks(piece)
                    .zip(oc.par_chunks_mut(6 * piece))
                    .try_for_each(|(tp, op)| self.eval_serial(tp, op))?;
            } else {
                self.eval_serial(tc, oc)?;
            }
        }
        Ok(())
    }

    /// [`Solution::l_batch`] on the calling thread only (for benchmarks and
    /// callers that parallelise themselves).
    pub fn l_batch_serial(&self, t: &[f64], out: &mut [f64], cancel: &Cancel) -> Result<()> {
        if out.len() != 6 * t.len() {
            return Err(Error::Shape {
                what: "out",
                expected: format!("({}, 6)", t.len()),
                got: format!("{} entries", out.len()),
            });
        }
        crate::error::check_finite("t", t)?;
        for (tc, oc) in t.chunks(CHUNK).zip(out.chunks_mut(6 * CHUNK)) {
            cancel.check()?;
            self.eval_serial(tc, oc)?;
        }
        Ok(())
    }

    /// `l(t)` at one time.
    pub fn l(&self, t: f64) -> Result<[f64; 6]> {
        let mut out = [0.0; 6];
        self.l_batch(&[t], &mut out, &Cancel::never())?;
        Ok(out)
    }
}

/// Relative least-squares residual of the velocity equations
/// `(∇N_q − l_q ∇D)·U = l̇_q D` above which the theta quotients at `v0` solve
/// Frahm's equations (1) for no velocity: the set-up is wrong, and the
/// solution is refused rather than returned. Consistent set-ups leave ~1e-13
/// (≤ 1e-10 on near_degenerate); the set-ups that took the wrong combination
/// of (41) left 1e-2 … 1.
pub const QUOTIENT_RESIDUAL_RTOL: f64 = 1e-6;

/// `what` of the error for quotients that solve (1) for no velocity.
pub const INCONSISTENT: &str = "theta quotients at v0";

/// The velocity equations at `v0`: `l_q = N_q(v)/D(v)` gives
/// `(∇N_q − l_q ∇D)·U = l̇_q D`, six complex equations for `U ∈ C²`, with the
/// gradients from the theta jet at `v0`. The rows are the components of `l`
/// themselves, unscaled (they share the scale `|l|`), and `l̇` is (1) at the
/// quotient's own value `l_q(v0)` (it differs from `l0` by the rounding of the
/// constants, ~1e-13): `U` is then the rate of the theta quotient's own flow.
/// On tops with a nearly symmetric pair `a_i ≈ a_j` (`|U|` ~ 100) this keeps
/// `U` to ~1e-14, where rows in `ξ, η` scaled to unit size lost up to 1e-12 of
/// `U` (1e-9 of `l` at `t = 20`).
struct VelocitySystem {
    amat: DMatrix<C>,
    svd: nalgebra::SVD<C, nalgebra::Dyn, nalgebra::Dyn>,
    lq: [f64; 6],
    dval: C,
}

impl VelocitySystem {
    /// Errors: [`SingularKind::DegenerateGradients`] when the two singular
    /// values differ by more than 1e12 (`U` is not determined).
    fn at(jet: &ThetaJet, idx: &[usize; 8], num: &[[C; 8]; 6], den: &[C; 8]) -> Result<Self> {
        let theta = |m: usize| jet.values[idx[m]];
        let grad = |m: usize, k: usize| jet.gradient[idx[m] * 2 + k];
        let dval: C = (0..8).map(|m| den[m] * theta(m)).sum();
        let dgrad: [C; 2] = std::array::from_fn(|k| (0..8).map(|m| den[m] * grad(m, k)).sum());
        let lq: [C; 6] =
            std::array::from_fn(|q| (0..8).map(|m| num[q][m] * theta(m)).sum::<C>() / dval);
        let mut amat = DMatrix::<C>::zeros(6, 2);
        for (q, w) in num.iter().enumerate() {
            for k in 0..2 {
                let ng: C = (0..8).map(|m| w[m] * grad(m, k)).sum();
                amat[(q, k)] = ng - lq[q] * dgrad[k];
            }
        }
        let svd = amat.clone().svd(true, true);
        let sv = &svd.singular_values;
        if sv[1].is_nan() || sv[1] <= 1e-12 * sv[0] {
            return Err(Error::Singular {
                what: "state l0",
                kind: SingularKind::DegenerateGradients,
                reason: format!(
                    "the theta-quotient gradients at v0 are degenerate (singular values {:e}, {:e}): \
                     U is not determined",
                    sv[0], sv[1]
                ),
            });
        }
        Ok(VelocitySystem {
            amat,
            svd,
            lq: lq.map(|z| z.re),
            dval,
        })
    }

    /// The velocity of the flow with coefficients `c4` and the relative
    /// residual `|A U − r| / |r|` of its fit.
    fn rate(&self, c4: &[f64; 6], what: &'static str) -> Result<([C; 2], f64)> {
        let ldot = so4::vector_field4(c4, &self.lq);
        let rhs = DVector::<C>::from_fn(6, |q, _| ldot[q] * self.dval);
        let x = self
            .svd
            .solve(&rhs, 0.0)
            .map_err(|e| Error::InvalidArgument {
                what,
                reason: e.to_string(),
            })?;
        let u = [x[0], x[1]];
        if !u.iter().all(|v| v.re.is_finite() && v.im.is_finite()) {
            return Err(Error::NonFinite { what, index: 0 });
        }
        let res = (&self.amat * &x - &rhs).norm() / rhs.norm().max(f64::MIN_POSITIVE);
        Ok((u, res))
    }
}

/// Refuses a set-up whose quotients fit (1) for no velocity (least-squares
/// residual above [`QUOTIENT_RESIDUAL_RTOL`]): a guard against a wrong
/// constant or branch, which reproduces `l0` at `t = 0` and is O(1) wrong later.
fn check_velocity_fit(res: f64) -> Result<()> {
    if res.is_nan() || res > QUOTIENT_RESIDUAL_RTOL {
        return Err(Error::InvalidArgument {
            what: INCONSISTENT,
            reason: format!(
                "the theta quotients (9)-(10) at v0 satisfy Frahm's equations (1) for no \
                 velocity (least-squares residual {res:e} > {QUOTIENT_RESIDUAL_RTOL:e}): a \
                 constant or branch of the set-up is wrong at this state; please report it"
            ),
        });
    }
    Ok(())
}

/// `ε` by the corrected (41), in root differences of `F`: with
/// `Y = √((s2−s3)(s1−s4))`, `W = √((s1−s3)(s2−s4))`, `Z = √((s1−s2)(s3−s4))`
/// the two combinations `(Y ∓ W)/(√d_4 Z)` are `ε` and `−1/(d_4 ε)`
/// (`Y² − W² = −Z²`), and principal roots do not tell which is which; the
/// one (and the sign) nearest the reduction's `ε` (corrected (40)) is taken.
/// (41) serves because it keeps its digits where (40)'s sums cancel.
fn eps41(k: &KotterConstants) -> C {
    let s = k.s;
    let sq = sqrt_principal;
    let sd4 = k.sqrt_d[0] * k.sqrt_d[1] * k.sqrt_d[2];
    let y = sq((s[1] - s[2]) * (s[0] - s[3]));
    let w = sq((s[0] - s[2]) * (s[1] - s[3]));
    let den = sd4 * sq((s[0] - s[1]) * (s[2] - s[3]));
    [(y - w) / den, (y + w) / den]
        .into_iter()
        .flat_map(|e| [e, -e])
        .min_by(|p, q| (p - k.eps).norm().total_cmp(&(q - k.eps).norm()))
        .unwrap_or(k.eps)
}

/// The Abel map takes the route from the nearest branch point `d_b` with the
/// reduction's offset `z − d_b` when that offset is below this fraction of
/// `|z|`: the double `z` fixes `z − d_b` only to `u |z|` absolute (u the unit
/// roundoff), so below it the local parameter `√(z − d_b)` would lose
/// `u |z| / |z − d_b|` of its digits; the offset keeps them.
const NEAR_BRANCH_FRACTION: f64 = 0.1;

/// The Abel map of a point of the divisor: from its offsets `zd[j] = z − d_j`
/// (full relative accuracy, [`crate::curve::WurzelPoints`]) when it is near a
/// branch point ([`HyperellipticCurve::abel_near_branch`]), else of `z`. The
/// two routes give the Abel map modulo the lattice, so a state moving across
/// the threshold may see its image jump by a lattice vector (the solution's
/// `u0` is computed once; `sol.abel` is documented modulo the lattice).
fn abel_of_point(curve: &HyperellipticCurve, z: C, y: C, zd: &[C; 5]) -> Result<Vec<C>> {
    let b = (0..5)
        .min_by(|&i, &j| zd[i].norm().total_cmp(&zd[j].norm()))
        .unwrap_or(0);
    if zd[b].norm() < NEAR_BRANCH_FRACTION * z.norm() {
        curve.abel_near_branch(b, zd[b], y)
    } else {
        curve.abel(z, y)
    }
}

/// The a-period matrix `A_ij = ∮_{a_j} x^i dx/y` of the curve, row-major.
pub fn a_periods_of(curve: &HyperellipticCurve) -> [C; 4] {
    let (a, _) = curve.periods();
    [a[(0, 0)], a[(0, 1)], a[(1, 0)], a[(1, 1)]]
}

/// The level set of a state as the reduction and the Riemann-surface layer
/// see it: Kötter's constants, the curve (8) in both forms, and the
/// characteristics `χ_L` of [`LABELS`] in the curve's homology basis.
#[derive(Debug, Clone)]
pub struct LevelSetCurve {
    /// Kötter's constants of the level set ([`kotter_constants`]).
    pub kotter: KotterConstants,
    /// The curve (8) with the Wurzelfunktionen.
    pub kcurve: KotterCurve,
    /// The same curve with periods, Abel map and theta characteristics
    /// (branch points passed as `(d_0, …, d_4)`).
    pub curve: HyperellipticCurve,
    /// `χ_0 = η(d_0)`, `χ_kl = η(d_k) + η(d_l)`, `χ_j4 = η(d_j) + η(d_4)` for
    /// the labels `P0, P23, P31, P12, P14, P24, P34`.
    pub chars: [([u8; 2], [u8; 2]); 7],
}

/// The checks of `l0` that precede the reduction, and the reduction's
/// level-set objects: refuses `l0 = 0`, `h0 = 0`, `h1² = 4h0²` (relative to
/// [`SINGULAR_SET_RTOL`]) and coinciding branch points with a
/// [`Error::Singular`] that names the reason.
pub fn level_set_curve(a: &[f64; 4], l0: &[f64; 6]) -> Result<LevelSetCurve> {
    crate::error::check_finite("l0", l0)?;
    let size = l0.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if size == 0.0 {
        return Err(singular(
            SingularKind::ZeroState,
            "l0 = 0: the rest state; the solution is l(t) = 0, there is no curve (8)".into(),
        ));
    }
    let h = so4::integrals4(a, l0);
    let s2 = size * size;
    if h[0].abs() <= SINGULAR_SET_RTOL * s2 {
        return Err(singular(
            SingularKind::VanishingH0,
            format!(
                "h0 = {:e} vanishes: the branch points d_0 = 0 and d_j coincide (F (19) has double \
                 roots), the curve (8) degenerates; the solution exists in a limiting sense \
                 (genus < 2, elementary functions), not as a genus-2 theta quotient",
                h[0]
            ),
        ));
    }
    let disc = h[1] * h[1] - 4.0 * h[0] * h[0];
    if disc.abs() <= SINGULAR_SET_RTOL * (h[1] * h[1] + 4.0 * h[0] * h[0]) {
        return Err(singular(
            SingularKind::SelfDual,
            format!(
                "h1^2 - 4 h0^2 = {disc:e} vanishes (m = ±n, a self-dual state): F (19) is not \
                 defined; the motion reduces to an so(3) top (elliptic functions), the \
                 genus-2 solution exists only as a limit"
            ),
        ));
    }
    let kotter = kotter_constants(a, l0).map_err(map_coinciding)?;
    let [d1, d2, d3] = kotter.d;
    let kcurve = KotterCurve::new(d1, d2, d3).map_err(map_coinciding)?;
    let curve = HyperellipticCurve::new(&kcurve.branch_points()).map_err(map_coinciding)?;
    // χ_j = η(d_j) (index j of the branch points passed), χ_jk = χ_j + χ_k mod 2.
    let mut eta = [([0u8; 2], [0u8; 2]); 5];
    for (j, e) in eta.iter_mut().enumerate() {
        let (ca, cb) = curve.try_branch_char(j)?;
        *e = ([ca[0], ca[1]], [cb[0], cb[1]]);
    }
    let sum = |p: usize, q: usize| {
        (
            [
                (eta[p].0[0] + eta[q].0[0]) % 2,
                (eta[p].0[1] + eta[q].0[1]) % 2,
            ],
            [
                (eta[p].1[0] + eta[q].1[0]) % 2,
                (eta[p].1[1] + eta[q].1[1]) % 2,
            ],
        )
    };
    let mut chars = [([0u8; 2], [0u8; 2]); 7];
    chars[0] = eta[0];
    for (j, &(_, k, l)) in CYCLIC.iter().enumerate() {
        chars[1 + j] = sum(k, l);
        chars[4 + j] = sum(j + 1, 4);
    }
    Ok(LevelSetCurve {
        kotter,
        kcurve,
        curve,
        chars,
    })
}

fn map_coinciding(e: Error) -> Error {
    match e {
        Error::RepeatedBranchPoints { i, j, value } => coinciding(i, j, value),
        other => other,
    }
}

fn coinciding(i: usize, j: usize, value: C) -> Error {
    let reason = format!(
        "branch points d{i} and d{j} of the curve (8) coincide (= {value}){}: the genus drops, \
         the motion is degenerate (the solution exists as a limit in lower-genus functions)",
        if i == 0 || j == 0 {
            ", i.e. h0 = 0 or a vanishing d_j"
        } else {
            ""
        }
    );
    Error::Singular {
        what: "state l0",
        kind: SingularKind::CoincidingBranchPoints,
        reason,
    }
}

/// Relative agreement of two estimates of the `C_L²` that counts as a vote
/// in [`aux_constants_squared`]: estimates from well-conditioned divisors
/// agree to ~1e-14, a poorly conditioned one misses by 1e-10 … 1e-5.
const AUX_AGREE_RTOL: f64 = 1e-12;

/// `C_L² = P_L² θ(v)²/θ_L(v)²` by consensus over a few fixed divisors and the
/// estimate `est0` at `v0` (`None` where a `θ_L(v0)` is too small to divide by).
///
/// A single divisor is not enough: where the branch points span many orders
/// of magnitude (`|d_4| / |d_3|` up to 1e10 when two `a_j` nearly coincide), a
/// divisor at the scale of the largest one loses up to 1e-9 of `C_L²` (a
/// common factor in all seven), while divisors at the geometric mean of the
/// scales keep roundoff. So four divisors are placed at the geometric-mean
/// scale, four more at the outer scale only if fewer than three estimates
/// agree, each gives an estimate, and the estimate that agrees
/// ([`AUX_AGREE_RTOL`]) with the most others wins; ties go to the divisor whose smallest needed `|θ[χ](v)|` is
/// largest relative to the largest.
fn aux_constants_squared(
    curve: &HyperellipticCurve,
    kc: &KotterCurve,
    plan: &ThetaPlan,
    idx: &[usize; 8],
    rc: &[C; 2],
    est0: Option<[C; 7]>,
) -> Result<[C; 7]> {
    let bp = kc.branch_points();
    let center: C = bp.iter().sum::<C>() / 5.0;
    let radius = bp
        .iter()
        .fold(0.0f64, |m, d| m.max((d - center).norm()))
        .max(f64::MIN_POSITIVE);
    // Geometric mean of the non-zero |d_j|: a point at that modulus is, in
    // ratio, far from every branch point, whatever their spread.
    let (log_sum, count) = bp
        .iter()
        .filter(|d| d.norm() > 0.0)
        .fold((0.0f64, 0u32), |(s, n), d| (s + d.norm().ln(), n + 1));
    let geo = if count > 0 {
        (log_sum / f64::from(count)).exp()
    } else {
        radius
    };
    // Fixed generic offsets (off the real axis, both sheets).
    const W: [(f64, f64, f64, f64); 4] = [
        (0.37, 0.61, -0.53, -0.29),
        (-0.71, 0.43, 0.58, 0.47),
        (0.12, -0.77, -0.41, 0.66),
        (0.83, 0.21, -0.19, -0.88),
    ];
    let mut cands: Vec<(f64, [C; 7])> = Vec::with_capacity(9);
    if let Some(e) = est0 {
        cands.push((0.0, e));
    }
    let agree = |x: &[C; 7], y: &[C; 7]| {
        x.iter()
            .zip(y)
            .all(|(p, q)| (p - q).norm() <= AUX_AGREE_RTOL * p.norm().max(q.norm()))
    };
    // (votes, q, index) of the best-supported candidate.
    let best = |cands: &[(f64, [C; 7])]| {
        cands
            .iter()
            .enumerate()
            .map(|(i, (q, x))| (cands.iter().filter(|(_, y)| agree(x, y)).count(), *q, i))
            .max_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)))
    };
    // The geometric-mean scale first; the outer scale only when fewer than
    // three estimates agree there (a clustered curve: the two scales coincide).
    for (origin, scale) in [(C::new(0.0, 0.0), geo), (center, 1.3 * radius)] {
        if best(&cands).is_some_and(|(votes, _, _)| votes >= 3) {
            break;
        }
        for (k, &(a1, b1, a2, b2)) in W.iter().enumerate() {
            let x1 = origin + C::new(a1, b1) * scale;
            let x2 = origin + C::new(a2, b2) * scale;
            let y1 = curve.y(x1, 1);
            let y2 = curve.y(x2, if k % 2 == 0 { -1 } else { 1 });
            let ua = curve.abel(x1, y1)?;
            let ub = curve.abel(x2, y2)?;
            let v = [ua[0] + ub[0] + rc[0], ua[1] + ub[1] + rc[1]];
            let (vals, _) = plan.theta_all(&v)?;
            let big = vals.iter().fold(0.0f64, |m, z| m.max(z.norm()));
            let q = idx
                .iter()
                .map(|&i| vals[i].norm() / big)
                .fold(f64::INFINITY, f64::min);
            if q.is_nan() || q <= 0.0 {
                continue;
            }
            let Ok(w) = kc.wurzel(x1, y1, x2, y2, None) else {
                continue;
            };
            let p: [C; 7] = [
                w.p[0],
                w.pjk[2][3],
                w.pjk[3][1],
                w.pjk[1][2],
                w.pjk[1][4],
                w.pjk[2][4],
                w.pjk[3][4],
            ];
            let th = vals[idx[0]];
            let c2: [C; 7] = std::array::from_fn(|m| {
                let r = p[m] * th / vals[idx[m + 1]];
                r * r
            });
            if c2.iter().all(|z| z.re.is_finite() && z.im.is_finite()) {
                cands.push((q, c2));
            }
        }
    }
    best(&cands)
        .map(|(_, _, i)| cands[i].1)
        .ok_or(Error::InvalidArgument {
            what: "curve",
            reason: "no auxiliary divisor gives finite Wurzelfunktionen".into(),
        })
}

#[cfg(test)]
pub(crate) mod tests;
