//! Bindings for `crate::so4`.

use numpy::ndarray::Array2;
use numpy::PyReadonlyArray2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3, PyArrayMethods, PyReadonlyArray1};
use pyo3::prelude::*;

use super::arrays::{array1, map_rows, out_shape_err, vec1, vec2};
use crate::error::Error;
use crate::so4::{self, FrahmTop};

/// The top of a symmetric `c` `(n, n)`; `n` is checked against `so4::MAX_N`
/// before `c` is copied.
pub(super) fn top_from_c(c: &PyReadonlyArray2<'_, f64>) -> PyResult<FrahmTop> {
    let (r, k) = c.as_array().dim();
    if r != k {
        return Err(Error::Shape {
            what: "c",
            expected: "(n, n)".into(),
            got: format!("({r}, {k})"),
        }
        .into());
    }
    so4::check_n("c", r)?;
    let (cv, _, _) = vec2(c, "c")?;
    Ok(FrahmTop::new(r, &cv)?)
}

pub(super) fn check_states(what: &'static str, cols: usize, m: usize) -> Result<(), Error> {
    if cols != m {
        return Err(Error::Shape {
            what,
            expected: format!("(..., {m})"),
            got: format!("(..., {cols})"),
        });
    }
    Ok(())
}

/// Nanoseconds of (1) at one state of so(n), about (for the cancellation
/// checks of a batch; so(4) has its own fast path).
fn field_cost_ns(n: usize) -> f64 {
    if n == 4 {
        5.0
    } else {
        (n * n * n) as f64
    }
}

/// Manakov's c_ij (2) from a, b.
#[pyfunction(name = "manakov_c")]
fn manakov_c_py<'py>(
    py: Python<'py>,
    a: PyReadonlyArray1<'py, f64>,
    b: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    so4::check_n("a", a.as_array().len())?;
    let (a, b) = (vec1(&a, "a", None)?, vec1(&b, "b", None)?);
    let n = a.len();
    let c = py.detach(|| so4::manakov_c(&a, &b))?;
    Ok(Array2::from_shape_vec((n, n), c)
        .map_err(out_shape_err)?
        .into_pyarray(py))
}

/// Validates a Frahm coefficient matrix c (raises ValueError).
#[pyfunction(name = "check_c")]
fn check_c_py(c: PyReadonlyArray2<'_, f64>) -> PyResult<()> {
    top_from_c(&c)?;
    Ok(())
}

/// The vector field (1) at each row of l (N, n(n-1)/2).
#[pyfunction(name = "vector_field")]
fn vector_field_py<'py>(
    py: Python<'py>,
    c: PyReadonlyArray2<'py, f64>,
    l: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let top = top_from_c(&c)?;
    let m = top.dim();
    check_states("l", l.as_array().ncols(), m)?;
    map_rows(py, &l, "l", m, field_cost_ns(top.n()), |x, o| {
        top.vector_field(x, o);
        Ok(())
    })
}

/// The Hamiltonian (4) at each row of l.
#[pyfunction(name = "hamiltonian")]
fn hamiltonian_py<'py>(
    py: Python<'py>,
    c: PyReadonlyArray2<'py, f64>,
    l: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let top = top_from_c(&c)?;
    let (rows, cols) = l.as_array().dim();
    check_states("l", cols, top.dim())?;
    let out = map_rows(py, &l, "l", 1, top.dim() as f64, |x, o| {
        o[0] = top.hamiltonian(x);
        Ok(())
    })?;
    out.reshape([rows])
}

/// The so(4) integrals [H0, H1, H2, H3] (6)-(7), corrected, at each row of l (N, 6).
#[pyfunction(name = "so4_integrals")]
fn so4_integrals_py<'py>(
    py: Python<'py>,
    a: PyReadonlyArray1<'py, f64>,
    l: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let a4: [f64; 4] = array1(&a, "a")?;
    check_states("l", l.as_array().ncols(), 6)?;
    map_rows(py, &l, "l", 4, 30.0, |x, o| {
        let x: &[f64; 6] = x.try_into().map_err(|_| Error::Shape {
            what: "l",
            expected: "(..., 6)".into(),
            got: format!("(..., {})", x.len()),
        })?;
        o.copy_from_slice(&so4::integrals4(&a4, x));
        Ok(())
    })
}

/// Labels (k, j) of Manakov's integrals on so(n).
#[pyfunction(name = "manakov_integral_labels")]
fn manakov_integral_labels_py(n: usize) -> PyResult<Vec<(usize, usize)>> {
    so4::check_n("n", n)?;
    Ok(so4::manakov_integral_labels(n))
}

/// Manakov's integrals (coefficients of tr (l + λA)^k) at each row of l.
#[pyfunction(name = "manakov_integrals")]
fn manakov_integrals_py<'py>(
    py: Python<'py>,
    a: PyReadonlyArray1<'py, f64>,
    l: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    so4::check_n("a", a.as_array().len())?;
    let a = vec1(&a, "a", None)?;
    let n = a.len();
    check_states("l", l.as_array().ncols(), so4::state_dim(n))?;
    let k = so4::manakov_integral_labels(n).len();
    // n powers of an n x n matrix, each n^3: n^5 a state.
    let cost = (n as f64).powi(5);
    map_rows(py, &l, "l", k, cost, |x, o| {
        o.copy_from_slice(&so4::manakov_integrals(&a, x));
        Ok(())
    })
}

/// The Poisson tensor (3) at each row of l, shape (N, m, m).
#[pyfunction(name = "poisson_tensor")]
fn poisson_tensor_py<'py>(
    py: Python<'py>,
    l: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let (rows, cols) = l.as_array().dim();
    let n = so4::n_from_state_dim(cols)
        .filter(|&n| n >= 2)
        .ok_or_else(|| Error::Shape {
            what: "l",
            expected: "(..., n(n-1)/2)".into(),
            got: format!("(..., {cols})"),
        })?;
    so4::check_n("l", n)?;
    let out = map_rows(py, &l, "l", cols * cols, (cols * cols) as f64, |x, o| {
        so4::poisson_tensor(n, x, o);
        Ok(())
    })?;
    out.reshape([rows, cols, cols])
}

/// Adds this module's functions to `manakov._core`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(manakov_c_py, m)?)?;
    m.add_function(wrap_pyfunction!(check_c_py, m)?)?;
    m.add_function(wrap_pyfunction!(vector_field_py, m)?)?;
    m.add_function(wrap_pyfunction!(hamiltonian_py, m)?)?;
    m.add_function(wrap_pyfunction!(so4_integrals_py, m)?)?;
    m.add_function(wrap_pyfunction!(manakov_integral_labels_py, m)?)?;
    m.add_function(wrap_pyfunction!(manakov_integrals_py, m)?)?;
    m.add_function(wrap_pyfunction!(poisson_tensor_py, m)?)?;
    Ok(())
}
