//! The two frequencies reported for an Euler motion (docs/degenerate.md §5):
//! the Euler frequency `ν_E = ω/(4K)` of the closed orbit, and the transverse
//! rotation number `ν_⊥` of the linearized motion off its subspace.
//!
//! An Euler motion (an so(3) block, or `n = ±m`) is a closed orbit of period
//! `T = 1/ν_E`; the states near it lie on 2-tori whose second cycle shrinks
//! onto it. Linearizing (1) off the invariant subspace along the orbit:
//!
//! * **self-dual** `n = σ m`: in `p = m + n`, `q = m − n` (so(4) =
//!   so(3) ⊕ so(3)), `H = Σ_j [(c_kl + c_j4)(p_j² + q_j²)/8 + (c_kl − c_j4) p_j q_j/4]`
//!   and `ṗ = −2 p × ∂H/∂p`, `q̇ = −2 q × ∂H/∂q`; the small factor (`q` for
//!   `σ = +1`, `p` for `σ = −1`) obeys `ẋ = (D∘m(t)) × x`, `D_j = c_kl − c_j4`:
//!   it is rotated, and the monodromy `Φ(T) ∈ SO(3)` is a rotation by `θ`;
//! * **block** `{i, j, k}` with the fourth index `r`: the small components
//!   `s_x = L_xr` (`x` in the block) obey `ṡ_x = Σ_{y≠x} L_xy(t)(c_yr − c_xy) s_y`;
//!   `m(0)ᵀ Φ(T) = m(0)ᵀ` (`h0 = m·n` is conserved), `det Φ = 1`, so the other
//!   two multipliers are `e^{±iθ}` (**elliptic**: `|tr Φ − 1| < 2`) or `λ, 1/λ`
//!   (**hyperbolic**).
//!
//! `ν_⊥ = θ/(2π T)` with `θ ∈ [0, π]`, i.e. `ν_⊥ ∈ [0, ν_E/2]`: the transverse
//! rotation number, defined modulo `ν_E` and up to sign. The frequencies of
//! the genus-2 tori near the orbit tend to `(|ν_⊥ + k ν_E|, ν_E)` for an
//! integer `k` that their reduced lattice basis fixes (measured:
//! docs/degenerate.md §5): the frequency module is continuous. A
//! transversally hyperbolic block orbit has no nearby tori shrinking onto it;
//! its neighbours' second frequency tends to 0 (logarithmically), and
//! `ν_⊥ = 0` is reported.
//!
//! `Φ(T)` is integrated with the sixth-order Magnus method of Blanes, Casas
//! and Ros (BIT 40 (2000) 434–450; three Gauss–Legendre nodes, three
//! commutators) on `N` equal steps of the exact orbit `m(t)`, `N` doubled from
//! [`MIN_STEPS`] until `cos θ` (or `tr Φ`) changes by less than
//! [`MONODROMY_TOL`].

use super::euler::{Embedding, EulerRegime, EulerTop};
use super::motion::Motion;
use crate::error::{Error, Result};
use crate::numeric::cancel::Cancel;

/// First number of Magnus steps per period, at least: the count starts at
/// the power of two with `h max‖A‖ ≤ 1` (`A` the coefficient matrix, its
/// norm sampled along the orbit), where the sixth-order method is in its
/// asymptotic regime (a factor 64 per doubling, measured).
pub const MIN_STEPS: usize = 32;

/// At most this many doublings beyond the first count: from `h‖A‖ ≤ 1/2`
/// six doublings reach rounding (`64^6`) on every orbit tried.
pub const MAX_DOUBLINGS: u32 = 8;

/// A hard cap on the steps per period (~0.1 s): a state so near the Euler
/// separatrix that its period needs more is refused (`NoConvergence`).
pub const MAX_STEPS: usize = 1 << 20;

/// The step count stops doubling when two successive Richardson
/// extrapolations (`v_2n + (v_2n − v_n)/63`, eighth order) of `cos θ`
/// (self-dual: also `sin θ`) or of `(tr Φ − 1)/2` (blocks, relative to
/// the largest entry of `Φ`, the scale of its rounding) agree to this, or
/// to the rounding floor `8 ε (max‖A‖ T + √n)` when that is larger: an orbit
/// whose neighbours turn `max‖A‖ T ≫ 1` radians per period has `θ mod 2π`
/// fixed by its data only to `ε` times that. Then `ν_⊥` is good to ~1e-12 relative away from `θ ∈ {0, π}`,
/// where the trace fixes `θ` only to the square root of its error (blocks).
pub const MONODROMY_TOL: f64 = 1e-13;

