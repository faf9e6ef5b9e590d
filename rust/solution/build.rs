//! The steps of [`Solution::with_c4_lo`], in the order of the chain: the level
//! set and the divisor of `l0` with the theta data at `v0`; the constants
//! `C_L` (37) with the signs `l0` decides; `U` in closed form; every undecided
//! sign pattern built and self-checked; the phase in lattice coordinates.

use super::check::Defect;
use super::*;

/// The level set of `l0`, its divisor and the theta data at `v0`: what every
/// sign pattern of the constants shares.
pub(super) struct Divisor0 {
    pub(super) kotter: KotterConstants,
    pub(super) curve: HyperellipticCurve,
    pub(super) chars: [([u8; 2], [u8; 2]); 7],
    pub(super) state0: KotterState,
    pub(super) tau: [C; 4],
    pub(super) plan: ThetaPlan,
    /// The Riemann constant `K`.
    pub(super) rc: [C; 2],
    /// Theta indices (FLINT order): `θ`, then the seven labels.
    pub(super) idx: [usize; 8],
    /// `u0 = u(P1) + u(P2)`.
    pub(super) u0: [C; 2],
    /// `v0 = u0 + K`.
    pub(super) v0: [C; 2],
    /// The thetas and their gradients at `v0`.
    pub(super) jet: ThetaJet,
}

impl Divisor0 {
    /// The curve (8) of `l0`'s level set, the divisor of `l0` on it, its Abel
    /// image `u0`, `v0 = u0 + K` and the thetas of the seven labels at `v0`.
    ///
    /// `soft`: where given, a failure of the reduction's consistency checks
    /// (`H0`'s structure, the corrected (42)) is written there instead of
    /// refused, for a solution that certifies every `l(t)`.
    pub(super) fn new(
        a: &[f64; 4],
        l0: &[f64; 6],
        mut soft: Option<&mut Option<String>>,
    ) -> Result<Self> {
        let LevelSetCurve {
            kotter,
            kcurve: _,
            curve,
            chars,
        } = level_set_curve_soft(a, l0, soft.as_deref_mut())?;
        let state0 =
            crate::kotter::kotter_with_soft(kotter.clone(), l0, soft).map_err(map_coinciding)?;
        let tau_rm = curve.tau_row_major();
        let tau: [C; 4] = [tau_rm[0], tau_rm[1], tau_rm[2], tau_rm[3]];
        let plan = ThetaPlan::new(&tau, 2, THETA_TOL, 1)?.with_parallel(false);
        let rcv = curve.riemann_constant_with(&plan)?;
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
        Ok(Divisor0 {
            kotter,
            curve,
            chars,
            state0,
            tau,
            plan,
            rc,
            idx,
            u0,
            v0,
            jet,
        })
    }
}

/// `U` in closed form (Dubrovin's equations at the half periods,
/// [`dubrovin`]), with its lattice coordinates in DD and the real structure
/// imposed: the velocity `V` of the flow `c4` (for the sign against the theta
/// quotients' fit) and the lattice rates of the flows.
///
/// With rounding errors `c4_lo`, two flows: `c4` as rounded, which the theta
/// quotients, their velocity fit and the self-check are consistent with (they
/// evaluate (1) with `c4`), and `c4 + c4_lo`, the unrounded top, whose lattice
/// rates give the phase of l(t) and `U` (the last of the rates): the two differ
/// by the rounding of c (relative ε times the condition of the differences
/// `c_kj − c_ik`, ~1e-10 where two `a_i` nearly meet).
pub(super) fn closed_velocity(
    d: &Divisor0,
    l0: &[f64; 6],
    c4: &[f64; 6],
    c4_lo: &[f64; 6],
) -> Result<([C; 2], dubrovin::LatticeRates)> {
    let exact_flow = c4_lo.iter().any(|v| *v != 0.0);
    let (flows, flows_lo): (&[[f64; 6]], &[[f64; 6]]) = if exact_flow {
        (&[*c4, *c4], &[[0.0; 6], *c4_lo])
    } else {
        (std::slice::from_ref(c4), &[])
    };
    let hp = dubrovin::half_period_velocities_lo(&d.kotter, l0, flows, flows_lo, true)?;
    let e_lo = hp.branch_point_errors(&d.curve);
    let lat = dubrovin::lattice_rates_dd(&d.curve, e_lo.as_ref().map(|e| &e[..]), &hp.v_dd)?;
    Ok((hp.v[0], lat))
}

