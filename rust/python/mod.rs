//! PyO3 bindings: the private extension module `manakov._core`.
//!
//! Bindings only. Each submodule mirrors one core module and exposes a
//! `register` function; every `#[pyfunction]` extracts read-only arrays,
//! checks shapes, runs the core with the GIL released and converts the result
//! and the error (see `errors.rs`). The public API is the Python package.

use pyo3::prelude::*;

mod arrays;
mod curve;
mod errors;
mod fluid;
mod integrate;
mod kotter;
mod motion;
mod riemann;
mod so4;
mod solution;
mod theta;
mod tori;

#[pymodule]
mod _core {
    use super::*;

    #[pymodule_export]
    use super::errors::ConvergenceError;

    #[pymodule_export]
    use super::errors::ClosedFormError;

    #[pymodule_init]
    fn init(m: &Bound<'_, PyModule>) -> PyResult<()> {
        m.add("__version__", env!("CARGO_PKG_VERSION"))?;
        so4::register(m)?;
        integrate::register(m)?;
        theta::register(m)?;
        kotter::register(m)?;
        curve::register(m)?;
        tori::register(m)?;
        riemann::register(m)?;
        solution::register(m)?;
        motion::register(m)?;
        fluid::register(m)?;
        Ok(())
    }
}
