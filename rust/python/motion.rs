//! Bindings for `crate::solution::motion` (the dispatcher over every kind of
//! state), its closed forms, and the Jacobi elliptic functions behind them.

use numpy::ndarray::Array1;
use numpy::{Complex64, IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1};
use pyo3::prelude::*;

use super::arrays::{array1, check_call, l_of_times, stack, vec1};
use super::errors::py_cancel;
use super::solution::SolutionCore;
use crate::error::Error;
use crate::numeric::alloc::try_with_capacity;
use crate::solution::jacobi::Jacobi;
use crate::solution::motion::{Kind, Motion};
use crate::solution::transverse::euler_frequencies_with;
use crate::tori::motion::{closed_orbit_frequencies_of_state, torus_of_motion};
use crate::tori::near_euler::near_euler_frequencies;
use crate::tori::near_plane::near_plane_frequencies;

type C = Complex64;

/// `(λ rows, coords rows, ν, U')` of a torus.
type TorusOut<'py> = (
    Bound<'py, PyArray2<C>>,
    Bound<'py, PyArray2<i64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<C>>,
);

/// A solved state of any kind.
#[pyclass(name = "MotionCore", module = "manakov._core", frozen)]
pub struct MotionCore {
    motion: Motion,
}

#[pymethods]
impl MotionCore {
    #[new]
    fn new(
        py: Python<'_>,
        a: PyReadonlyArray1<'_, f64>,
        b: PyReadonlyArray1<'_, f64>,
        l0: PyReadonlyArray1<'_, f64>,
    ) -> PyResult<Self> {
        let a: [f64; 4] = array1(&a, "a")?;
        let b: [f64; 4] = array1(&b, "b")?;
        let l0: [f64; 6] = array1(&l0, "l0")?;
        let motion = py.detach(|| Motion::new(&a, &b, &l0))?;
        Ok(MotionCore { motion })
    }

    /// The kind's name.
    #[getter]
    fn kind(&self) -> &'static str {
        self.motion.kind().name()
    }

    /// `l(t_k)`, `(N, 6)`, for a flat array of times (the user's frame).
    fn l<'py>(
        &self,
        py: Python<'py>,
        t: PyReadonlyArray1<'_, f64>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        l_of_times(py, t, |t, out, cancel| self.motion.l_batch(t, out, cancel))
    }

    /// `l(t_k)` with the polished constants, evaluated in double-double.
    fn l_precise<'py>(
        &self,
        py: Python<'py>,
        t: PyReadonlyArray1<'_, f64>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        l_of_times(py, t, |t, out, cancel| {
            self.motion.l_precise_batch(t, out, cancel)
        })
    }

    /// `(residual, correction)` of the polish of a genus-2 motion's constants.
    fn precise_polish(&self, py: Python<'_>) -> PyResult<(f64, f64)> {
        let Some(sol) = self.motion.genus2() else {
            return Err(Error::Unverified {
                what: "precise l(t)",
                reason: format!(
                    "a motion of kind '{}' has no polished constants",
                    self.motion.kind().name()
                ),
            }
            .into());
        };
        let cancel = py_cancel();
        let p = py.detach(|| sol.precise(&cancel).map(|p| (p.residual(), p.correction())))?;
        Ok(p)
    }

    /// `s` of `l0' = l0/s`.
    #[getter]
    fn state_scale(&self) -> f64 {
        self.motion.state_scale()
    }

    /// `T` of `t' = T t`.
    #[getter]
    fn time_scale(&self) -> f64 {
        self.motion.time_scale()
    }

    /// `(a', c', κ, σ, μ, λ)` of the normalized top.
    fn frame<'py>(
        &self,
        py: Python<'py>,
    ) -> (
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
        [f64; 4],
    ) {
        let f = self.motion.frame();
        (
            Array1::from(f.a.to_vec()).into_pyarray(py),
            Array1::from(f.c4.to_vec()).into_pyarray(py),
            [f.kappa, f.sigma, f.mu, f.lambda],
        )
    }

    /// The genus-2 solution in the normalized frame, or `None`.
    fn genus2(&self) -> Option<SolutionCore> {
        self.motion.genus2_shared().map(SolutionCore::from_shared)
    }

    /// For the Euler kinds: `(subalgebra name, W (3,), M0 (3,), regime,
    /// (m, 1 − m, ω))` in the normalized frame; else `None`.
    #[allow(clippy::type_complexity)]
    fn euler(&self) -> Option<(String, [f64; 3], [f64; 3], &'static str, [f64; 3])> {
        self.motion.euler().map(|(emb, top)| {
            let regime = match top.regime() {
                crate::solution::euler::EulerRegime::Rest => "rest",
                crate::solution::euler::EulerRegime::Axisymmetric => "axisymmetric",
                crate::solution::euler::EulerRegime::Elliptic => "elliptic",
                crate::solution::euler::EulerRegime::Separatrix => "separatrix",
            };
            (emb.name(), top.w(), top.m0(), regime, top.parameters())
        })
    }

    /// `(ν1, ν2)` (user's time) of a state next to an so(3) block, the
    /// self-dual states or a coordinate plane whose frequencies are otherwise
    /// refused: the interpolation between the Euler motion of the nearest
    /// state of that subspace (or the plane's equilibrium) and states farther
    /// out (`crate::tori::near_euler`), the numbers the frequency map gives.
    /// Raises where it does not apply or its bound fails.
    fn near_euler_frequencies(&self, py: Python<'_>) -> PyResult<[f64; 2]> {
        let cancel = py_cancel();
        Ok(py.detach(|| near_euler_frequencies(self.motion.frame(), self.motion.l0(), &cancel))?)
    }

    /// The route of `near_euler_frequencies` next to the nearest coordinate
    /// plane alone (`crate::tori::near_plane`), for checks against the
    /// genus-2 torus where both answer.
    fn near_plane_frequencies(&self, py: Python<'_>) -> PyResult<[f64; 2]> {
        let cancel = py_cancel();
        Ok(py.detach(|| near_plane_frequencies(self.motion.frame(), self.motion.l0(), &cancel))?)
    }

    /// The frequency map's last route alone (`crate::tori::closed_orbits`),
    /// for checks against the genus-2 torus where both answer.
    fn closed_orbit_frequencies(&self, py: Python<'_>) -> PyResult<[f64; 2]> {
        let cancel = py_cancel();
        Ok(py.detach(|| {
            closed_orbit_frequencies_of_state(self.motion.frame(), self.motion.l0(), &cancel)
        })?)
    }

    /// `(ν1, ν2)` of the closed forms (user's time): `(ν_⊥, ν_E)` of
    /// `crate::solution::transverse` for an Euler motion; `(0, 0)` on the
    /// separatrix (no period: the limit of both) and for the constant kinds.
    fn closed_form_frequencies(&self, py: Python<'_>) -> PyResult<[f64; 2]> {
        match self.motion.kind() {
            Kind::Euler => {
                let cancel = py_cancel();
                Ok(py.detach(|| euler_frequencies_with(&self.motion, &cancel))?)
            }
            Kind::Genus2 => Err(Error::InvalidArgument {
                what: "frequencies",
                reason: "a genus-2 motion's frequencies are its torus's".into(),
            }
            .into()),
            Kind::Integrated => Err(Error::Unverified {
                what: "frequencies",
                reason: format!(
                    "{}; its frequencies are not known",
                    self.motion.stand_ins().1
                ),
            }
            .into()),
            _ => Ok([0.0, 0.0]),
        }
    }

    /// `(calls, why)` of [`Motion::stand_ins`].
    #[getter]
    fn stand_ins(&self) -> (u64, String) {
        self.motion.stand_ins()
    }

    /// The count alone ([`Motion::stand_in_calls`]).
    #[getter]
    fn stand_in_calls(&self) -> u64 {
        self.motion.stand_in_calls()
    }

    /// The real torus of a genus-2 motion: `(λ rows, coords rows, ν, U')`.
    fn torus<'py>(&self, py: Python<'py>) -> PyResult<TorusOut<'py>> {
        let (t, u2) = {
            let cancel = py_cancel();
            py.detach(|| torus_of_motion(&self.motion, &cancel))
        }?;
        Ok((
            stack(t.lambda)?.into_pyarray(py),
            stack(t.coords)?.into_pyarray(py),
            Array1::from(t.nu.to_vec()).into_pyarray(py),
            Array1::from(u2.to_vec()).into_pyarray(py),
        ))
    }
}