/// What builds the theta quotients for one sign pattern of the constants.
pub(super) struct Candidates<'a> {
    pub(super) d: &'a Divisor0,
    pub(super) at_v0: ThetaAtV0<'a>,
    /// `√c_j` of Kötter's curve.
    pub(super) sc: [C; 3],
    pub(super) eps: C,
    pub(super) c4: [f64; 6],
    pub(super) closed: &'a Result<([C; 2], dubrovin::LatticeRates)>,
    pub(super) check: SelfCheck,
    /// Whether a pattern whose quotients fit (1) at `v0` for no velocity is
    /// kept (for [`super::Solution::with_c4_lo_certifying`]) where no pattern
    /// fits, instead of refused.
    pub(super) certifying: bool,
}

impl Candidates<'_> {
    /// The quotients (9)-(10) with the constants `cl` and their self-check
    /// defect; where they fit (1) at `v0` for no velocity, that refusal
    /// (returned as an error unless [`Candidates::certifying`]).
    fn build(&self, cl: [C; 7]) -> Result<(Defect, Built, Option<Error>)> {
        let d = self.d;
        let big_g = self.at_v0.big_g(&d.state0, &self.sc, &cl, self.eps);
        let (num, den) = quotient_weights(&d.kotter, &self.sc, self.eps, big_g, &cl);
        // The quotients' own velocity at v0 by least squares (see
        // [`VelocitySystem`]): a set-up whose quotients fit (1) for no
        // velocity, or for another one than the closed form, is refused;
        // the fit gives the closed form its sign.
        let sys = VelocitySystem::at(&d.jet, &d.idx, &num, &den)?;
        let (fit, residual) = sys.rate(&self.c4, "U")?;
        let unfit = match check_velocity_fit(residual) {
            Ok(()) => None,
            Err(e) if self.certifying => Some(e),
            Err(e) => return Err(e),
        };
        let (rate, closed) = match self.closed {
            Ok((v, lat)) => {
                let (s, dev) = dubrovin::sign_against(&d.curve, v, &fit);
                let u = lat.u[0].map(|z| s * z);
                let res_closed = sys.residual_at(&u, &self.c4);
                if dubrovin::closed_form_fits(dev, res_closed, residual) {
                    (u, true)
                } else {
                    // The closed form misses the quotients' own equations at v0
                    // where their fit holds (next to a pinched curve `U = A⁻¹V`
                    // with an ill-conditioned `A` loses the direction `A` nearly
                    // annihilates): the fit is taken, and the self-check, which
                    // evaluates the velocity along it at points across the
                    // torus, decides.
                    (fit, false)
                }
            }
            Err(_) => (fit, false),
        };
        let built = Built {
            cl,
            num,
            den,
            rate,
            closed,
        };
        Ok((
            self.check
                .defect(&d.plan, &d.curve, &d.idx, &built, &d.v0, &d.jet)?,
            built,
            unfit,
        ))
    }

    /// Every sign pattern of the constants that l0 leaves undecided, built and
    /// checked (check.rs): the one that passes the self-check best (each part
    /// relative to its bound), with the self-check's verdict on it
    /// ([`self_check_verdict`]).
    pub(super) fn best(
        &self,
        cl0: &[C; 7],
        calibration: &[f64; 7],
    ) -> Result<(Defect, Built, Result<()>)> {
        let mut best: Option<(Defect, Built)> = None;
        // Where no pattern fits (1) at v0 (certifying only): the best of those
        // that do not, with the refusal.
        let mut best_unfit: Option<(Defect, Built, Error)> = None;
        let mut last_err: Option<Error> = None;
        for cl in sign_patterns(cl0, calibration) {
            match self.build(cl) {
                Ok((d, b, None)) if best.as_ref().is_none_or(|(bd, _)| d.rank() < bd.rank()) => {
                    best = Some((d, b))
                }
                Ok((d, b, Some(e)))
                    if best_unfit
                        .as_ref()
                        .is_none_or(|(bd, _, _)| d.rank() < bd.rank()) =>
                {
                    best_unfit = Some((d, b, e))
                }
                Ok(_) => {}
                Err(e) => last_err = Some(e),
            }
        }
        if best.is_none() {
            if let Some((d, b, e)) = best_unfit {
                return Ok((d, b, Err(e)));
            }
        }
        let (defect, built) = match (best, last_err) {
            (Some(b), _) => b,
            (None, Some(e)) => return Err(e),
            (None, None) => {
                return Err(Error::Unverified {
                    what: "solution of l0",
                    reason: "no sign of the constants C_L gives a solution".into(),
                })
            }
        };
        let verdict = self_check_verdict(&defect);
        Ok((defect, built, verdict))
    }
}