/// The convergence tolerance of the trace for a hyperbolic orbit's exponent
/// ([`hyperbolic_exponent_with`]): the exponent's relative error is the
/// trace's over `√(c² − 1) ln|μ|`, large next to `|c| = 1` (an orbit
/// hyperbolic by 1e-2 loses four digits), so the trace is taken to its
/// rounding where the steps allow.
pub const EXPONENT_TOL: f64 = 1e-15;

/// `|tr Φ − 1|/2` beyond `1 +` this at two step counts is taken as
/// hyperbolic without further digits (the multipliers are real and apart).
pub const HYPERBOLIC_MARGIN: f64 = 1e-6;

/// How the orbit's neighbours move.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Transverse {
    /// Rotated by `θ` per period (multipliers `e^{±iθ}`).
    Elliptic,
    /// Stretched by `λ` per period (multipliers `λ, 1/λ`, real).
    Hyperbolic,
}

/// The monodromy of the linearized motion off an Euler orbit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Monodromy {
    pub kind: Transverse,
    /// `θ ∈ [0, π]` (elliptic) or `ln |λ| ≥ 0` (hyperbolic).
    pub angle_or_exponent: f64,
    /// Magnus steps used.
    pub steps: usize,
}

type M3 = [[f64; 3]; 3];

fn mul(a: &M3, b: &M3) -> M3 {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

fn lin(x: f64, a: &M3, y: f64, b: &M3) -> M3 {
    std::array::from_fn(|i| std::array::from_fn(|j| x * a[i][j] + y * b[i][j]))
}

fn comm(a: &M3, b: &M3) -> M3 {
    lin(1.0, &mul(a, b), -1.0, &mul(b, a))
}

const ID: M3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// `exp(a)` by scaling and squaring with the Taylor series: the scaled
/// matrix has norm ≤ 1/2, where 14 terms leave `0.5^15/15! < 3e-17`.
fn expm(a: &M3) -> M3 {
    let norm = a
        .iter()
        .map(|r| r.iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0f64, f64::max);
    let s = if norm > 0.5 {
        (norm / 0.5).log2().ceil() as i32
    } else {
        0
    };
    let scaled = lin((-f64::from(s)).exp2(), a, 0.0, a);
    let mut term = ID;
    let mut sum = ID;
    for k in 1..=14 {
        term = lin(1.0 / k as f64, &mul(&term, &scaled), 0.0, &term);
        sum = lin(1.0, &sum, 1.0, &term);
    }
    for _ in 0..s {
        sum = mul(&sum, &sum);
    }
    sum
}

/// The coefficient matrix `A(t)` of the linearized motion off the subspace,
/// at the normalized state `m` of the Euler top (see the module docs).
fn coefficient(emb: Embedding, c4: &[f64; 6], m: &[f64; 3]) -> M3 {
    match emb {
        Embedding::SelfDual(_) => {
            let d = [c4[3] - c4[2], c4[1] - c4[4], c4[0] - c4[5]];
            let w = [d[0] * m[0], d[1] * m[1], d[2] * m[2]];
            // x ↦ w × x.
            [[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]]
        }
        Embedding::Block(blk) => {
            let l = emb.state(m);
            let pairs = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];
            let mut lm = [[0.0f64; 4]; 4];
            let mut cm = [[0.0f64; 4]; 4];
            for (q, &(i, j)) in pairs.iter().enumerate() {
                lm[i][j] = l[q];
                lm[j][i] = -l[q];
                cm[i][j] = c4[q];
                cm[j][i] = c4[q];
            }
            let r = 6 - blk[0] - blk[1] - blk[2];
            std::array::from_fn(|x| {
                std::array::from_fn(|y| {
                    if x == y {
                        0.0
                    } else {
                        let (bx, by) = (blk[x], blk[y]);
                        lm[bx][by] * (cm[by][r] - cm[bx][by])
                    }
                })
            })
        }
    }
}

