//! Evaluation at one point: the class sums over the half-integer lattice
//! (`sum.rs`) at the reduced point, combined into the 4^g characteristics by
//! Walsh–Hadamard transforms, with the unit factors of the reductions of `z`
//! and `Re τ`, and the derivatives by the product rule.

use super::reduce::Reduced;
use super::{pi, ThetaJet, ThetaPlan, Workspace, MAX_GENUS};
use crate::error::{Error, Result};
use crate::numeric::cancel::Cancel;
use num_complex::Complex64;

impl ThetaPlan {
    /// All 4^g normalised values `Ω` and `L` with `θ = exp(L) Ω` at one point `z`.
    pub fn theta_all(&self, z: &[Complex64]) -> Result<(Vec<Complex64>, f64)> {
        let jet = self.jet(z, 0)?;
        Ok((jet.values, jet.log_scale))
    }

    /// Values and derivatives up to `order ≤ self.order()` at one point.
    pub fn jet(&self, z: &[Complex64], order: usize) -> Result<ThetaJet> {
        let n = 1usize << (2 * self.g);
        let g = self.g;
        let mut ws = self.workspace();
        let mut values = vec![Complex64::new(0.0, 0.0); n];
        let mut gradient = vec![Complex64::new(0.0, 0.0); if order >= 1 { n * g } else { 0 }];
        let mut hessian = vec![Complex64::new(0.0, 0.0); if order >= 2 { n * g * g } else { 0 }];
        let log_scale = self.eval_into(z, &mut ws, &mut values, &mut gradient, &mut hessian)?;
        Ok(ThetaJet {
            g,
            values,
            gradient,
            hessian,
            log_scale,
        })
    }

    /// Core evaluation at one point: writes the normalised values (length 4^g),
    /// gradient (length 4^g·g, or empty to skip) and Hessian (4^g·g², or empty)
    /// and returns `L`.
    pub fn eval_into(
        &self,
        z: &[Complex64],
        ws: &mut Workspace,
        values: &mut [Complex64],
        gradient: &mut [Complex64],
        hessian: &mut [Complex64],
    ) -> Result<f64> {
        self.eval_into_cancel(z, ws, values, gradient, hessian, None)
    }

    /// [`ThetaPlan::eval_into`] whose lattice sum checks `cancel` every few
    /// dozen rows (a single point may take up to `MAX_SECONDS_PER_POINT`)
    /// and stops with [`Error::Interrupted`].
    pub fn eval_into_cancel(
        &self,
        z: &[Complex64],
        ws: &mut Workspace,
        values: &mut [Complex64],
        gradient: &mut [Complex64],
        hessian: &mut [Complex64],
        cancel: Option<&Cancel>,
    ) -> Result<f64> {
        let g = self.g;
        let n = 1usize << (2 * g);
        if z.len() != g {
            return Err(Error::Shape {
                what: "z",
                expected: format!("({g},)"),
                got: format!("({},)", z.len()),
            });
        }
        let order = if !hessian.is_empty() {
            2
        } else if !gradient.is_empty() {
            1
        } else {
            0
        };
        if values.len() != n
            || (order >= 1 && gradient.len() != n * g)
            || (order == 2 && hessian.len() != n * g * g)
        {
            return Err(Error::Shape {
                what: "theta output",
                expected: format!("{n} values, {} gradient, {} hessian", n * g, n * g * g),
                got: format!("{}, {}, {}", values.len(), gradient.len(), hessian.len()),
            });
        }
        if order > self.order {
            return Err(Error::InvalidArgument {
                what: "order",
                reason: format!(
                    "plan built for derivative order {}, asked for {order}",
                    self.order
                ),
            });
        }
        if ws.s0.len() != n || ws.s2.len() != n * g * g {
            // a workspace made by a plan of another genus
            *ws = self.workspace();
        }
        let red = self.reduce(z)?;
        let (zr, wr) = (&red.zr[..g], &red.wr[..g]);
        ws.s0.iter_mut().for_each(|v| *v = Complex64::new(0.0, 0.0));
        if order >= 1 {
            ws.s1.iter_mut().for_each(|v| *v = Complex64::new(0.0, 0.0));
        }
        if order >= 2 {
            ws.s2.iter_mut().for_each(|v| *v = Complex64::new(0.0, 0.0));
        }
        match (self.fast_g2, order) {
            (true, 0) => self.sum_g2::<0>(zr, wr, ws, cancel)?,
            (true, 1) => self.sum_g2::<1>(zr, wr, ws, cancel)?,
            (true, _) => self.sum_g2::<2>(zr, wr, ws, cancel)?,
            (false, 0) => self.sum_generic::<0>(zr, wr, ws, cancel)?,
            (false, 1) => self.sum_generic::<1>(zr, wr, ws, cancel)?,
            (false, _) => self.sum_generic::<2>(zr, wr, ws, cancel)?,
        }
        self.combine(&red, ws, order, values, gradient, hessian);
        Ok(red.log_scale)
    }

