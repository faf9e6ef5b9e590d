//! Dormand–Prince 8(5,3), "DOP853": explicit, adaptive, order 8.
//!
//! The tableau of P. J. Prince and J. R. Dormand, *High order embedded
//! Runge–Kutta formulae*, J. Comput. Appl. Math. 7 (1981) 67–75, in the form
//! published by E. Hairer, S. P. Nørsett and G. Wanner, *Solving Ordinary
//! Differential Equations I* (2nd ed., Springer 1993), Section II.10, with its
//! error estimator combining the embedded 5th- and 3rd-order solutions
//! (`err = err5² / sqrt(err5² + 0.01 err3²)`) and its step-size control
//! (exponent 1/8, safety 0.9, factor limited to [1/3, 6]). The coefficients are
//! checked against the order conditions in the tests below.

// Index loops mirror the stage subscripts.
#![allow(clippy::needless_range_loop)]
#![allow(clippy::excessive_precision)]

use super::explicit::{scaled, Control, Explicit};
use super::VectorField;

/// Nodes `c_i`. The vector field is autonomous, so only the order-condition
/// tests use them.
#[cfg_attr(not(test), allow(dead_code))]
const C: [f64; 12] = [
    0.0,
    0.526001519587677318785587544488e-01,
    0.789002279381515978178381316732e-01,
    0.118350341907227396726757197510,
    0.281649658092772603273242802490,
    0.333333333333333333333333333333,
    0.25,
    0.307692307692307692307692307692,
    0.651282051282051282051282051282,
    0.6,
    0.857142857142857142857142857142,
    1.0,
];

/// Rows of the Runge–Kutta matrix, `A[i][j]`, `j < i` (zeros as published).
pub(super) const A: [[f64; 11]; 12] = [
    [0.0; 11],
    [
        5.26001519587677318785587544488e-02,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        1.97250569845378994544595329183e-02,
        5.91751709536136983633785987549e-02,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        2.95875854768068491816892993775e-02,
        0.0,
        8.87627564304205475450678981324e-02,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        2.41365134159266685502369798665e-01,
        0.0,
        -8.84549479328286085344864962717e-01,
        9.24834003261792003115737966543e-01,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        3.7037037037037037037037037037e-02,
        0.0,
        0.0,
        1.70828608729473871279604482173e-01,
        1.25467687566822425016691814123e-01,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        3.7109375e-02,
        0.0,
        0.0,
        1.70252211019544039314978060272e-01,
        6.02165389804559606850219397283e-02,
        -1.7578125e-02,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        3.70920001185047927108779319836e-02,
        0.0,
        0.0,
        1.70383925712239993810214054705e-01,
        1.07262030446373284651809199168e-01,
        -1.53194377486244017527936158236e-02,
        8.27378916381402288758473766002e-03,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        6.24110958716075717114429577812e-01,
        0.0,
        0.0,
        -3.36089262944694129406857109825,
        -8.68219346841726006818189891453e-01,
        2.75920996994467083049415600797e+01,
        2.01540675504778934086186788979e+01,
        -4.34898841810699588477366255144e+01,
        0.0,
        0.0,
        0.0,
    ],
    [
        4.77662536438264365890433908527e-01,
        0.0,
        0.0,
        -2.48811461997166764192642586468,
        -5.90290826836842996371446475743e-01,
        2.12300514481811942347288949897e+01,
        1.52792336328824235832596922938e+01,
        -3.32882109689848629194453265587e+01,
        -2.03312017085086261358222928593e-02,
        0.0,
        0.0,
    ],
    [
        -9.3714243008598732571704021658e-01,
        0.0,
        0.0,
        5.18637242884406370830023853209,
        1.09143734899672957818500254654,
        -8.14978701074692612513997267357,
        -1.85200656599969598641566180701e+01,
        2.27394870993505042818970056734e+01,
        2.49360555267965238987089396762,
        -3.0467644718982195003823669022,
        0.0,
    ],
    [
        2.27331014751653820792359768449,
        0.0,
        0.0,
        -1.05344954667372501984066689879e+01,
        -2.00087205822486249909675718444,
        -1.79589318631187989172765950534e+01,
        2.79488845294199600508499808837e+01,
        -2.85899827713502369474065508674,
        -8.87285693353062954433549289258,
        1.23605671757943030647266201528e+01,
        6.43392746015763530355970484046e-01,
    ],
];

/// 8th-order weights.
pub(super) const B: [f64; 12] = [
    5.42937341165687622380535766363e-02,
    0.0,
    0.0,
    0.0,
    0.0,
    4.45031289275240888144113950566,
    1.89151789931450038304281599044,
    -5.8012039600105847814672114227,
    3.1116436695781989440891606237e-01,
    -1.52160949662516078556178806805e-01,
    2.01365400804030348374776537501e-01,
    4.47106157277725905176885569043e-02,
];

/// 3rd-order embedded weights on stages 1, 9, 12.
pub(super) const BHH: [f64; 3] = [
    0.244094488188976377952755905512,
    0.733846688281611857341361741547,
    0.220588235294117647058823529412e-01,
];