/// `Φ(T)` with `n` sixth-order Magnus steps.
///
/// `cancel` is checked every [`CANCEL_STEPS`] steps.
fn propagate(
    emb: Embedding,
    c4: &[f64; 6],
    top: &EulerTop,
    period: f64,
    n: usize,
    cancel: &Cancel,
) -> Result<M3> {
    match emb {
        Embedding::SelfDual(_) => propagate_so3(c4, top, period, n, cancel),
        Embedding::Block(_) => propagate_general(emb, c4, top, period, n, cancel),
    }
}

/// Magnus steps between two checks of the cancellation token (~1 ms).
const CANCEL_STEPS: usize = 4096;

/// The three Gauss–Legendre nodes of a step, as fractions of it.
fn nodes() -> [f64; 3] {
    let r = 15f64.sqrt() / 10.0;
    [0.5 - r, 0.5, 0.5 + r]
}

fn propagate_general(
    emb: Embedding,
    c4: &[f64; 6],
    top: &EulerTop,
    period: f64,
    n: usize,
    cancel: &Cancel,
) -> Result<M3> {
    let h = period / n as f64;
    let mut phi = ID;
    for k in 0..n {
        if k % CANCEL_STEPS == 0 {
            cancel.check()?;
        }
        let t0 = h * k as f64;
        let a: [M3; 3] = nodes().map(|c| coefficient(emb, c4, &top.m(t0 + c * h)));
        let a1 = lin(h, &a[1], 0.0, &a[1]);
        let a2 = lin(
            15f64.sqrt() * h / 3.0,
            &lin(1.0, &a[2], -1.0, &a[0]),
            0.0,
            &a[0],
        );
        let a3 = lin(
            10.0 * h / 3.0,
            &lin(1.0, &lin(1.0, &a[2], 1.0, &a[0]), -2.0, &a[1]),
            0.0,
            &a[0],
        );
        let c1 = comm(&a1, &a2);
        let c2 = lin(-1.0 / 60.0, &comm(&a1, &lin(2.0, &a3, 1.0, &c1)), 0.0, &c1);
        let left = lin(1.0, &lin(-20.0, &a1, -1.0, &a3), 1.0, &c1);
        let right = lin(1.0, &a2, 1.0, &c2);
        let omega = lin(
            1.0,
            &lin(1.0, &a1, 1.0 / 12.0, &a3),
            1.0 / 240.0,
            &comm(&left, &right),
        );
        phi = mul(&expm(&omega), &phi);
    }
    Ok(phi)
}

type V3 = [f64; 3];

