//! Bindings for `crate::so4`.

use pyo3::prelude::*;

/// Adds this module's functions to `manakov._core`.
pub fn register(_m: &Bound<'_, PyModule>) -> PyResult<()> {
    Ok(())
}
