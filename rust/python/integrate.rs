//! Bindings for `crate::integrate`.

use numpy::ndarray::{Array2, Array3};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

use super::arrays::{check_call, out_shape_err, vec1, vec2};
use super::errors::{callback_or, py_cancel_progress};
use super::so4::{check_states, top_from_c};
use crate::error::Error;
use crate::integrate::{self, Method, Options, VectorField};

/// The result of `integrate`: `(y (S', m), steps, evals, error)`.
pub(super) type IntegrateOut<'py> = (
    Bound<'py, PyArray2<f64>>,
    u64,
    u64,
    Option<Bound<'py, PyAny>>,
);

/// Runs `integrate::integrate_partial` for any field with the GIL released and
/// converts the result: the samples reached as `(S', m)`, the counts, and the
/// error of a run that failed or was interrupted after it started (returned,
/// not raised). A refused call (nothing computed) raises. `progress(samples
/// written)` is called at each poll (every `numeric::cancel::POLL_INTERVAL`); its
/// exception stops the run and becomes the returned error.
pub(super) fn run_partial<'py, F: VectorField>(
    py: Python<'py>,
    f: &F,
    y0: &[f64],
    t0: f64,
    times: &[f64],
    opts: &Options,
    progress: Option<Py<PyAny>>,
) -> PyResult<IntegrateOut<'py>> {
    let (cancel, slot) = py_cancel_progress(progress);
    let (tr, res) = py.detach(|| integrate::integrate_partial(f, y0, t0, times, opts, &cancel))?;
    let y = Array2::from_shape_vec((tr.t.len(), f.dim()), tr.y)
        .map_err(out_shape_err)?
        .into_pyarray(py);
    let err = res.err().map(|e| {
        callback_or(&slot, e)
            .into_value(py)
            .into_any()
            .into_bound(py)
    });
    Ok((y, tr.steps, tr.evals, err))
}

/// Runs `integrate::integrate_many_with` for any field on `rows` initial states
/// (`y0s` row-major, `(rows, m)`) with the GIL released: `(y (rows, S, m), steps)`.
/// `progress(samples written, over all trajectories)` as in [`run_partial`].
#[allow(clippy::too_many_arguments)]
pub(super) fn run_many<'py, F: VectorField>(
    py: Python<'py>,
    f: &F,
    y0s: &[f64],
    rows: usize,
    t0: f64,
    times: &[f64],
    opts: &Options,
    parallel: bool,
    progress: Option<Py<PyAny>>,
) -> PyResult<(Bound<'py, PyArray3<f64>>, u64)> {
    let (cancel, slot) = py_cancel_progress(progress);
    let (ys, steps) = py
        .detach(|| integrate::integrate_many_with(f, y0s, t0, times, opts, parallel, &cancel))
        .map_err(|e| callback_or(&slot, e))?;
    let y = Array3::from_shape_vec((rows, times.len(), f.dim()), ys)
        .map_err(out_shape_err)?
        .into_pyarray(py);
    Ok((y, steps))
}

/// Checks before any copy that `samples` sample times and the states of
/// `rows` trajectories of `m` entries at them fit the allocation budget.
pub(super) fn check_samples(samples: usize, rows: usize, m: usize) -> PyResult<()> {
    let each = rows.max(1).saturating_mul(m).saturating_add(1);
    check_call(
        "samples",
        samples,
        each.saturating_mul(std::mem::size_of::<f64>()),
    )
}

/// Integrates (1) from l0 at t0, sampling at `times`; returns `(l (S', m), steps,
/// evals, error)`: on a failure or Ctrl-C after the run started, `error` is the
/// exception to raise (not raised here) and `l` holds the `S' < S` samples reached.
/// Interruptible: Python's signal handlers run every `numeric::cancel::POLL_INTERVAL`,
/// and with them `progress(samples written)` when given.
#[pyfunction(name = "integrate")]
#[pyo3(signature = (c, l0, t0, times, method, dt, rtol, atol, max_steps, progress=None))]
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
    progress: Option<Py<PyAny>>,
) -> PyResult<IntegrateOut<'py>> {
    let top = top_from_c(&c)?;
    // The sample times and the states at them, before anything is copied.
    check_samples(times.as_array().len(), 1, top.dim())?;
    let (l0, times) = (vec1(&l0, "l0", None)?, vec1(&times, "times", None)?);
    let opts = Options::parse(method, dt, rtol, atol, max_steps)?;
    run_partial(py, &top, &l0, t0, &times, &opts, progress)
}

/// Integrates a batch (B, m) of initial states; returns (l (B, S, m), steps).
/// `progress(samples written, over all trajectories)` as in `integrate`.
#[pyfunction(name = "integrate_many")]
#[pyo3(signature = (c, l0s, t0, times, method, dt, rtol, atol, max_steps, parallel, progress=None))]
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
    progress: Option<Py<PyAny>>,
) -> PyResult<(Bound<'py, PyArray3<f64>>, u64)> {
    let top = top_from_c(&c)?;
    let (rows, cols) = l0s.as_array().dim();
    check_states("l0s", cols, top.dim())?;
    check_samples(times.as_array().len(), rows, cols)?;
    let (l0s, _, _) = vec2(&l0s, "l0s")?;
    let times = vec1(&times, "times", None)?;
    let opts = Options::parse(method, dt, rtol, atol, max_steps)?;
    run_many(py, &top, &l0s, rows, t0, &times, &opts, parallel, progress)
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
    check_samples(times.as_array().len(), 0, 0)?;
    let times = vec1(&times, "times", None)?;
    integrate::check_sample_times(t0, &times)?;
    integrate::check_budget(Method::from_name(method)?, t0, &times, dt, max_steps)?;
    Ok(())
}

/// The number of steps a Gauss method takes from t0 through `times` at steps of at
/// most `dt` (see `integrate::gauss_steps`).
#[pyfunction(name = "gauss_steps")]
fn gauss_steps_py(t0: f64, times: PyReadonlyArray1<'_, f64>, dt: f64) -> PyResult<u64> {
    check_samples(times.as_array().len(), 0, 0)?;
    let times = vec1(&times, "times", None)?;
    integrate::check_sample_times(t0, &times)?;
    if !(dt > 0.0 && dt.is_finite()) {
        return Err(Error::InvalidArgument {
            what: "dt",
            reason: format!("must be finite and > 0, got {dt}"),
        }
        .into());
    }
    Ok(integrate::gauss_steps(t0, &times, dt) as u64)
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
    m.add_function(wrap_pyfunction!(integrate_py, m)?)?;
    m.add_function(wrap_pyfunction!(integrate_many_py, m)?)?;
    m.add_function(wrap_pyfunction!(gauss_tableau_py, m)?)?;
    m.add_function(wrap_pyfunction!(check_budget_py, m)?)?;
    m.add_function(wrap_pyfunction!(gauss_steps_py, m)?)?;
    Ok(())
}
