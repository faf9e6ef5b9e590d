//! The one map from the core's `Error` to Python exceptions.

use std::sync::{Arc, Mutex};

use pyo3::create_exception;
use pyo3::exceptions::{PyKeyboardInterrupt, PyMemoryError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::PyErr;

use crate::error::Error;

create_exception!(
    manakov,
    ConvergenceError,
    PyRuntimeError,
    "An iterative computation did not reach its tolerance."
);

create_exception!(
    manakov,
    ClosedFormError,
    PyRuntimeError,
    "A valid state whose closed-form solution could not be built to the package's \
     accuracy, or failed its own check; the message names the step. Integrate it instead."
);

impl From<Error> for PyErr {
    fn from(e: Error) -> PyErr {
        exception(&e, e.to_string())
    }
}

/// The exception of `e` with the message `msg`.
fn exception(e: &Error, msg: String) -> PyErr {
    // Exhaustive on purpose: a new variant must choose its exception here.
    match e {
        Error::NoConvergence { .. } => ConvergenceError::new_err(msg),
        Error::Unverified { .. } => ClosedFormError::new_err(msg),
        Error::Interrupted => PyKeyboardInterrupt::new_err(msg),
        // A size over the budget, or one the machine cannot hold: numpy's
        // exception for an array it cannot allocate.
        Error::OutOfMemory { .. } | Error::TooLarge { .. } => PyMemoryError::new_err(msg),
        // A batch row's error: its own exception, the message naming the row.
        Error::InRow { source, .. } => exception(source, msg),
        Error::Shape { .. }
        | Error::NonFinite { .. }
        | Error::RepeatedA { .. }
        | Error::NotSymmetric { .. }
        | Error::ImagNotPositiveDefinite { .. }
        | Error::RepeatedBranchPoints { .. }
        | Error::Singular { .. }
        | Error::InvalidArgument { .. }
        | Error::NoRealTorus { .. } => PyValueError::new_err(msg),
    }
}

/// A cancellation token for a call that runs with the GIL released: it runs
/// Python's signal handlers (so Ctrl-C is seen) from the calling thread, at
/// most every `numeric::cancel::POLL_INTERVAL`.
pub fn py_cancel() -> crate::numeric::cancel::Cancel {
    crate::numeric::cancel::Cancel::with_poll(|| {
        pyo3::Python::attach(|py| py.check_signals().is_err())
    })
}

/// The exception raised by a progress callback, kept until the call returns.
pub type CallbackError = Arc<Mutex<Option<PyErr>>>;

/// [`py_cancel`] that also calls `progress(done)` at each poll, `done` the work
/// counted by the core (`Cancel::advance`: samples written, for the
/// integrators). An exception raised by `progress` stops the call like Ctrl-C
/// and is kept in the returned slot; [`callback_or`] raises it in place of the
/// interruption.
pub fn py_cancel_progress(
    progress: Option<Py<PyAny>>,
) -> (crate::numeric::cancel::Cancel, CallbackError) {
    let slot: CallbackError = Arc::new(Mutex::new(None));
    let kept = slot.clone();
    let cancel = crate::numeric::cancel::Cancel::with_progress_poll(move |done| {
        Python::attach(|py| {
            if py.check_signals().is_err() {
                return true;
            }
            match progress.as_ref().map(|f| f.call1(py, (done,))) {
                Some(Err(e)) => {
                    if let Ok(mut s) = kept.lock() {
                        *s = Some(e);
                    }
                    true
                }
                _ => false,
            }
        })
    });
    (cancel, slot)
}

/// The exception of a progress callback that stopped the call, if any, else `e`.
pub fn callback_or(slot: &CallbackError, e: Error) -> PyErr {
    match slot.lock().ok().and_then(|mut s| s.take()) {
        Some(err) if e == Error::Interrupted => err,
        _ => PyErr::from(e),
    }
}
