//! Lattice coordinates of the velocities of the closed form ([`super::dubrovin`]):
//! `(X, Y)` with `V = A X + B Y` and `U = X + τY`, the periods in
//! double-double where the branch points are known beyond double, and the
//! real structure of the torus imposed exactly.

use num_complex::Complex64;

use super::dubrovin::CLOSED_FORM;
use crate::error::{Error, Result};
use crate::numeric::dd::{Cdd, Dd};
use crate::riemann::HyperellipticCurve;

type C = Complex64;

/// Lattice coordinates of the velocities, with the real structure imposed.
#[derive(Debug, Clone, PartialEq)]
pub struct LatticeRates {
    /// `U = X + τ Y` of each flow (normalised: `u(t) = u0 + U t`).
    pub u: Vec<[C; 2]>,
    /// `(X_1, X_2, Y_1, Y_2)` of each flow: `V = A X + B Y`.
    pub w: Vec<[f64; 4]>,
    /// The rounding errors of `w`: `w + w_lo` is `(X, Y)` to DD accuracy when
    /// the periods were computed in DD ([`LatticeRates::periods_dd`]).
    pub w_lo: Vec<[f64; 4]>,
    /// Whether the periods entered in DD on the curve's unrounded branch
    /// points (else in double: no rounding errors given, or a quadrature
    /// piece plan that does not close).
    pub periods_dd: bool,
    /// The integer matrix `T` (row-major) of the antiholomorphic involution on
    /// the lattice coordinates, when one fixes the velocities (`None`: none
    /// found, nothing imposed).
    pub involution: Option<[[i64; 4]; 4]>,
}

/// An integer matrix is taken as such when every entry is this close to an
/// integer: the periods are accurate to ~1e-15, so a true lattice map misses
/// by that much, and a non-lattice map by O(1).
const INTEGER_TOL: f64 = 1e-6;

/// A velocity is taken as fixed by an involution `V ↦ D V̄` when it moves by
/// less than this, relative (the closed form keeps ~1e-16; a flow not tangent
/// to a real torus moves by O(1)).
const FIXED_TOL: f64 = 1e-8;

/// `(X, Y)` with `V = A X + B Y` (`A`, `B` the a- and b-periods) for each `V`,
/// and `U = X + τY`.
///
/// Precision: `V` in DD, the periods in DD on the branch points `e + e_lo`
/// (`e_lo` their rounding errors, when given and when every cycle edge is a
/// Chebyshev one, [`HyperellipticCurve::periods_dd`]), the real 4 × 4 system
/// solved in double and refined twice with DD residuals: `w + w_lo` is then
/// `(X, Y)` to ~1e-20 relative, and the motion's phase `x0 + (w + w_lo) t`
/// keeps its digits at large `t`.
///
/// The real structure is imposed exactly: the curve of a real state is
/// invariant under `x ↦ x̄` (real `d_j`) or `x ↦ −x̄` (imaginary `d_j`), which
/// acts on the differentials `(1, x) dx/y` as `V ↦ D V̄` with `D = ±1` or
/// `D = ±diag(i, −i)` and on the lattice coordinates as an integer matrix `T`
/// (`D Π̄ = Π T`, `Π = [A B]`). The velocities of a real motion are fixed by it
/// (`T w = w`), so `w` is replaced by `(w + T w)/2`: components that are zero
/// by symmetry become exactly zero instead of ~1e-16 (which would move the
/// motion off the real torus by `1e-16 t`). Where no such `D` fixes every
/// velocity (a complex level set, or all of them zero), nothing is imposed.
pub(crate) fn lattice_rates_dd(
    curve: &HyperellipticCurve,
    e_lo: Option<&[C]>,
    v: &[[Cdd; 2]],
) -> Result<LatticeRates> {
    let pm = PeriodMatrix::new(curve, e_lo)?;
    let singular = || Error::InvalidArgument {
        what: CLOSED_FORM,
        reason: "the period matrix [A B] is singular as a real 4 x 4 matrix".into(),
    };
    let mut w: Vec<[Dd; 4]> = v
        .iter()
        .map(|z| {
            pm.solve([z[0].re, z[1].re, z[0].im, z[1].im])
                .ok_or_else(singular)
        })
        .collect::<Result<_>>()?;
    let vc: Vec<[C; 2]> = v.iter().map(|z| z.map(|x| x.to_c())).collect();
    let involution = pm.involution(&vc);
    if let Some(t) = involution {
        for wf in &mut w {
            let tw: [Dd; 4] = std::array::from_fn(|r| {
                (0..4).fold(Dd::ZERO, |acc, k| acc.add(wf[k].mul_f64(t[r][k] as f64)))
            });
            *wf = std::array::from_fn(|r| wf[r].add(tw[r]).mul_f64(0.5));
        }
    }
    let tau = curve.tau_row_major();
    let hi: Vec<[f64; 4]> = w.iter().map(|wf| wf.map(|x| x.to_f64())).collect();
    let lo: Vec<[f64; 4]> = w
        .iter()
        .zip(&hi)
        .map(|(wf, h)| std::array::from_fn(|r| wf[r].sub(Dd::new(h[r])).to_f64()))
        .collect();
    let u = hi
        .iter()
        .map(|wf| {
            [
                C::new(wf[0], 0.0) + tau[0] * wf[2] + tau[1] * wf[3],
                C::new(wf[1], 0.0) + tau[2] * wf[2] + tau[3] * wf[3],
            ]
        })
        .collect();
    Ok(LatticeRates {
        u,
        w: hi,
        w_lo: lo,
        periods_dd: pm.dd,
        involution,
    })
}