    /// Genus 2, values only: 4 Walsh–Hadamard transforms of length 4 (the hot
    /// case written out; takes the class sums directly to avoid a copy).
    fn combine_g2_values(
        &self,
        red: &Reduced,
        s0: impl Fn(usize) -> Complex64,
        values: &mut [Complex64],
    ) {
        let (prefactor, pbits, qbits) = (red.prefactor, red.pbits, red.qbits);
        // The hot case written out: 4 Walsh–Hadamard transforms of length 4.
        for a in 0..4usize {
            let r = &self.class_of[4 * a..4 * a + 4];
            let (s0, s1, s2, s3) = (s0(r[0]), s0(r[1]), s0(r[2]), s0(r[3]));
            let (p0, p1, p2, p3) = (s0 + s1, s0 - s1, s2 + s3, s2 - s3);
            let v = [p0 + p2, p1 + p3, p0 - p2, p1 - p3];
            let sa = (a & pbits).count_ones();
            for (b, vb) in v.iter().enumerate() {
                let sign = ((sa + (b & qbits).count_ones()) & 1) as u8;
                let u = self.unit_pow[(a << 2) | b].wrapping_add(2 * sign);
                // table lookup, not a branch: u depends on the parities of p, q
                values[(a << 2) | b] = I_POW[(u & 3) as usize] * prefactor * vb;
            }
        }
    }

    /// Class sums in `ws` → the 4^g outputs (and derivatives) at the original point.
    fn combine(
        &self,
        red: &Reduced,
        ws: &mut Workspace,
        order: usize,
        values: &mut [Complex64],
        gradient: &mut [Complex64],
        hessian: &mut [Complex64],
    ) {
        let g = self.g;
        let (prefactor, pbits, qbits, q) = (red.prefactor, red.pbits, red.qbits, &red.q);
        // θ[a;b] = i^{a·b} Σ_h (-1)^{h·b} S[a + 2h]: a Walsh–Hadamard transform over h
        // per a, then one unit factor per characteristic collecting i^{a·b},
        // i^{aᵀSa} (Re τ reduction) and (-1)^{a·p + b·q} (z reduction).
        if g == 2 && order == 0 {
            return self.combine_g2_values(red, |r| ws.s0[r], values);
        }
        let nh = 1usize << g;
        let ipi = Complex64::new(0.0, pi());
        let mut gq = [Complex64::new(0.0, 0.0); MAX_GENUS];
        for k in 0..g {
            // gradient of the reduction prefactor exp(-2πi qᵀz)
            gq[k] = Complex64::new(0.0, -2.0 * pi() * q[k]);
        }
        let Workspace {
            s0,
            s1,
            s2,
            buf,
            vrow,
            grow,
            ..
        } = ws;
        for a in 0..nh {
            let rows = &self.class_of[a * nh..(a + 1) * nh];
            let mut units = [0u8; 1 << MAX_GENUS];
            for (b, u) in units[..nh].iter_mut().enumerate() {
                let sign = ((a & pbits).count_ones() + (b & qbits).count_ones()) as u8 & 1;
                *u = self.unit_pow[(a << g) | b].wrapping_add(2 * sign);
            }
            let fac = |b: usize| times_i_pow(prefactor, units[b]);
            for (h, &r) in rows.iter().enumerate() {
                vrow[h] = s0[r];
            }
            walsh_hadamard(&mut vrow[..nh]);
            for b in 0..nh {
                values[(a << g) | b] = fac(b) * vrow[b];
            }
            if order >= 1 {
                for k in 0..g {
                    for (h, &r) in rows.iter().enumerate() {
                        buf[h] = s1[r * g + k];
                    }
                    walsh_hadamard(&mut buf[..nh]);
                    for b in 0..nh {
                        let gr = ipi * buf[b];
                        grow[b * g + k] = gr;
                        gradient[((a << g) | b) * g + k] = fac(b) * (gr + gq[k] * vrow[b]);
                    }
                }
            }
            if order >= 2 {
                for k in 0..g {
                    for l in 0..g {
                        for (h, &r) in rows.iter().enumerate() {
                            buf[h] = s2[(r * g + k) * g + l];
                        }
                        walsh_hadamard(&mut buf[..nh]);
                        for b in 0..nh {
                            let hkl = -pi() * pi() * buf[b]
                                + gq[k] * grow[b * g + l]
                                + grow[b * g + k] * gq[l]
                                + gq[k] * gq[l] * vrow[b];
                            hessian[(((a << g) | b) * g + k) * g + l] = fac(b) * hkl;
                        }
                    }
                }
            }
        }
    }
}

/// `i^k`, `k = 0..4`.
const I_POW: [Complex64; 4] = [
    Complex64::new(1.0, 0.0),
    Complex64::new(0.0, 1.0),
    Complex64::new(-1.0, 0.0),
    Complex64::new(0.0, -1.0),
];

/// `v · i^p` by swapping and negating parts.
#[inline(always)]
fn times_i_pow(v: Complex64, p: u8) -> Complex64 {
    match p & 3 {
        0 => v,
        1 => Complex64::new(-v.im, v.re),
        2 => -v,
        _ => Complex64::new(v.im, -v.re),
    }
}

/// In-place Walsh–Hadamard transform `v_b ← Σ_h (-1)^{popcount(h & b)} v_h`.
#[inline(always)]
fn walsh_hadamard(v: &mut [Complex64]) {
    let n = v.len();
    let mut half = 1;
    while half < n {
        for start in (0..n).step_by(2 * half) {
            for i in start..start + half {
                let (x, y) = (v[i], v[i + half]);
                v[i] = x + y;
                v[i + half] = x - y;
            }
        }
        half *= 2;
    }
}
