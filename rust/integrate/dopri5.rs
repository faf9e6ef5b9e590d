//! Dormand–Prince 5(4) with FSAL and standard error-per-step control
//! (J. R. Dormand, P. J. Prince, *A family of embedded Runge–Kutta
//! formulae*, J. Comput. Appl. Math. 6 (1980) 19–26; HNW I, II.5 and II.4).

use super::explicit::{
    check_error_norm, next_attempt, scaled, starting_step, too_many_steps, Explicit,
};
use super::{Options, VectorField};
use crate::error::Result;
use crate::numeric::cancel::Cancel;

// Dormand–Prince 5(4) tableau (Dormand & Prince 1980, Table 2; HNW I, Table II.5.2).
/// Nodes; the field is autonomous, so only the tests use them.
#[cfg_attr(not(test), allow(dead_code))]
pub(super) const DP_C: [f64; 7] = [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0];

pub(super) const DP_A: [[f64; 6]; 7] = [
    [0.0; 6],
    [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
        0.0,
    ],
    [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ],
];

/// 5th-order weights (= last row of A: first same as last).
pub(super) const DP_B: [f64; 7] = [
    35.0 / 384.0,
    0.0,
    500.0 / 1113.0,
    125.0 / 192.0,
    -2187.0 / 6784.0,
    11.0 / 84.0,
    0.0,
];

/// 4th-order embedded weights.
pub(super) const DP_BHAT: [f64; 7] = [
    5179.0 / 57600.0,
    0.0,
    7571.0 / 16695.0,
    393.0 / 640.0,
    -92097.0 / 339200.0,
    187.0 / 2100.0,
    1.0 / 40.0,
];

/// Dormand–Prince 5(4) stepper with its scratch space.
pub(super) struct Dopri5 {
    m: usize,
    k: Vec<f64>,
    ytmp: Vec<f64>,
    h: f64,
    fsal_valid: bool,
    evals: u64,
    rtol: f64,
    atol: f64,
}

impl Dopri5 {
    pub(super) fn new(m: usize, opts: &Options) -> Self {
        Dopri5 {
            m,
            k: vec![0.0; 7 * m],
            ytmp: vec![0.0; m],
            h: opts.dt,
            fsal_valid: false,
            evals: 0,
            rtol: opts.rtol,
            atol: opts.atol,
        }
    }
}

impl Explicit for Dopri5 {
    /// Advances `y` from `t` to exactly `t_target` with adaptive steps; returns the number
    /// of steps, failing once more than `budget` are needed.
    fn advance<F: VectorField>(
        &mut self,
        f: &F,
        y: &mut [f64],
        t: &mut f64,
        t_target: f64,
        budget: u64,
        cancel: &Cancel,
    ) -> Result<u64> {
        let m = self.m;
        let mut steps = 0u64;
        let mut attempts = 0u32;
        if !self.fsal_valid {
            f.eval(y, &mut self.k[0..m]);
            self.evals += 1;
            self.fsal_valid = true;
        }
        if self.h == 0.0 {
            self.h = starting_step(y, &self.k[0..m], self.atol, self.rtol);
        }
        while *t < t_target {
            let (h, last) = next_attempt(
                "dopri5 step size underflow",
                self.h,
                *t,
                t_target,
                (self.rtol, steps),
                &mut attempts,
                cancel,
            )?;
            for st in 1..7 {
                for i in 0..m {
                    let mut acc = 0.0;
                    for (j, &aij) in DP_A[st].iter().enumerate().take(st) {
                        acc += aij * self.k[j * m + i];
                    }
                    self.ytmp[i] = y[i] + h * acc;
                }
                let (_, tail) = self.k.split_at_mut(st * m);
                f.eval(&self.ytmp, &mut tail[..m]);
            }
            self.evals += 6;
            // ytmp holds the 5th-order solution (stage 7 point); error = h Σ (b - b̂) k.
            let mut err = 0.0f64;
            for i in 0..m {
                let mut e = 0.0;
                for j in 0..7 {
                    e += (DP_B[j] - DP_BHAT[j]) * self.k[j * m + i];
                }
                let sc = self.atol + self.rtol * y[i].abs().max(self.ytmp[i].abs());
                err += scaled(h * e, sc).powi(2);
            }
            let err = (err / m as f64).sqrt();
            check_error_norm("dopri5 (state became non-finite)", err, self.rtol, steps)?;
            // Step-size factor 0.9·err^(-1/5), limited to [0.2, 10] (HNW I, (4.13)).
            let fac = (0.9 * err.max(1e-300).powf(-0.2)).clamp(0.2, 10.0);
            if err <= 1.0 {
                y.copy_from_slice(&self.ytmp);
                self.k.copy_within(6 * m..7 * m, 0);
                *t = if last { t_target } else { *t + h };
                steps += 1;
                if !last {
                    self.h = h * fac;
                } else {
                    self.h = self.h.max(h * fac.min(1.0));
                }
            } else {
                self.h = h * fac.min(1.0);
            }
            if steps > budget {
                return Err(too_many_steps(budget));
            }
        }
        Ok(steps)
    }

    fn evals(&self) -> u64 {
        self.evals
    }
}