/// `Π = [A B]` as a real 4 × 4 matrix (rows Re, Re, Im, Im), in DD where the
/// periods are, with the LU factors of its double for the refinements.
struct PeriodMatrix {
    /// The columns of `Π` in double (a- then b-periods).
    cols: [[C; 2]; 4],
    pi_dd: [[Dd; 4]; 4],
    lu: nalgebra::LU<f64, nalgebra::Const<4>, nalgebra::Const<4>>,
    /// Whether the periods entered in DD.
    dd: bool,
}

impl PeriodMatrix {
    fn new(curve: &HyperellipticCurve, e_lo: Option<&[C]>) -> Result<Self> {
        let (a, b) = curve.periods();
        let cols: [[C; 2]; 4] = [
            [a[(0, 0)], a[(1, 0)]],
            [a[(0, 1)], a[(1, 1)]],
            [b[(0, 0)], b[(1, 0)]],
            [b[(0, 1)], b[(1, 1)]],
        ];
        let pdd = match e_lo {
            Some(lo) => curve.periods_dd(lo)?,
            None => None,
        };
        let pi_dd: [[Dd; 4]; 4] = std::array::from_fn(|r| {
            std::array::from_fn(|k| {
                let z = match &pdd {
                    Some(p) if k < 2 => p.a[r % 2][k],
                    Some(p) => p.b[r % 2][k - 2],
                    None => Cdd::new(cols[k][r % 2]),
                };
                if r < 2 {
                    z.re
                } else {
                    z.im
                }
            })
        });
        let pi = nalgebra::Matrix4::from_fn(|r, k| pi_dd[r][k].to_f64());
        Ok(PeriodMatrix {
            cols,
            pi_dd,
            lu: pi.lu(),
            dd: pdd.is_some(),
        })
    }

    /// `Π w = rhs` in DD: the double LU refined with DD residuals, three
    /// times with DD periods (DD accuracy), once with double ones (as good as
    /// the periods). `None` where `Π` is singular or `w` not finite.
    fn solve(&self, rhs: [Dd; 4]) -> Option<[Dd; 4]> {
        let steps = if self.dd { 3 } else { 1 };
        let mut w = [Dd::ZERO; 4];
        for _ in 0..steps {
            let res: [f64; 4] = std::array::from_fn(|r| {
                (0..4)
                    .fold(rhs[r], |acc, k| acc.sub(self.pi_dd[r][k].mul(w[k])))
                    .to_f64()
            });
            let dw = self.lu.solve(&nalgebra::Vector4::from(res))?;
            w = std::array::from_fn(|k| w[k].add(Dd::new(dw[k])));
        }
        w.iter().all(|x| x.hi.is_finite()).then_some(w)
    }

    /// The involution of the real structure: the integer matrix `T` of the
    /// candidate `D` that fixes every velocity `vc` (at least one of them
    /// non-zero) and maps the lattice to itself (found in double: `T` is an
    /// integer matrix); `None` where no candidate does.
    fn involution(&self, vc: &[[C; 2]]) -> Option<[[i64; 4]; 4]> {
        let real4 = |z: [C; 2]| nalgebra::Vector4::new(z[0].re, z[1].re, z[0].im, z[1].im);
        let i = C::new(0.0, 1.0);
        let one = C::new(1.0, 0.0);
        if !vc.iter().any(|z| z[0].norm().max(z[1].norm()) > 0.0) {
            return None;
        }
        for dg in [[one, one], [-one, -one], [i, -i], [-i, i]] {
            let fixed = vc.iter().all(|z| {
                let moved = (dg[0] * z[0].conj() - z[0])
                    .norm()
                    .max((dg[1] * z[1].conj() - z[1]).norm());
                moved <= FIXED_TOL * z[0].norm().max(z[1].norm())
            });
            if !fixed {
                continue;
            }
            let mut t = [[0i64; 4]; 4];
            let mut ok = true;
            for (k, col) in self.cols.iter().enumerate() {
                let image = real4([dg[0] * col[0].conj(), dg[1] * col[1].conj()]);
                match self.lu.solve(&image) {
                    Some(tk) => {
                        for r in 0..4 {
                            let n = tk[r].round();
                            ok &= (tk[r] - n).abs() <= INTEGER_TOL && n.abs() < 1e6;
                            t[r][k] = n as i64;
                        }
                    }
                    None => ok = false,
                }
            }
            if ok {
                return Some(t);
            }
        }
        None
    }
}
