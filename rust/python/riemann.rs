//! Bindings for `crate::riemann`: one frozen class holding a built
//! `HyperellipticCurve` (its construction is the expensive step), with
//! methods on flattened arrays that the Python layer has broadcast.

use numpy::ndarray::{Array1, Array2};
use numpy::{Complex64, IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

use super::arrays::{check_call, out_shape_err, shape_err, vec1};
use super::errors::py_cancel;
use crate::numeric::alloc::try_collect;
use crate::riemann::{AbelRoute, HyperellipticCurve};

type C = Complex64;

fn matrix_to_array(m: &nalgebra::DMatrix<C>) -> Array2<C> {
    Array2::from_shape_fn((m.nrows(), m.ncols()), |(i, j)| m[(i, j)])
}

/// A hyperelliptic curve with its homology basis, periods and Abel map.
#[pyclass(name = "HyperellipticCore", module = "manakov._core", frozen)]
pub struct HyperellipticCore {
    curve: HyperellipticCurve,
}

#[pymethods]
impl HyperellipticCore {
    #[new]
    fn new(py: Python<'_>, branch_points: PyReadonlyArray1<'_, C>) -> PyResult<Self> {
        let e = vec1(&branch_points, "branch_points", None)?;
        let curve = py.detach(|| HyperellipticCurve::new(&e))?;
        Ok(HyperellipticCore { curve })
    }

    #[getter]
    fn genus(&self) -> usize {
        self.curve.genus()
    }

    #[getter]
    fn branch_points<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<C>> {
        Array1::from(self.curve.branch_points().to_vec()).into_pyarray(py)
    }

    /// `(A, B)`, `g × g` each.
    fn periods<'py>(&self, py: Python<'py>) -> (Bound<'py, PyArray2<C>>, Bound<'py, PyArray2<C>>) {
        let (a, b) = self.curve.periods();
        (
            matrix_to_array(a).into_pyarray(py),
            matrix_to_array(b).into_pyarray(py),
        )
    }

    fn tau<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<C>> {
        matrix_to_array(self.curve.tau()).into_pyarray(py)
    }

    /// `∮_{c_j} ω_i` of the tree loops, `g × 2g`.
    fn cycle_periods<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<C>> {
        matrix_to_array(&self.curve.cycle_periods()).into_pyarray(py)
    }

    /// Tree edges of the cycles `c_j` as `(2g, 2)` indices.
    fn cycle_edges<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<i64>>> {
        let e = self.curve.cycle_edges();
        let flat: Vec<i64> = e.iter().flat_map(|&(p, q)| [p as i64, q as i64]).collect();
        Ok(Array2::from_shape_vec((e.len(), 2), flat)
            .map_err(out_shape_err)?
            .into_pyarray(py))
    }

    fn intersection_matrix<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<i64>>> {
        let m = self.curve.intersection_matrix();
        let flat: Vec<i64> = m.iter().flatten().copied().collect();
        Ok(Array2::from_shape_vec((m.len(), m.len()), flat)
            .map_err(out_shape_err)?
            .into_pyarray(py))
    }

    fn symplectic_basis<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<i64>>> {
        let m = self.curve.symplectic_basis();
        let flat: Vec<i64> = m.iter().flatten().copied().collect();
        Ok(Array2::from_shape_vec((m.len(), m.len()), flat)
            .map_err(out_shape_err)?
            .into_pyarray(py))
    }

    /// `y(x, sheet)` at each `x`.
    fn y<'py>(
        &self,
        py: Python<'py>,
        x: PyReadonlyArray1<'py, C>,
        sheet: i8,
    ) -> PyResult<Bound<'py, PyArray1<C>>> {
        check_call("x", x.as_array().len(), 2 * 16)?;
        let xs = vec1(&x, "x", None)?;
        let cancel = py_cancel();
        let out = py.detach(|| self.curve.y_many(&xs, sheet, &cancel))?;
        Ok(Array1::from(out).into_pyarray(py))
    }

    /// Abel map of `N` points, `(N, g)`; `route` (tests): `None` the best route,
    /// `-1` the ray from infinity, `k ≥ 0` the segment from branch point `k`.
    #[pyo3(signature = (x, y, route=None))]
    fn abel<'py>(
        &self,
        py: Python<'py>,
        x: PyReadonlyArray1<'py, C>,
        y: PyReadonlyArray1<'py, C>,
        route: Option<i64>,
    ) -> PyResult<Bound<'py, PyArray2<C>>> {
        let g = self.curve.genus();
        check_call("x", x.as_array().len(), (2 + g) * 16)?;
        let xs = vec1(&x, "x", None)?;
        let ys = vec1(&y, "y", Some(xs.len()))?;
        let n = xs.len();
        let route = match route {
            None => AbelRoute::Best,
            Some(r) if r < 0 => AbelRoute::Infinity,
            Some(k) => AbelRoute::Branch(k as usize),
        };
        let cancel = py_cancel();
        let out = py.detach(|| self.curve.abel_many(&xs, &ys, route, &cancel))?;
        Ok(Array2::from_shape_vec((n, g), out)
            .map_err(out_shape_err)?
            .into_pyarray(py))
    }

    /// Abel map of `N` points `(e_k + dx, y)` near the branch point `e_k`,
    /// given their offsets `dx` (full relative accuracy), `(N, g)`.
    fn abel_near_branch<'py>(
        &self,
        py: Python<'py>,
        k: usize,
        dx: PyReadonlyArray1<'py, C>,
        y: PyReadonlyArray1<'py, C>,
    ) -> PyResult<Bound<'py, PyArray2<C>>> {
        let g = self.curve.genus();
        check_call("dx", dx.as_array().len(), (2 + g) * 16)?;
        let dxs = vec1(&dx, "dx", None)?;
        let ys = vec1(&y, "y", Some(dxs.len()))?;
        let n = dxs.len();
        let cancel = py_cancel();
        let out = py.detach(|| self.curve.abel_near_branch_many(k, &dxs, &ys, &cancel))?;
        Ok(Array2::from_shape_vec((n, g), out)
            .map_err(out_shape_err)?
            .into_pyarray(py))
    }

    /// `u(e_k)` for every finite branch point (unreduced, tree paths), `(n, g)`.
    fn abel_branch_points<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<C>>> {
        let (n, g) = (self.curve.branch_points().len(), self.curve.genus());
        let mut flat = Vec::with_capacity(n * g);
        for k in 0..n {
            flat.extend(self.curve.abel_branch_point(k)?);
        }
        Ok(Array2::from_shape_vec((n, g), flat)
            .map_err(out_shape_err)?
            .into_pyarray(py))
    }

    /// Characteristics `[a | b]` of `η(e_k)`, `k = 0..n` (row `n` is `∞` for odd `n`).
    fn branch_chars<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<u8>>> {
        let n = self.curve.branch_points().len();
        let g = self.curve.genus();
        let rows = if n % 2 == 1 { n + 1 } else { n };
        let mut flat = Vec::with_capacity(rows * 2 * g);
        for k in 0..rows {
            let (a, b) = self.curve.branch_char(k)?;
            flat.extend(a);
            flat.extend(b);
        }
        Ok(Array2::from_shape_vec((rows, 2 * g), flat)
            .map_err(out_shape_err)?
            .into_pyarray(py))
    }

    fn riemann_constant<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<C>>> {
        let k = py.detach(|| self.curve.riemann_constant().map(|k| k.to_vec()))?;
        Ok(Array1::from(k).into_pyarray(py))
    }

    fn riemann_constant_char<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<u8>>> {
        let (a, b) = py.detach(|| self.curve.riemann_constant_char())?;
        Ok(Array1::from([a, b].concat()).into_pyarray(py))
    }

    /// `z (N, g)` reduced modulo the lattice.
    fn reduce<'py>(
        &self,
        py: Python<'py>,
        z: PyReadonlyArray2<'py, C>,
    ) -> PyResult<Bound<'py, PyArray2<C>>> {
        let g = self.curve.genus();
        let v = z.as_array();
        if v.ncols() != g {
            return Err(shape_err("z", format!("(N, {g})"), v.shape()));
        }
        check_call("z", v.nrows(), 2 * g * 16)?;
        let flat: Vec<C> = try_collect("z", v.len(), v.iter().copied())?;
        let cancel = py_cancel();
        let out = py.detach(|| self.curve.reduce_many(&flat, &cancel))?;
        Ok(Array2::from_shape_vec((v.nrows(), g), out)
            .map_err(out_shape_err)?
            .into_pyarray(py))
    }

    /// Jacobi inversion of `u (N, 2)`: `(x (N, 2), y (N, 2))`.
    #[allow(clippy::type_complexity)]
    fn invert<'py>(
        &self,
        py: Python<'py>,
        u: PyReadonlyArray2<'py, C>,
    ) -> PyResult<(Bound<'py, PyArray2<C>>, Bound<'py, PyArray2<C>>)> {
        let v = u.as_array();
        let g = self.curve.genus();
        if v.ncols() != g {
            return Err(shape_err("u", format!("(N, {g})"), v.shape()));
        }
        check_call("u", v.nrows(), (g + 4) * 16)?;
        let flat: Vec<C> = try_collect("u", v.len(), v.iter().copied())?;
        let n = v.nrows();
        let cancel = py_cancel();
        let (xs, ys) = py.detach(|| self.curve.invert_many(&flat, &cancel))?;
        Ok((
            Array2::from_shape_vec((n, 2), xs)
                .map_err(out_shape_err)?
                .into_pyarray(py),
            Array2::from_shape_vec((n, 2), ys)
                .map_err(out_shape_err)?
                .into_pyarray(py),
        ))
    }
}

/// Adds this module's class to `manakov._core`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<HyperellipticCore>()?;
    Ok(())
}
