//! Bindings for `crate::tori`.

use numpy::ndarray::Array1;
use numpy::{Complex64, IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

use super::arrays::{array1, check_call, rows, stack};
use super::errors::py_cancel;
use crate::numeric::alloc::try_collect;
use crate::tori::{self, Char};

type C = Complex64;

/// The reduced basis `(λ1, λ2)` (rows, complex), its integer coordinates
/// `(m1, m2, n1, n2)` (rows) and `(ν1, ν2)` of the real torus.
#[pyfunction(name = "real_torus")]
#[allow(clippy::type_complexity)]
fn real_torus_py<'py>(
    py: Python<'py>,
    tau: PyReadonlyArray2<'py, C>,
    u: PyReadonlyArray1<'py, C>,
    u2: PyReadonlyArray1<'py, C>,
    chars: PyReadonlyArray2<'py, u8>,
) -> PyResult<(
    Bound<'py, PyArray2<C>>,
    Bound<'py, PyArray2<i64>>,
    Bound<'py, PyArray1<f64>>,
)> {
    let t: Vec<[C; 2]> = rows(&tau, "tau", Some(2))?;
    let tau = [t[0], t[1]];
    let u: [C; 2] = array1(&u, "U")?;
    let u2: [C; 2] = array1(&u2, "U2")?;
    let chars: Vec<Char> = rows(&chars, "characteristics", None)?;
    let torus = py.detach(|| tori::real_torus_checked(&tau, &u, &u2, &chars))?;
    Ok((
        stack(torus.lambda)?.into_pyarray(py),
        stack(torus.coords)?.into_pyarray(py),
        Array1::from(torus.nu.to_vec()).into_pyarray(py),
    ))
}

/// `(ν1, ν2)` (rows) and the status code of each state of the top `(a, b)`:
/// the whole chain per state, in parallel, with the GIL released and Ctrl-C
/// checked between waves of states.
#[pyfunction(name = "frequency_map")]
#[allow(clippy::type_complexity)]
fn frequency_map_py<'py>(
    py: Python<'py>,
    a: PyReadonlyArray1<'py, f64>,
    b: PyReadonlyArray1<'py, f64>,
    states: PyReadonlyArray2<'py, f64>,
) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<u8>>)> {
    let a: [f64; 4] = array1(&a, "a")?;
    let b: [f64; 4] = array1(&b, "b")?;
    // The states, their results and the two output arrays.
    check_call("states", states.as_array().nrows(), 48 + 64 + 17)?;
    let ls: Vec<[f64; 6]> = rows(&states, "states", None)?;
    let cancel = py_cancel();
    let out = py.detach(|| tori::solve::frequency_map(&a, &b, &ls, &cancel))?;
    let nu = stack(out.iter().map(|e| e.nu))?;
    let status: Vec<u8> = try_collect("status", out.len(), out.iter().map(|e| e.status as u8))?;
    Ok((nu.into_pyarray(py), Array1::from(status).into_pyarray(py)))
}

/// The real torus of one state: `(λ rows, coords rows, ν, U')`; the
/// solution's errors as exceptions (ValueError naming the singular case).
#[pyfunction(name = "torus_of_state")]
#[allow(clippy::type_complexity)]
fn torus_of_state_py<'py>(
    py: Python<'py>,
    a: PyReadonlyArray1<'py, f64>,
    b: PyReadonlyArray1<'py, f64>,
    l0: PyReadonlyArray1<'py, f64>,
) -> PyResult<(
    Bound<'py, PyArray2<C>>,
    Bound<'py, PyArray2<i64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<C>>,
)> {
    let a: [f64; 4] = array1(&a, "a")?;
    let b: [f64; 4] = array1(&b, "b")?;
    let l0: [f64; 6] = array1(&l0, "l0")?;
    let (t, u2) = {
        let cancel = py_cancel();
        py.detach(|| tori::solve::torus_of_state(&a, &b, &l0, &cancel))
    }?;
    Ok((
        stack(t.lambda)?.into_pyarray(py),
        stack(t.coords)?.into_pyarray(py),
        Array1::from(t.nu.to_vec()).into_pyarray(py),
        Array1::from(u2.to_vec()).into_pyarray(py),
    ))
}

/// The names of the frequency-map status codes, indexed by code.
#[pyfunction(name = "tori_status_names")]
fn tori_status_names_py() -> Vec<&'static str> {
    tori::STATUS_NAMES.to_vec()
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(real_torus_py, m)?)?;
    m.add_function(wrap_pyfunction!(tori_status_names_py, m)?)?;
    m.add_function(wrap_pyfunction!(frequency_map_py, m)?)?;
    m.add_function(wrap_pyfunction!(torus_of_state_py, m)?)?;
    Ok(())
}
