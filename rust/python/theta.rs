//! Bindings for `crate::theta`.

use num_complex::Complex64;
use numpy::ndarray::{Array3, Array4};
use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyArray3, PyArray4, PyArrayMethods, PyReadonlyArray2,
};
use pyo3::exceptions::PyMemoryError;
use pyo3::prelude::*;

use super::errors::py_cancel;

use crate::error::Error;
use crate::theta::{ThetaPlan, MAX_GENUS};

type Jet<'py> = (
    Bound<'py, PyArray2<Complex64>>,
    Bound<'py, PyArray3<Complex64>>,
    Bound<'py, PyArray4<Complex64>>,
    Bound<'py, PyArray1<f64>>,
    bool,
);

fn read_tau(tau: &PyReadonlyArray2<'_, Complex64>) -> Result<(Vec<Complex64>, usize), Error> {
    let t = tau.as_array();
    let (r, c) = t.dim();
    if r != c {
        return Err(Error::Shape {
            what: "tau",
            expected: "(g, g)".into(),
            got: format!("({r}, {c})"),
        });
    }
    // Checked here, before 4^g = 1 << 2g sizes the output arrays (the shift overflows
    // for g >= 32); ThetaPlan::new checks it again for Rust callers.
    if r == 0 || r > MAX_GENUS {
        return Err(Error::InvalidArgument {
            what: "genus",
            reason: format!("g must be in 1..={MAX_GENUS}, got {r} (tau of shape ({r}, {c}))"),
        });
    }
    Ok((t.iter().copied().collect(), r))
}

/// `len` complex zeros, or MemoryError if they cannot be allocated (a plain
/// `vec!` would abort the process).
fn try_zeros(len: usize) -> PyResult<Vec<Complex64>> {
    let mut v = Vec::new();
    v.try_reserve_exact(len).map_err(|e| {
        PyMemoryError::new_err(format!("cannot allocate {len} complex numbers: {e}"))
    })?;
    v.resize(len, Complex64::new(0.0, 0.0));
    Ok(v)
}

/// All 4^g theta values θ[a;b](z, τ) = Σ_n exp(iπ mᵀτm + 2πi mᵀ(z + b/2)),
/// m = n + a/2 (the paper's (36) with the characteristics of (35)), FLINT order,
/// and their z-derivatives up to `order` at
/// `n` points `z` (shape (n, g)): returns (values (n, 4^g), gradient
/// (n, 4^g, g or 0), hessian (n, 4^g, g, g or 0), log_scale (n,), finite),
/// normalised so that θ = exp(log_scale) · values; with `scaled` the arrays hold
/// θ itself and `finite` is false if some value overflowed. With `parallel`
/// large batches are split over rayon's thread pool.
#[pyfunction(name = "theta_jet")]
#[pyo3(signature = (z, tau, tol, order, scaled, parallel))]
fn theta_jet_py<'py>(
    py: Python<'py>,
    z: PyReadonlyArray2<'py, Complex64>,
    tau: PyReadonlyArray2<'py, Complex64>,
    tol: f64,
    order: usize,
    scaled: bool,
    parallel: bool,
) -> PyResult<Jet<'py>> {
    let (tau_v, g) = read_tau(&tau)?;
    let zv = z.as_array();
    let (npts, gz) = zv.dim();
    if gz != g {
        return Err(Error::Shape {
            what: "z",
            expected: format!("(..., {g})"),
            got: format!("(..., {gz})"),
        }
        .into());
    }
    // Invalid tau or tol is reported before a large batch is allocated.
    let plan = ThetaPlan::new(&tau_v, g, tol, order)?.with_parallel(parallel);
    let n = 1usize << (2 * g);
    let (gd, hd) = plan.batch_widths(npts)?;
    // The values and L are written straight into numpy-allocated arrays: numpy
    // asks for huge pages for large arrays, which saves most of the page faults
    // of first touching a fresh 256-bytes-per-point output (measured: a one-core
    // 10^5-point call went from 0.160 to 0.147 µs/point). They are made by
    // numpy.zeros through Python, so that a failed allocation raises MemoryError
    // (PyArray::zeros panics on it).
    let np = py.import("numpy")?;
    let values_arr = np
        .call_method1("zeros", ((npts, n), "complex128"))?
        .cast_into::<PyArray2<Complex64>>()?;
    let logs_arr = np
        .call_method1("zeros", (npts, "float64"))?
        .cast_into::<PyArray1<f64>>()?;
    let mut gradient = try_zeros(npts * n * gd)?;
    let mut hessian = try_zeros(npts * n * gd * hd)?;
    let mut z_flat = try_zeros(npts * g)?;
    for (dst, src) in z_flat.iter_mut().zip(zv.iter()) {
        *dst = *src;
    }
    // SAFETY: both arrays were created just above, are contiguous and not yet
    // shared with Python or anything else, so these are the only references.
    let (values, logs) = unsafe { (values_arr.as_slice_mut()?, logs_arr.as_slice_mut()?) };
    let cancel = py_cancel();
    let out = py.detach(move || -> Result<_, Error> {
        let finite = plan.eval_batch_jet(
            &z_flat,
            values,
            &mut gradient,
            &mut hessian,
            logs,
            scaled,
            &cancel,
        )?;
        Ok((gradient, hessian, finite))
    })?;
    let (gradient, hessian, finite) = out;
    let shape_err = |e: numpy::ndarray::ShapeError| Error::Shape {
        what: "theta output",
        expected: "consistent sizes".into(),
        got: e.to_string(),
    };
    let gradient = Array3::from_shape_vec((npts, n, gd), gradient).map_err(shape_err)?;
    let hessian = Array4::from_shape_vec((npts, n, gd, hd), hessian).map_err(shape_err)?;
    Ok((
        values_arr,
        gradient.into_pyarray(py),
        hessian.into_pyarray(py),
        logs_arr,
        finite,
    ))
}

/// (radius, rho, error_bound, expected_terms, seconds_per_point) of the summation plan for `tau`
/// (the truncated lattice sum of (36), docs/theta.md).
#[pyfunction(name = "theta_plan_info")]
#[pyo3(signature = (tau, tol, order))]
fn theta_plan_info_py(
    tau: PyReadonlyArray2<'_, Complex64>,
    tol: f64,
    order: usize,
) -> PyResult<(f64, f64, f64, f64, f64)> {
    let (tau_v, g) = read_tau(&tau)?;
    let info = ThetaPlan::new(&tau_v, g, tol, order)?.info();
    Ok((
        info.radius,
        info.rho,
        info.error_bound,
        info.expected_terms,
        info.seconds_per_point,
    ))
}

/// Adds this module's functions to `manakov._core`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(theta_jet_py, m)?)?;
    m.add_function(wrap_pyfunction!(theta_plan_info_py, m)?)?;
    Ok(())
}
