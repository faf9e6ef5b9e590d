//! The one map from the core's `Error` to Python exceptions.

use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::PyErr;

use crate::error::Error;

create_exception!(
    manakov,
    ConvergenceError,
    PyRuntimeError,
    "An iterative computation did not reach its tolerance."
);

impl From<Error> for PyErr {
    fn from(e: Error) -> PyErr {
        let msg = e.to_string();
        // Exhaustive on purpose: a new variant must choose its exception here.
        match e {
            Error::NoConvergence { .. } => ConvergenceError::new_err(msg),
            Error::Shape { .. }
            | Error::NonFinite { .. }
            | Error::RepeatedA { .. }
            | Error::NotSymmetric { .. }
            | Error::ImagNotPositiveDefinite { .. }
            | Error::RepeatedBranchPoints { .. }
            | Error::InvalidArgument { .. } => PyValueError::new_err(msg),
        }
    }
}
