//! Bindings for `crate::so4` and `crate::integrate`.

use numpy::ndarray::{Array2, Array3};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

use super::arrays::{array1, out_shape_err, rows, stack, vec1};
use super::errors::py_cancel;
use crate::error::Error;
use crate::integrate::{self, Method, Options};
use crate::so4::{self, FrahmTop};

/// Copies a read-only 2-d array (any strides) into a row-major Vec with its shape.
fn vec2(x: &PyReadonlyArray2<'_, f64>) -> (Vec<f64>, usize, usize) {
    let v = x.as_array();
    let (r, c) = v.dim();
    (v.iter().copied().collect(), r, c)
}

fn top_from_c(c: &PyReadonlyArray2<'_, f64>) -> Result<FrahmTop, Error> {
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

fn check_states(what: &'static str, cols: usize, m: usize) -> Result<(), Error> {
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

fn options(method: &str, dt: f64, rtol: f64, atol: f64, max_steps: u64) -> Result<Options, Error> {
    let o = Options {
        method: Method::from_name(method)?,
        dt,
        rtol,
        atol,
        max_steps,
    };
    o.validate()?;
    Ok(o)
}

/// The result of `integrate`: `(l (S', m), steps, evals, error)`.
type IntegrateOut<'py> = (
    Bound<'py, PyArray2<f64>>,
    u64,
    u64,
    Option<Bound<'py, PyAny>>,
);

/// Integrates (1) from l0 at t0, sampling at `times`; returns `(l (S', m), steps,
/// evals, error)`: on a failure or Ctrl-C after the run started, `error` is the
/// exception to raise (not raised here) and `l` holds the `S' < S` samples reached.
/// Interruptible: Python's signal handlers run every `cancel::POLL_INTERVAL`.
#[pyfunction(name = "integrate")]
#[pyo3(signature = (c, l0, t0, times, method, dt, rtol, atol, max_steps))]
#[allow(clippy::too_many_arguments)]
fn integrate_py<'py>(
    py: Python<'py>,
    c: PyReadonlyArray2<'py, f64>,
    l0: PyReadonlyArray1<'py, f64>,
    t0: f64,
    times: PyReadonlyArray1<'py, f64>,
    method: &str,
    dt: f64,
    rtol: f64,
    atol: f64,
    max_steps: u64,
) -> PyResult<IntegrateOut<'py>> {
    let top = top_from_c(&c)?;
    let (l0, times) = (vec1(&l0, "l0", None)?, vec1(&times, "times", None)?);
    let opts = options(method, dt, rtol, atol, max_steps)?;
    let cancel = py_cancel();
    let (tr, res) =
        py.detach(|| integrate::integrate_partial(&top, &l0, t0, &times, &opts, &cancel))?;
    let m = top.dim();
    let y = Array2::from_shape_vec((tr.t.len(), m), tr.y)
        .map_err(out_shape_err)?
        .into_pyarray(py);
    let err = res
        .err()
        .map(|e| PyErr::from(e).into_value(py).into_any().into_bound(py));
    Ok((y, tr.steps, tr.evals, err))
}

/// Integrates a batch (B, m) of initial states; returns (l (B, S, m), steps).
#[pyfunction(name = "integrate_many")]
#[pyo3(signature = (c, l0s, t0, times, method, dt, rtol, atol, max_steps, parallel))]
#[allow(clippy::too_many_arguments)]
fn integrate_many_py<'py>(
    py: Python<'py>,
    c: PyReadonlyArray2<'py, f64>,
    l0s: PyReadonlyArray2<'py, f64>,
    t0: f64,
    times: PyReadonlyArray1<'py, f64>,
    method: &str,
    dt: f64,
    rtol: f64,
    atol: f64,
    max_steps: u64,
    parallel: bool,
) -> PyResult<(Bound<'py, PyArray3<f64>>, u64)> {
    let top = top_from_c(&c)?;
    let (l0s, rows, cols) = vec2(&l0s);
    check_states("l0s", cols, top.dim())?;
    let times = vec1(&times, "times", None)?;
    let opts = options(method, dt, rtol, atol, max_steps)?;
    let cancel = py_cancel();
    let (ys, steps) = py.detach(|| {
        integrate::integrate_many_with(&top, &l0s, t0, &times, &opts, parallel, &cancel)
    })?;
    let y = Array3::from_shape_vec((rows, times.len(), cols), ys)
        .map_err(out_shape_err)?
        .into_pyarray(py);
    Ok((y, steps))
}

/// Refuses, before any work, a run that needs more than `max_steps` steps (ValueError
/// naming the cause: the sample spacing or dt); see `integrate::check_budget`.
#[pyfunction(name = "check_budget")]
fn check_budget_py(
    method: &str,
    t0: f64,
    times: PyReadonlyArray1<'_, f64>,
    dt: f64,
    max_steps: u64,
) -> PyResult<()> {
    let times = vec1(&times, "times", None)?;
    integrate::check_sample_times(t0, &times)?;
    integrate::check_budget(Method::from_name(method)?, t0, &times, dt, max_steps)?;
    Ok(())
}

/// `(c, b, mu)` as numpy arrays.
type Tableau<'py> = (
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray2<f64>>,
);

/// The Gauss tableau (c, b, mu) of a Gauss method, mu_ij = a_ij / b_j.
#[pyfunction(name = "gauss_tableau")]
fn gauss_tableau_py<'py>(py: Python<'py>, method: &str) -> PyResult<Tableau<'py>> {
    let m = Method::from_name(method)?;
    let (c, b, mu) = m.gauss_tableau().ok_or_else(|| Error::InvalidArgument {
        what: "method",
        reason: format!("{method:?} is not a Gauss method"),
    })?;
    let s = b.len();
    let mu = Array2::from_shape_vec((s, s), mu)
        .map_err(out_shape_err)?
        .into_pyarray(py);
    Ok((c.to_vec().into_pyarray(py), b.to_vec().into_pyarray(py), mu))
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
    m.add_function(wrap_pyfunction!(integrate_py, m)?)?;
    m.add_function(wrap_pyfunction!(integrate_many_py, m)?)?;
    m.add_function(wrap_pyfunction!(gauss_tableau_py, m)?)?;
    m.add_function(wrap_pyfunction!(check_budget_py, m)?)?;
    Ok(())
}