/// The self-check's verdict: refused above [`SELF_CHECK_RTOL`] in its shape
/// or [`VELOCITY_CHECK_RTOL`] in its velocity.
fn self_check_verdict(defect: &Defect) -> Result<()> {
    if defect.shape.is_nan() || defect.shape > SELF_CHECK_RTOL {
        return Err(Error::Unverified {
            what: "solution of l0",
            reason: format!(
                "the theta quotients (9)-(10) fail the self-check: relative defect \
                 {:e} > {SELF_CHECK_RTOL:e} in the integrals (6)-(7), a real l or \
                 l(0) = l0 at points of the torus",
                defect.shape
            ),
        });
    }
    if defect.velocity.is_nan() || defect.velocity > VELOCITY_CHECK_RTOL {
        return Err(Error::Unverified {
            what: "solution of l0",
            reason: format!(
                "the theta quotients (9)-(10) fail the self-check: they move along U \
                 against Frahm's equations (1) by {:e} > {VELOCITY_CHECK_RTOL:e} of \
                 the largest speed at points of the torus",
                defect.velocity
            ),
        });
    }
    Ok(())
}

/// The phase of the solution: `U`, its lattice rates `X, Y` (with their
/// rounding errors) and the sign `v_sign` of the closed-form velocities in
/// the convention of `rate` (the checked pattern's `U`). From the closed form
/// of the unrounded top where it was built, else from the fit `rate`.
pub(super) struct Phase {
    pub(super) rate: [C; 2],
    pub(super) lat_rate: [f64; 4],
    pub(super) lat_rate_lo: [f64; 4],
    pub(super) v_sign: f64,
}

impl Phase {
    pub(super) fn new(
        curve: &HyperellipticCurve,
        closed: &Result<([C; 2], dubrovin::LatticeRates)>,
        rate: [C; 2],
    ) -> Self {
        match closed {
            Ok((_, lat)) => {
                let u = lat.u[0];
                let s = if (u[0].conj() * rate[0] + u[1].conj() * rate[1]).re >= 0.0 {
                    1.0
                } else {
                    -1.0
                };
                // the unrounded top's flow (the last) for U and the phase
                let k = lat.u.len() - 1;
                Phase {
                    rate: lat.u[k].map(|z| s * z),
                    lat_rate: lat.w[k].map(|x| s * x),
                    lat_rate_lo: lat.w_lo[k].map(|x| s * x),
                    v_sign: s,
                }
            }
            Err(_) => {
                let (xr, yr) = curve.lattice_coordinates(&rate);
                Phase {
                    rate,
                    lat_rate: [xr[0], xr[1], yr[0], yr[1]],
                    lat_rate_lo: [0.0; 4],
                    v_sign: 1.0,
                }
            }
        }
    }
}
