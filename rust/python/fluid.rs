//! Bindings for `crate::fluid`: a frozen class holding a Kirchhoff body
//! (field, energy, integration with the GIL released), and one holding the
//! Clebsch conjugacy (the maps to and from the conjugate Manakov top).

use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyArray3, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2,
};
use pyo3::prelude::*;

use super::arrays::{array1, map_rows, rows, shape_err, vec1, vec2};
use super::integrate::{check_samples, run_many, run_partial, IntegrateOut};
use crate::fluid::clebsch::ClebschConjugacy;
use crate::fluid::{self, KirchhoffBody, SpaceMotion, DIM, SPACE_DIM};
use crate::integrate::Options;

/// A 3 × 3 array as its 9 entries, row-major.
fn mat3(x: &PyReadonlyArray2<'_, f64>, what: &'static str) -> PyResult<[f64; 9]> {
    let r = rows::<f64, 3>(x, what, Some(3))?;
    Ok(std::array::from_fn(|k| r[k / 3][k % 3]))
}

/// Checks that `y` holds states of [`DIM`] entries on its last axis.
fn check_six(y: &PyReadonlyArray2<'_, f64>, what: &'static str) -> PyResult<()> {
    let v = y.as_array();
    if v.ncols() != DIM {
        return Err(shape_err(what, format!("(n, {DIM})"), v.shape()));
    }
    Ok(())
}

/// `f` of one state as the row of `K` values of [`map_rows`].
fn six<const K: usize>(
    f: impl Fn(&[f64; DIM]) -> [f64; K],
) -> impl Fn(&[f64], &mut [f64]) -> crate::error::Result<()> {
    move |x, o| {
        let x: [f64; DIM] = std::array::from_fn(|k| x[k]);
        o.copy_from_slice(&f(&x));
        Ok(())
    }
}

/// A rigid body in an ideal fluid, `H = ½ (Mᵀ A M + 2 Mᵀ B p + pᵀ C p)`.
#[pyclass(name = "KirchhoffCore", module = "manakov._core", frozen)]
pub struct KirchhoffCore {
    body: KirchhoffBody,
}

#[pymethods]
impl KirchhoffCore {
    #[new]
    fn new(
        a: PyReadonlyArray2<'_, f64>,
        b: PyReadonlyArray2<'_, f64>,
        c: PyReadonlyArray2<'_, f64>,
    ) -> PyResult<Self> {
        let (a, b, c) = (mat3(&a, "A")?, mat3(&b, "B")?, mat3(&c, "C")?);
        Ok(KirchhoffCore {
            body: KirchhoffBody::new(&a, &b, &c)?,
        })
    }

    /// `‖Q'‖₂`, the rate scale of the field (Casimir parts removed).
    #[getter]
    fn rate_scale(&self) -> f64 {
        self.body.rate_scale()
    }

    /// Kirchhoff's equations at each row of `y` (N, 6).
    fn vector_field<'py>(
        &self,
        py: Python<'py>,
        y: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        check_six(&y, "y")?;
        map_rows(py, &y, "y", DIM, 20.0, six(|s| self.body.vector_field(s)))
    }

    /// The energy at each row of `y` (N, 6).
    fn hamiltonian<'py>(
        &self,
        py: Python<'py>,
        y: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        check_six(&y, "y")?;
        let rows = y.as_array().nrows();
        let out = map_rows(py, &y, "y", 1, 20.0, six(|s| [self.body.hamiltonian(s)]))?;
        out.reshape([rows])
    }

    /// Integrates from `y0` (6,) at `t0`, sampling at `times`: `(y (S', 6), steps,
    /// evals, error)` (see `integrate` of the so(4) bindings).
    #[pyo3(signature = (y0, t0, times, method, dt, rtol, atol, max_steps))]
    #[allow(clippy::too_many_arguments)]
    fn integrate<'py>(
        &self,
        py: Python<'py>,
        y0: PyReadonlyArray1<'py, f64>,
        t0: f64,
        times: PyReadonlyArray1<'py, f64>,
        method: &str,
        dt: f64,
        rtol: f64,
        atol: f64,
        max_steps: u64,
    ) -> PyResult<IntegrateOut<'py>> {
        let y0: [f64; DIM] = array1(&y0, "y0")?;
        check_samples(times.as_array().len(), 1, DIM)?;
        let times = vec1(&times, "times", None)?;
        let opts = Options::parse(method, dt, rtol, atol, max_steps)?;
        run_partial(py, &self.body, &y0, t0, &times, &opts, None)
    }

    /// Integrates a batch `y0s` (B, 6); returns `(y (B, S, 6), steps)`.
    #[pyo3(signature = (y0s, t0, times, method, dt, rtol, atol, max_steps, parallel))]
    #[allow(clippy::too_many_arguments)]
    fn integrate_many<'py>(
        &self,
        py: Python<'py>,
        y0s: PyReadonlyArray2<'py, f64>,
        t0: f64,
        times: PyReadonlyArray1<'py, f64>,
        method: &str,
        dt: f64,
        rtol: f64,
        atol: f64,
        max_steps: u64,
        parallel: bool,
    ) -> PyResult<(Bound<'py, PyArray3<f64>>, u64)> {
        check_six(&y0s, "y0s")?;
        check_samples(times.as_array().len(), y0s.as_array().nrows(), DIM)?;
        let (flat, n, _) = vec2(&y0s, "y0s")?;
        let times = vec1(&times, "times", None)?;
        let opts = Options::parse(method, dt, rtol, atol, max_steps)?;
        run_many(py, &self.body, &flat, n, t0, &times, &opts, parallel, None)
    }

    /// Integrates the body with its rotation and position, `s0 = (M, p, R row-major,
    /// x)` (18,): `(s (S', 18), steps, evals, error)`.
    #[pyo3(signature = (s0, t0, times, method, dt, rtol, atol, max_steps))]
    #[allow(clippy::too_many_arguments)]
    fn integrate_space<'py>(
        &self,
        py: Python<'py>,
        s0: PyReadonlyArray1<'py, f64>,
        t0: f64,
        times: PyReadonlyArray1<'py, f64>,
        method: &str,
        dt: f64,
        rtol: f64,
        atol: f64,
        max_steps: u64,
    ) -> PyResult<IntegrateOut<'py>> {
        let s0: [f64; SPACE_DIM] = array1(&s0, "s0")?;
        check_samples(times.as_array().len(), 1, SPACE_DIM)?;
        let times = vec1(&times, "times", None)?;
        let opts = Options::parse(method, dt, rtol, atol, max_steps)?;
        run_partial(
            py,
            &SpaceMotion { body: &self.body },
            &s0,
            t0,
            &times,
            &opts,
            None,
        )
    }
}