fn cross(a: &V3, b: &V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn vlin(x: f64, a: &V3, y: f64, b: &V3) -> V3 {
    std::array::from_fn(|i| x * a[i] + y * b[i])
}

/// The same Magnus method on so(3) ≅ (R³, ×) for the self-dual case
/// (`A = [w]×`, `[a]×[b]× − [b]×[a]× = [a × b]×`), with Rodrigues' formula
/// for the exponential: the product stays a rotation to rounding.
fn propagate_so3(
    c4: &[f64; 6],
    top: &EulerTop,
    period: f64,
    n: usize,
    cancel: &Cancel,
) -> Result<M3> {
    let d = [c4[3] - c4[2], c4[1] - c4[4], c4[0] - c4[5]];
    let h = period / n as f64;
    let mut phi = ID;
    for k in 0..n {
        if k % CANCEL_STEPS == 0 {
            cancel.check()?;
        }
        let t0 = h * k as f64;
        let w: [V3; 3] = nodes().map(|c| {
            let m = top.m(t0 + c * h);
            [d[0] * m[0], d[1] * m[1], d[2] * m[2]]
        });
        let a1 = vlin(h, &w[1], 0.0, &w[1]);
        let a2 = vlin(
            15f64.sqrt() * h / 3.0,
            &vlin(1.0, &w[2], -1.0, &w[0]),
            0.0,
            &w[0],
        );
        let a3 = vlin(
            10.0 * h / 3.0,
            &vlin(1.0, &vlin(1.0, &w[2], 1.0, &w[0]), -2.0, &w[1]),
            0.0,
            &w[0],
        );
        let c1 = cross(&a1, &a2);
        let c2 = vlin(
            -1.0 / 60.0,
            &cross(&a1, &vlin(2.0, &a3, 1.0, &c1)),
            0.0,
            &c1,
        );
        let left = vlin(1.0, &vlin(-20.0, &a1, -1.0, &a3), 1.0, &c1);
        let right = vlin(1.0, &a2, 1.0, &c2);
        let om = vlin(
            1.0,
            &vlin(1.0, &a1, 1.0 / 12.0, &a3),
            1.0 / 240.0,
            &cross(&left, &right),
        );
        let th = (om[0] * om[0] + om[1] * om[1] + om[2] * om[2]).sqrt();
        let kx: M3 = [
            [0.0, -om[2], om[1]],
            [om[2], 0.0, -om[0]],
            [-om[1], om[0], 0.0],
        ];
        // sin θ/θ and (1 − cos θ)/θ² without cancellation at small θ.
        let (s1, s2) = if th < 1e-4 {
            (1.0 - th * th / 6.0, 0.5 - th * th / 24.0)
        } else {
            let half = (0.5 * th).sin();
            (th.sin() / th, 2.0 * half * half / (th * th))
        };
        let r = lin(1.0, &lin(1.0, &ID, s1, &kx), s2, &mul(&kx, &kx));
        phi = mul(&r, &phi);
    }
    Ok(phi)
}

/// The invariant of `Φ(T)` that fixes `θ`: for a rotation `(cos θ, sin θ)`
/// from the trace and the axial vector; for a block `(tr Φ − 1)/2` and NaN.
fn invariant(emb: Embedding, phi: &M3) -> (f64, f64) {
    let tr = phi[0][0] + phi[1][1] + phi[2][2];
    match emb {
        Embedding::SelfDual(_) => {
            let v = [
                phi[2][1] - phi[1][2],
                phi[0][2] - phi[2][0],
                phi[1][0] - phi[0][1],
            ];
            let sin = 0.5 * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            (0.5 * (tr - 1.0), sin)
        }
        Embedding::Block(_) => (0.5 * (tr - 1.0), f64::NAN),
    }
}

/// The largest entry of `Φ`: the scale of the rounding in its trace (a
/// block's monodromy may grow transiently far beyond its trace).
fn size(phi: &M3) -> f64 {
    phi.iter().flatten().fold(1.0f64, |m, v| m.max(v.abs()))
}

/// The monodromy of the linearized motion off the orbit of an Euler motion
/// (normalized frame).
///
/// Errors: a motion of another kind, a motion without period (separatrix,
/// rest), or no convergence within [`MAX_STEPS`] steps.
pub fn monodromy(m: &Motion) -> Result<Monodromy> {
    monodromy_with(m, &Cancel::never())
}

/// [`monodromy`], checking `cancel` every few thousand steps (a map of many
/// Euler states must stop on Ctrl-C; one state can take up to ~0.1 s).
pub fn monodromy_with(m: &Motion, cancel: &Cancel) -> Result<Monodromy> {
    Ok(monodromy_full(m, false, cancel)?.0)
}

/// The monodromy, the converged invariant `c = cos` and its tolerance
/// ([`Orbit::converged_invariant`]; `full`: not stopped once clearly
/// hyperbolic).
fn monodromy_full(m: &Motion, full: bool, cancel: &Cancel) -> Result<(Monodromy, f64, f64)> {
    let orbit = Orbit::of(m)?;
    let mut n = orbit.first_steps()?;
    let ((cos, sin), tol) = orbit.converged_invariant(&mut n, full, cancel)?;
    Ok((classify(cos, sin, n), cos, tol))
}

/// `ν_E` of an Euler motion in the user's time.
fn user_euler_frequency(m: &Motion) -> Result<f64> {
    let (_, top) = m.euler().ok_or(Error::InvalidArgument {
        what: "state l0",
        reason: "not an Euler top".into(),
    })?;
    Ok(top.frequency() * m.time_scale())
}

/// The transverse Lyapunov exponent `λ = ln|μ| ν_E` (per unit of the user's
/// time; `μ` the larger multiplier of `Φ(T)`) of a transversally hyperbolic
/// block orbit, and a bound on its relative error: the trace converged to
/// [`EXPONENT_TOL`] or its rounding (not stopped once clearly hyperbolic, as
/// [`monodromy_with`] does), its last change carried through
/// `d ln|μ| = d c/√(c² − 1)`, `c = (tr Φ − 1)/2`.
///
/// Errors: those of [`monodromy_with`], and an orbit that is not
/// transversally hyperbolic.
pub fn hyperbolic_exponent_with(m: &Motion, cancel: &Cancel) -> Result<(f64, f64)> {
    let (mono, cos, tol) = monodromy_full(m, true, cancel)?;
    let lambda = mono.angle_or_exponent * user_euler_frequency(m)?;
    if mono.kind != Transverse::Hyperbolic || !(lambda > 0.0 && lambda.is_finite()) {
        return Err(Error::InvalidArgument {
            what: "state l0",
            reason: "the Euler orbit is not transversally hyperbolic (or its exponent is not \
                     finite)"
                .into(),
        });
    }
    let rel = tol / (cos * cos - 1.0).sqrt() / mono.angle_or_exponent;
    Ok((lambda, rel))
}

/// A periodic Euler orbit of (1): what the Magnus steps along it need.
struct Orbit<'a> {
    emb: Embedding,
    c4: &'a [f64; 6],
    top: &'a EulerTop,
    /// The period `T` of the orbit.
    period: f64,
    /// `max ‖A‖` (row sums) at 64 points of the period: the rate of the
    /// transverse rotation, which sets the steps and the rounding floor.
    norm_a: f64,
}