/// `(sn, cn, dn, am)` of `u` (flat array) at parameter `m`, complement `m1`.
#[pyfunction(name = "jacobi_ellipj")]
#[allow(clippy::type_complexity)]
fn jacobi_ellipj_py<'py>(
    py: Python<'py>,
    u: PyReadonlyArray1<'py, f64>,
    m: f64,
    m1: f64,
) -> PyResult<(
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
)> {
    let j = Jacobi::new(m, m1)?;
    // u and the four results.
    check_call("u", u.as_array().len(), 5 * std::mem::size_of::<f64>())?;
    let u = vec1(&u, "u", None)?;
    crate::error::check_finite("u", &u)?;
    let mut out = [
        try_with_capacity("sn", u.len())?,
        try_with_capacity("cn", u.len())?,
        try_with_capacity("dn", u.len())?,
        try_with_capacity("am", u.len())?,
    ];
    for &x in &u {
        let (s, c, d) = j.sncndn(x);
        out[0].push(s);
        out[1].push(c);
        out[2].push(d);
        out[3].push(j.am(x));
    }
    let [s, c, d, a] = out.map(|v| Array1::from(v).into_pyarray(py));
    Ok((s, c, d, a))
}

/// `(K(m), [F(φ_k | m)])`.
#[pyfunction(name = "jacobi_ellipf")]
fn jacobi_ellipf_py<'py>(
    py: Python<'py>,
    phi: PyReadonlyArray1<'py, f64>,
    m: f64,
    m1: f64,
) -> PyResult<(f64, Bound<'py, PyArray1<f64>>)> {
    let j = Jacobi::new(m, m1)?;
    let phi = phi.as_array();
    check_call("phi", phi.len(), 2 * std::mem::size_of::<f64>())?;
    let mut f: Vec<f64> = try_with_capacity("F", phi.len())?;
    for &p in phi.iter() {
        f.push(j.f(p)?);
    }
    Ok((j.quarter_period(), Array1::from(f).into_pyarray(py)))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<MotionCore>()?;
    m.add_function(wrap_pyfunction!(jacobi_ellipj_py, m)?)?;
    m.add_function(wrap_pyfunction!(jacobi_ellipf_py, m)?)?;
    Ok(())
}
