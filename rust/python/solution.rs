//! Bindings for `crate::solution`: one frozen class holding a set-up
//! `Solution`; `l` evaluates a flat array of times with the GIL released.

use numpy::ndarray::{Array1, Array2};
use numpy::{Complex64, IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1};
use pyo3::prelude::*;

use std::sync::Arc;

use super::arrays::{array1, l_of_times, out_shape_err};
use crate::solution::Solution;

type C = Complex64;

/// `(idx, num, den)` of [`SolutionCore::quotient`].
type Quotient<'py> = (
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray2<C>>,
    Bound<'py, PyArray1<C>>,
);

/// The explicit theta-function solution through one state.
#[pyclass(name = "SolutionCore", module = "manakov._core", frozen)]
pub struct SolutionCore {
    sol: Arc<Solution>,
}

impl SolutionCore {
    /// A handle on a solution set up elsewhere (the dispatcher's genus-2 kind).
    pub(super) fn from_shared(sol: Arc<Solution>) -> Self {
        SolutionCore { sol }
    }
}

#[pymethods]
impl SolutionCore {
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
        let sol = py.detach(|| Solution::new(&a, &b, &l0))?;
        Ok(SolutionCore { sol: Arc::new(sol) })
    }

    /// `l(t_k)`, `(N, 6)`, for a flat array of times.
    fn l<'py>(
        &self,
        py: Python<'py>,
        t: PyReadonlyArray1<'_, f64>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        l_of_times(py, t, |t, out, cancel| self.sol.l_batch(t, out, cancel))
    }

    /// The Abel image `u(P1) + u(P2)` of a state on the same level set.
    fn abel<'py>(
        &self,
        py: Python<'py>,
        l: PyReadonlyArray1<'_, f64>,
    ) -> PyResult<Bound<'py, PyArray1<C>>> {
        let l: [f64; 6] = array1(&l, "l")?;
        let u = py.detach(|| self.sol.abel(&l))?;
        Ok(Array1::from(u.to_vec()).into_pyarray(py))
    }

    #[getter]
    fn u0<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<C>> {
        Array1::from(self.sol.u0().to_vec()).into_pyarray(py)
    }

    #[getter]
    fn rate<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<C>> {
        Array1::from(self.sol.rate().to_vec()).into_pyarray(py)
    }

    #[getter]
    fn tau<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<C>>> {
        Ok(Array2::from_shape_vec((2, 2), self.sol.tau().to_vec())
            .map_err(out_shape_err)?
            .into_pyarray(py))
    }

    #[getter]
    fn riemann_constant<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<C>> {
        Array1::from(self.sol.riemann_constant().to_vec()).into_pyarray(py)
    }

    /// `(d_0, …, d_4)`.
    #[getter]
    fn branch_points<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<C>> {
        Array1::from(self.sol.curve().branch_points().to_vec()).into_pyarray(py)
    }

    /// Characteristics of the seven labels, `(7, 4)` rows `(a1, a2, b1, b2)`.
    #[getter]
    fn characteristics<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<i64>>> {
        let flat: Vec<i64> = self
            .sol
            .characteristics()
            .iter()
            .flat_map(|(a, b)| [a[0], a[1], b[0], b[1]].map(i64::from))
            .collect();
        Ok(Array2::from_shape_vec((7, 4), flat)
            .map_err(out_shape_err)?
            .into_pyarray(py))
    }

    /// `C_L` of (34) for the seven labels.
    #[getter]
    fn constants<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<C>> {
        Array1::from(self.sol.constants().to_vec()).into_pyarray(py)
    }

    #[getter]
    fn calibration<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        Array1::from(self.sol.calibration().to_vec()).into_pyarray(py)
    }

    #[getter]
    fn self_check(&self) -> f64 {
        self.sol.self_check()
    }

    #[getter]
    fn velocity_check(&self) -> f64 {
        self.sol.velocity_check()
    }

    #[getter]
    fn drift_defect(&self) -> f64 {
        self.sol.drift_defect()
    }

    /// The reasons where the closed form failed a check and each `l(t)` is
    /// certified by an integration, else `None`.
    #[getter]
    fn certify_every(&self) -> Option<String> {
        self.sol.certify_every().map(str::to_string)
    }

    /// `(idx (8,), num (6, 8), den (8,))` of `l_q = N_q/D`.
    fn quotient<'py>(&self, py: Python<'py>) -> PyResult<Quotient<'py>> {
        let (idx, num, den) = self.sol.quotient();
        let flat: Vec<C> = num.iter().flatten().copied().collect();
        Ok((
            Array1::from(idx.iter().map(|&i| i as i64).collect::<Vec<_>>()).into_pyarray(py),
            Array2::from_shape_vec((6, 8), flat)
                .map_err(out_shape_err)?
                .into_pyarray(py),
            Array1::from(den.to_vec()).into_pyarray(py),
        ))
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<SolutionCore>()?;
    Ok(())
}