impl<'a> Orbit<'a> {
    /// The orbit of an Euler motion; errors for another kind of motion or a
    /// motion without period (rest, separatrix).
    fn of(m: &'a Motion) -> Result<Self> {
        let (emb, top) = m.euler().ok_or(Error::InvalidArgument {
            what: "state l0",
            reason: format!(
                "the motion is of kind '{}', not an Euler top",
                m.kind().name()
            ),
        })?;
        if matches!(top.regime(), EulerRegime::Rest | EulerRegime::Separatrix) {
            return Err(Error::InvalidArgument {
                what: "state l0",
                reason: "the Euler motion has no period (at rest or on its separatrix)".into(),
            });
        }
        let period = 1.0 / top.frequency();
        let c4 = &m.frame().c4;
        let norm_a = (0..64)
            .map(|k| {
                let a = coefficient(*emb, c4, &top.m(period * k as f64 / 64.0));
                a.iter()
                    .map(|r| r.iter().map(|v| v.abs()).sum::<f64>())
                    .fold(0.0f64, f64::max)
            })
            .fold(0.0f64, f64::max);
        Ok(Orbit {
            emb: *emb,
            c4,
            top,
            period,
            norm_a,
        })
    }

    /// The first step count: `‖A‖ T` steps, at least [`MIN_STEPS`], rounded up
    /// to a power of two; errors if that is beyond [`MAX_STEPS`].
    fn first_steps(&self) -> Result<usize> {
        let first = (self.norm_a * self.period).ceil().max(MIN_STEPS as f64);
        if first.is_nan() || first > MAX_STEPS as f64 {
            return Err(Error::NoConvergence {
                what: "transverse monodromy of the Euler orbit (steps per period)",
                tol: MONODROMY_TOL,
                reached: f64::INFINITY,
                iterations: MAX_STEPS,
            });
        }
        Ok((first as usize).next_power_of_two())
    }

    /// `Φ(T)` with `n` Magnus steps ([`propagate`]).
    fn propagate(&self, n: usize, cancel: &Cancel) -> Result<M3> {
        propagate(self.emb, self.c4, self.top, self.period, n, cancel)
    }

