//! Bindings for `crate::so4`.

use numpy::ndarray::{Array2, Array3};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

use super::arrays::{array1, out_shape_err, rows, stack, vec1};
use crate::error::Error;
use crate::so4::{self, FrahmTop};

/// Copies a read-only 2-d array (any strides) into a row-major Vec with its shape.
pub(super) fn vec2(x: &PyReadonlyArray2<'_, f64>) -> (Vec<f64>, usize, usize) {
    let v = x.as_array();
    let (r, c) = v.dim();
    (v.iter().copied().collect(), r, c)
}

pub(super) fn top_from_c(c: &PyReadonlyArray2<'_, f64>) -> Result<FrahmTop, Error> {
    let (cv, r, k) = vec2(c);
    if r != k {
        return Err(Error::Shape {
            what: "c",
            expected: "(n, n)".into(),
            got: format!("({r}, {k})"),
        });
    }
    FrahmTop::new(r, &cv)
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

/// Manakov's c_ij (2) from a, b.
#[pyfunction(name = "manakov_c")]
fn manakov_c_py<'py>(
    py: Python<'py>,
    a: PyReadonlyArray1<'py, f64>,
    b: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
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
    let (lv, rows, cols) = vec2(&l);
    check_states("l", cols, top.dim())?;
    let out = py.detach(|| {
        let mut out = vec![0.0; lv.len()];
        for (x, o) in lv.chunks(cols.max(1)).zip(out.chunks_mut(cols.max(1))) {
            top.vector_field(x, o);
        }
        out
    });
    Ok(Array2::from_shape_vec((rows, cols), out)
        .map_err(out_shape_err)?
        .into_pyarray(py))
}

/// The Hamiltonian (4) at each row of l.
#[pyfunction(name = "hamiltonian")]
fn hamiltonian_py<'py>(
    py: Python<'py>,
    c: PyReadonlyArray2<'py, f64>,
    l: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let top = top_from_c(&c)?;
    let (lv, _, cols) = vec2(&l);
    check_states("l", cols, top.dim())?;
    let out: Vec<f64> = py.detach(|| lv.chunks(cols.max(1)).map(|x| top.hamiltonian(x)).collect());
    Ok(out.into_pyarray(py))
}

/// The so(4) integrals [H0, H1, H2, H3] (6)-(7), corrected, at each row of l (N, 6).
#[pyfunction(name = "so4_integrals")]
fn so4_integrals_py<'py>(
    py: Python<'py>,
    a: PyReadonlyArray1<'py, f64>,
    l: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let a4: [f64; 4] = array1(&a, "a")?;
    let ls = rows::<f64, 6>(&l, "l", None)?;
    let out: Vec<[f64; 4]> = py.detach(|| ls.iter().map(|x| so4::integrals4(&a4, x)).collect());
    Ok(stack(out)?.into_pyarray(py))
}

/// Labels (k, j) of Manakov's integrals on so(n).
#[pyfunction(name = "manakov_integral_labels")]
fn manakov_integral_labels_py(n: usize) -> Vec<(usize, usize)> {
    so4::manakov_integral_labels(n)
}

/// Manakov's integrals (coefficients of tr (l + λA)^k) at each row of l.
#[pyfunction(name = "manakov_integrals")]
fn manakov_integrals_py<'py>(
    py: Python<'py>,
    a: PyReadonlyArray1<'py, f64>,
    l: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let a = vec1(&a, "a", None)?;
    let n = a.len();
    let (lv, rows, cols) = vec2(&l);
    check_states("l", cols, so4::state_dim(n))?;
    let k = so4::manakov_integral_labels(n).len();
    let out: Vec<f64> = py.detach(|| {
        lv.chunks(cols.max(1))
            .flat_map(|x| so4::manakov_integrals(&a, x))
            .collect()
    });
    Ok(Array2::from_shape_vec((rows, k), out)
        .map_err(out_shape_err)?
        .into_pyarray(py))
}

/// The Poisson tensor (3) at each row of l, shape (N, m, m).
#[pyfunction(name = "poisson_tensor")]
fn poisson_tensor_py<'py>(
    py: Python<'py>,
    l: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let (lv, rows, cols) = vec2(&l);
    let n = so4::n_from_state_dim(cols)
        .filter(|&n| n >= 2)
        .ok_or_else(|| Error::Shape {
            what: "l",
            expected: "(..., n(n-1)/2)".into(),
            got: format!("(..., {cols})"),
        })?;
    let out = py.detach(|| {
        let mut out = vec![0.0; rows * cols * cols];
        for (x, o) in lv.chunks(cols).zip(out.chunks_mut(cols * cols)) {
            so4::poisson_tensor(n, x, o);
        }
        out
    });
    Ok(Array3::from_shape_vec((rows, cols, cols), out)
        .map_err(out_shape_err)?
        .into_pyarray(py))
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