/// The Casimirs `(p·p, M·p)` at each row of `y` (N, 6).
#[pyfunction(name = "kirchhoff_casimirs")]
fn kirchhoff_casimirs_py<'py>(
    py: Python<'py>,
    y: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    check_six(&y, "y")?;
    map_rows(py, &y, "y", 2, 10.0, six(fluid::casimirs))
}

/// The linear conjugacy of a Clebsch body to a Manakov top.
#[pyclass(name = "ClebschCore", module = "manakov._core", frozen)]
pub struct ClebschCore {
    conj: ClebschConjugacy,
}

#[pymethods]
impl ClebschCore {
    #[new]
    fn new(a: PyReadonlyArray1<'_, f64>, c: PyReadonlyArray1<'_, f64>) -> PyResult<Self> {
        let (a, c): ([f64; 3], [f64; 3]) = (array1(&a, "A")?, array1(&c, "C")?);
        Ok(ClebschCore {
            conj: ClebschConjugacy::new(&a, &c)?,
        })
    }

    /// `a` of the conjugate Manakov top.
    #[getter]
    fn alpha<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.conj.alpha().to_vec().into_pyarray(py)
    }

    /// `b` of the conjugate Manakov top.
    #[getter]
    fn beta<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.conj.beta().to_vec().into_pyarray(py)
    }

    /// The original index of each of the top's indices (0–2 the axes, 3 = ∞).
    #[getter]
    fn order<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        self.conj
            .order()
            .iter()
            .map(|&o| o as i64)
            .collect::<Vec<_>>()
            .into_pyarray(py)
    }

    /// The body's `a_i` (`a_j − a_k = (C_k − C_j)/A_i`, mean 0).
    #[getter]
    fn body_a<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.conj.body_a().to_vec().into_pyarray(py)
    }

    /// Clebsch's condition relative to its terms.
    #[getter]
    fn violation(&self) -> f64 {
        self.conj.violation()
    }

    /// `(σ, λ)` of the Möbius map `s = σ + λ/t`.
    #[getter]
    fn mobius(&self) -> (f64, f64) {
        self.conj.mobius()
    }

    /// `l = L y` for each row of `y` (N, 6).
    fn to_so4<'py>(
        &self,
        py: Python<'py>,
        y: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        check_six(&y, "y")?;
        map_rows(py, &y, "y", DIM, 20.0, six(|s| self.conj.to_so4(s)))
    }

    /// `y = L⁻¹ l` for each row of `l` (N, 6).
    fn to_body<'py>(
        &self,
        py: Python<'py>,
        l: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        check_six(&l, "l")?;
        map_rows(py, &l, "l", DIM, 20.0, six(|s| self.conj.to_body(s)))
    }
}

/// Adds this module's classes and functions to `manakov._core`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<KirchhoffCore>()?;
    m.add_class::<ClebschCore>()?;
    m.add_function(wrap_pyfunction!(kirchhoff_casimirs_py, m)?)?;
    Ok(())
}
