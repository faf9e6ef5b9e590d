//! Bindings for `crate::tori`.

use numpy::ndarray::Array1;
use numpy::{Complex64, IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

use super::arrays::{array1, rows, stack};
use crate::error::Error;
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
    if let Some(bad) = chars.iter().flatten().find(|&&v| v > 1) {
        return Err(Error::InvalidArgument {
            what: "characteristics",
            reason: format!("entries must be 0 or 1, got {bad}"),
        }
        .into());
    }
    let torus = py
        .detach(|| tori::real_torus(&tau, &u, &u2, &chars))
        .map_err(Error::from)?;
    Ok((
        stack(torus.lambda)?.into_pyarray(py),
        stack(torus.coords)?.into_pyarray(py),
        Array1::from(torus.nu.to_vec()).into_pyarray(py),
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
    Ok(())
}
