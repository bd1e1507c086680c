//! The boundary: work runs with the GIL released and under `catch_unwind`; the library's
//! errors become the package's exceptions (defined in `polepatch/_errors.py`), a panic
//! becomes `polepatch.InternalError`.
//!
//! | Rust | Python | attributes |
//! |---|---|---|
//! | `Error::Parse`, `Error::Cl` | `InputError` | `path`, `line`, `column` |
//! | `Error::Unsupported` | `InputError` | `path`, `line` (`column` None) |
//! | `Error::Empty`, `NoRuns`, `NoRotary` (only where a call needs motion: `reorient`, `simulate`) | `InputError` | `path` |
//! | `Error::Point` | `InputError` | `index` (the array row) |
//! | `Error::Path` (joint arrays) | `InputError` | — |
//! | `Error::Options` | `ValueError` | — |
//! | `MachineError` | `MachineError` | — |
//! | a panic | `InternalError` | — |
//!
//! `path` is the name the caller gave (`name=`); None when it gave none.

use polepatch::Error;
use polepatch::kinematics::MachineError;
use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::panic::{AssertUnwindSafe, catch_unwind};

/// Why a call failed, before it is turned into a Python exception (which needs the GIL).
#[derive(Debug)]
pub(crate) enum Failure {
    /// An error of the library; `named`: the caller gave the input a name.
    Library { error: Error, named: bool },
    /// A machine that cannot be made.
    Machine(MachineError),
    /// An exception of `polepatch._errors` (`class`) with its message.
    Message {
        /// The class name.
        class: &'static str,
        /// The message.
        message: String,
    },
}

impl Failure {
    /// A library error for an input the caller named (`named`) or not.
    pub(crate) fn library(named: bool) -> impl Fn(Error) -> Failure {
        move |error| Failure::Library { error, named }
    }
}

/// Run `work` with the GIL released (other Python threads run meanwhile) and a panic
/// caught: a panic becomes `InternalError` with its message, never an abort.
pub(crate) fn detached<T: Send>(
    py: Python<'_>,
    work: impl FnOnce() -> Result<T, Failure> + Send,
) -> PyResult<T> {
    match py.detach(move || catch_unwind(AssertUnwindSafe(work))) {
        Ok(Ok(v)) => Ok(v),
        Ok(Err(failure)) => Err(to_python(py, failure)),
        Err(panic) => {
            let what = panic
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            Err(to_python(
                py,
                Failure::Message {
                    class: "InternalError",
                    message: format!("internal error in polepatch (please report): {what}"),
                },
            ))
        }
    }
}

/// An exception of `polepatch._errors` made with `message` and the keyword arguments
/// `kwargs` sets (its attributes).
fn exception(
    py: Python<'_>,
    class: &str,
    message: String,
    kwargs: impl FnOnce(&Bound<'_, PyDict>) -> PyResult<()>,
) -> PyErr {
    let make = || -> PyResult<PyErr> {
        let cls = py.import("polepatch._errors")?.getattr(class)?;
        let kw = PyDict::new(py);
        kwargs(&kw)?;
        Ok(PyErr::from_value(cls.call((message,), Some(&kw))?))
    };
    make().unwrap_or_else(|e| e)
}

/// An `InputError` with `path`, `line`, `column` (None where unknown).
fn input_error(
    py: Python<'_>,
    message: String,
    path: Option<String>,
    line: Option<usize>,
    column: Option<usize>,
) -> PyErr {
    exception(py, "InputError", message, |kw| {
        kw.set_item("path", path)?;
        kw.set_item("line", line)?;
        kw.set_item("column", column)
    })
}

/// The Python exception of a failure.
pub(crate) fn to_python(py: Python<'_>, failure: Failure) -> PyErr {
    match failure {
        Failure::Machine(e) => exception(py, "MachineError", e.to_string(), |_| Ok(())),
        Failure::Message { class, message } => exception(py, class, message, |_| Ok(())),
        Failure::Library { error, named } => {
            let message = error.to_string();
            let path = |p: &str| named.then(|| p.to_string());
            match &error {
                Error::Parse(p) => input_error(
                    py,
                    message,
                    p.path.as_deref().and_then(path),
                    Some(p.line),
                    Some(p.column),
                ),
                Error::Cl { path: p, record } => {
                    input_error(py, message, path(p), Some(record.line), Some(record.column))
                }
                Error::Unsupported { path: p, line, .. }
                | Error::NothingAnalysable { path: p, line } => {
                    input_error(py, message, path(p), Some(*line), None)
                }
                Error::Empty { path: p }
                | Error::NoRuns { path: p }
                | Error::NoRotary { path: p, .. } => input_error(py, message, path(p), None, None),
                Error::Point { index, .. } => {
                    exception(py, "InputError", message, |kw| kw.set_item("index", index))
                }
                Error::Path(_) => input_error(py, message, None, None, None),
                Error::Options(_) => PyValueError::new_err(message),
                Error::Output(_) => PyOSError::new_err(message),
                Error::OutOfMemory { .. } => pyo3::exceptions::PyMemoryError::new_err(message),
            }
        }
    }
}
