//! Dormand–Prince 5(4) with FSAL and standard error-per-step control
//! (J. R. Dormand, P. J. Prince, *A family of embedded Runge–Kutta
//! formulae*, J. Comput. Appl. Math. 6 (1980) 19–26; HNW I, II.5 and II.4).

use super::explicit::{scaled, Control, Explicit};
use super::{Options, VectorField};

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
    ctl: Control,
    k: Vec<f64>,
    ytmp: Vec<f64>,
}

impl Dopri5 {
    pub(super) fn new(m: usize, opts: &Options) -> Self {
        Dopri5 {
            ctl: Control::new(m, opts.dt, opts.rtol, opts.atol),
            k: vec![0.0; 7 * m],
            ytmp: vec![0.0; m],
        }
    }
}

impl Explicit for Dopri5 {
    const UNDERFLOW: &'static str = "dopri5 step size underflow";
    const NON_FINITE: &'static str = "dopri5 (state became non-finite)";

    fn ctl(&self) -> &Control {
        &self.ctl
    }

    fn ctl_mut(&mut self) -> &mut Control {
        &mut self.ctl
    }

    fn k1(&mut self) -> &mut [f64] {
        &mut self.k[..self.ctl.m]
    }

    #[inline(always)]
    fn attempt<F: VectorField>(&mut self, f: &F, y: &[f64], h: f64) -> f64 {
        let m = self.ctl.m;
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
        self.ctl.evals += 6;
        // ytmp holds the 5th-order solution (stage 7 point); error = h Σ (b - b̂) k.
        let (atol, rtol) = (self.ctl.atol, self.ctl.rtol);
        let mut err = 0.0f64;
        for i in 0..m {
            let mut e = 0.0;
            for j in 0..7 {
                e += (DP_B[j] - DP_BHAT[j]) * self.k[j * m + i];
            }
            let sc = atol + rtol * y[i].abs().max(self.ytmp[i].abs());
            err += scaled(h * e, sc).powi(2);
        }
        (err / m as f64).sqrt()
    }

    #[inline(always)]
    fn accept<F: VectorField>(&mut self, _f: &F, y: &mut [f64]) {
        let m = self.ctl.m;
        y.copy_from_slice(&self.ytmp);
        // First same as last: the stage-7 derivative is f(y).
        self.k.copy_within(6 * m..7 * m, 0);
    }

    #[inline(always)]
    fn next_h(&self, h: f64, err: f64, last: bool, accepted: bool) -> f64 {
        // Step-size factor 0.9·err^(-1/5), limited to [0.2, 10] (HNW I, (4.13)).
        let fac = (0.9 * err.max(1e-300).powf(-0.2)).clamp(0.2, 10.0);
        match (accepted, last) {
            (true, false) => h * fac,
            (true, true) => self.ctl.h.max(h * fac.min(1.0)),
            (false, _) => h * fac.min(1.0),
        }
    }
}