/// 8th minus 5th-order weights (the 5th-order error estimate).
pub(super) const ER: [f64; 12] = [
    0.1312004499419488073250102996e-01,
    0.0,
    0.0,
    0.0,
    0.0,
    -0.1225156446376204440720569753e+01,
    -0.4957589496572501915214079952,
    0.1664377182454986536961530415e+01,
    -0.3503288487499736816886487290,
    0.3341791187130174790297318841,
    0.8192320648511571246570742613e-01,
    -0.2235530786388629525884427845e-01,
];

/// DOP853 stepper with scratch allocated once.
pub(super) struct Dop853 {
    ctl: Control,
    k: Vec<f64>,
    ytmp: Vec<f64>,
    ynew: Vec<f64>,
}

impl Dop853 {
    pub(super) fn new(m: usize, h0: f64, rtol: f64, atol: f64) -> Self {
        Dop853 {
            ctl: Control::new(m, h0, rtol, atol),
            k: vec![0.0; 12 * m],
            ytmp: vec![0.0; m],
            ynew: vec![0.0; m],
        }
    }
}

impl Explicit for Dop853 {
    const UNDERFLOW: &'static str = "dop853 step size underflow";
    const NON_FINITE: &'static str = "dop853 (state became non-finite)";

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
        let (k, ytmp, ynew) = (&mut self.k[..], &mut self.ytmp[..], &mut self.ynew[..]);
        for st in 1..12 {
            for i in 0..m {
                let mut acc = 0.0;
                for j in 0..st {
                    acc += A[st][j] * k[j * m + i];
                }
                ytmp[i] = y[i] + h * acc;
            }
            let (_, tail) = k.split_at_mut(st * m);
            f.eval(ytmp, &mut tail[..m]);
        }
        self.ctl.evals += 11;
        let (atol, rtol) = (self.ctl.atol, self.ctl.rtol);
        let (mut err5, mut err3) = (0.0f64, 0.0f64);
        for i in 0..m {
            let mut bsum = 0.0;
            let mut e5 = 0.0;
            for j in 0..12 {
                let kj = k[j * m + i];
                bsum += B[j] * kj;
                e5 += ER[j] * kj;
            }
            let e3 = bsum - BHH[0] * k[i] - BHH[1] * k[8 * m + i] - BHH[2] * k[11 * m + i];
            ynew[i] = y[i] + h * bsum;
            let sk = atol + rtol * y[i].abs().max(ynew[i].abs());
            err5 += scaled(e5, sk).powi(2);
            err3 += scaled(e3, sk).powi(2);
        }
        let deno = if err5 + 0.01 * err3 > 0.0 {
            err5 + 0.01 * err3
        } else {
            1.0
        };
        h.abs() * err5 * (1.0 / (m as f64 * deno)).sqrt()
    }

    #[inline(always)]
    fn accept<F: VectorField>(&mut self, f: &F, y: &mut [f64]) {
        let m = self.ctl.m;
        y.copy_from_slice(&self.ynew);
        f.eval(y, &mut self.k[0..m]);
        self.ctl.evals += 1;
    }

    #[inline(always)]
    fn next_h(&self, h: f64, err: f64, last: bool, accepted: bool) -> f64 {
        // hnew = h / fac, fac = err^(1/8) / 0.9 limited to [1/6, 3] (HNW I, II.4 and dop853).
        let fac = (err.powf(0.125) / 0.9).clamp(1.0 / 6.0, 3.0);
        match (accepted, last) {
            (true, false) => h / fac,
            (true, true) => self.ctl.h,
            (false, _) => h / fac.max(1.0),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_sum_to_nodes() {
        for i in 0..12 {
            let s: f64 = A[i].iter().sum();
            // Summation roundoff: a few ulps of the largest partial sums (|a_ij| up to 43).
            let tol = 8.0 * f64::EPSILON * A[i].iter().map(|x| x.abs()).sum::<f64>();
            assert!((s - C[i]).abs() <= tol, "row {i}: {s} vs {}", C[i]);
        }
    }

    #[test]
    fn quadrature_conditions_to_order_8() {
        // Σ b_i c_i^k = 1/(k+1), k = 0..7 (the bushy trees).
        for k in 0..8 {
            let s: f64 = (0..12).map(|i| B[i] * C[i].powi(k)).sum();
            assert!((s - 1.0 / (k as f64 + 1.0)).abs() < 1e-14, "k = {k}: {s}");
        }
        // Σ b_i a_ij c_j^k = 1/((k+1)(k+2)), k = 0..6 (tall trees of order k+2).
        for k in 0..7 {
            let s: f64 = (0..12)
                .map(|i| B[i] * (0..11).map(|j| A[i][j] * C[j].powi(k)).sum::<f64>())
                .sum();
            let want = 1.0 / ((k as f64 + 1.0) * (k as f64 + 2.0));
            assert!((s - want).abs() < 1e-14, "k = {k}: {s} vs {want}");
        }
        // Embedded weights are consistent: 3rd order Σ bhh = 1 on c = (0, c9, 1).
        assert!((BHH.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        // ER = b8 - b5: Σ ER = 0 and Σ ER c = 0.
        let s0: f64 = ER.iter().sum();
        let s1: f64 = (0..12).map(|i| ER[i] * C[i]).sum();
        assert!(s0.abs() < 1e-14 && s1.abs() < 1e-14, "{s0} {s1}");
    }
}