    /// The invariant of `Φ(T)` ([`invariant`]) to [`MONODROMY_TOL`] (or the
    /// rounding floor), and that tolerance in the units of the invariant's
    /// first entry: step counts doubled from `*n` and Richardson extrapolated,
    /// `*n` left at the last count used. A clearly hyperbolic block orbit
    /// stops at once unless `full` (its exponent needs no digits to classify
    /// the orbit).
    fn converged_invariant(
        &self,
        n: &mut usize,
        full: bool,
        cancel: &Cancel,
    ) -> Result<((f64, f64), f64)> {
        let emb = self.emb;
        let cap = (*n << MAX_DOUBLINGS).min(MAX_STEPS);
        // Values at n, 2n, 4n, … and their Richardson extrapolations
        // r = v_2n + (v_2n − v_n)/63 (sixth order: the error of r is O(h^8)).
        let mut prev = invariant(emb, &self.propagate(*n, cancel)?);
        let mut prev_r: Option<(f64, f64)> = None;
        loop {
            let next_n = 2 * *n;
            let phi = self.propagate(next_n, cancel)?;
            let cur = invariant(emb, &phi);
            *n = next_n;
            // Clearly hyperbolic at both counts: θ does not exist, ν_⊥ = 0; the
            // exponent needs no more digits.
            if !full
                && cur.1.is_nan()
                && cur.0.abs() > 1.0 + HYPERBOLIC_MARGIN
                && prev.0.abs() > 1.0 + HYPERBOLIC_MARGIN
            {
                return Ok((cur, f64::NAN));
            }
            let r = (
                cur.0 + (cur.0 - prev.0) / 63.0,
                cur.1 + (cur.1 - prev.1) / 63.0,
            );
            prev = cur;
            if let Some(pr) = prev_r {
                let scale = r.0.abs().max(size(&phi));
                let change = ((r.0 - pr.0).abs() / scale).max(if r.1.is_nan() {
                    0.0
                } else {
                    (r.1 - pr.1).abs()
                });
                // The data fix θ only to the rounding of the total transverse
                // rotation (‖A‖ T radians) and of the n-fold product.
                let floor = 8.0 * f64::EPSILON * (self.norm_a * self.period + (*n as f64).sqrt());
                let tol = if full { EXPONENT_TOL } else { MONODROMY_TOL };
                if change <= tol.max(floor) {
                    return Ok((r, change.max(floor) * scale));
                }
                if *n >= cap {
                    return Err(Error::NoConvergence {
                        what: "transverse monodromy of the Euler orbit",
                        tol: MONODROMY_TOL,
                        reached: change,
                        iterations: *n,
                    });
                }
            }
            prev_r = Some(r);
        }
    }
}

/// The monodromy from the converged invariant `(cos θ, sin θ)` (a rotation)
/// or `((tr Φ − 1)/2, NaN)` (a block: elliptic within `[−1, 1]`, else hyperbolic).
fn classify(cos: f64, sin: f64, n: usize) -> Monodromy {
    if !sin.is_nan() {
        Monodromy {
            kind: Transverse::Elliptic,
            angle_or_exponent: sin.atan2(cos),
            steps: n,
        }
    } else if cos.abs() <= 1.0 {
        Monodromy {
            kind: Transverse::Elliptic,
            angle_or_exponent: cos.acos(),
            steps: n,
        }
    } else {
        // λ + 1/λ = 2 cos: |λ| = |cos| + √(cos² − 1).
        Monodromy {
            kind: Transverse::Hyperbolic,
            angle_or_exponent: (cos.abs() + (cos * cos - 1.0).sqrt()).ln(),
            steps: n,
        }
    }
}

/// `(ν_⊥, ν_E)` of an Euler motion in the user's time (see the module docs:
/// `ν_⊥ = θ ν_E/(2π)`, 0 when the orbit is transversally hyperbolic).
///
/// Errors: those of [`monodromy`].
pub fn euler_frequencies(m: &Motion) -> Result<[f64; 2]> {
    euler_frequencies_with(m, &Cancel::never())
}

/// [`euler_frequencies`] with a cancellation token ([`monodromy_with`]).
pub fn euler_frequencies_with(m: &Motion, cancel: &Cancel) -> Result<[f64; 2]> {
    let mono = monodromy_with(m, cancel)?;
    let nu_e = user_euler_frequency(m)?;
    let nu_perp = match mono.kind {
        Transverse::Elliptic => mono.angle_or_exponent / (2.0 * std::f64::consts::PI) * nu_e,
        Transverse::Hyperbolic => 0.0,
    };
    Ok([nu_perp, nu_e])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn expm_of_a_rotation_generator() {
        let th = 2.5;
        let a = [[0.0, -th, 0.0], [th, 0.0, 0.0], [0.0, 0.0, 0.0]];
        let e = expm(&a);
        assert!((e[0][0] - th.cos()).abs() < 1e-15 && (e[1][0] - th.sin()).abs() < 1e-15);
        assert!((e[2][2] - 1.0).abs() < 1e-15);
    }
}
