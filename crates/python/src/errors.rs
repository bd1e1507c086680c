//! The boundary: work runs with the GIL released and under `catch_unwind`; the library's
//! errors become the package's exceptions (defined in `polepatch/_errors.py`), a panic
//! becomes `polepatch.InternalError`.
//!
//! | Rust | Python | attributes |
//! |---|---|---|
//! | `Error::Parse`, `Error::Cl`, `Error::ForeignAxis`, `Error::BeyondRange` | `InputError` | `path`, `line`, `column` |
//! | `Error::Unsupported` | `InputError` | `path`, `line` (`column` None) |
//! | `Error::Empty`, `NoRuns`, `NoRotary` (only where a call needs motion: `reorient`, `simulate`) | `InputError` | `path` |
//! | `Error::Point`, `Error::OutOfRange` | `InputError` | `index` (the array row) |
//! | `Error::Cancelled` (Ctrl-C during the call) | `KeyboardInterrupt` | — |
//! | `Error::Path` (joint arrays) | `InputError` | — |
//! | `Error::Options` | `ValueError` | — |
//! | `Error::Unverified` (the patched program fails its check against the input) | `VerificationError` | `path`, `line` (the first failing line) |
//! | `MachineError`, `Error::Machine` (a machine polepatch cannot work with: a layout not supported yet, a controller code it cannot read) | `MachineError` | — |
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

/// How often a call made with [`detached_cancellable`] looks for a signal (Ctrl-C).
const SIGNAL_POLL: std::time::Duration = std::time::Duration::from_millis(50);

/// [`detached`] for a long call that can stop: `work` runs on a thread of its own and gets
/// a `cancelled` flag to hand to the library ([`polepatch::Hooks`]); meanwhile the calling
/// thread looks for signals every [`SIGNAL_POLL`] (`PyErr_CheckSignals`, which runs
/// Python's handlers when called from the main thread). A handler that raises (Ctrl-C's
/// `KeyboardInterrupt`) sets the flag, and once the library has stopped at its next check
/// (between stretches) its exception is raised, not the library's `Cancelled`.
pub(crate) fn detached_cancellable<T: Send>(
    py: Python<'_>,
    work: impl FnOnce(&(dyn Fn() -> bool + Sync)) -> Result<T, Failure> + Send,
) -> PyResult<T> {
    use std::sync::atomic::{AtomicBool, Ordering};
    let stop = AtomicBool::new(false);
    let mut raised: Option<PyErr> = None;
    let result = detached(py, || {
        std::thread::scope(|scope| {
            let (tx, rx) = std::sync::mpsc::channel();
            let stop = &stop;
            scope.spawn(move || {
                let cancelled = || stop.load(Ordering::Relaxed);
                let _ = tx.send(catch_unwind(AssertUnwindSafe(|| work(&cancelled))));
            });
            loop {
                match rx.recv_timeout(SIGNAL_POLL) {
                    Ok(Ok(r)) => return r,
                    Ok(Err(panic)) => std::panic::resume_unwind(panic),
                    Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {
                        if raised.is_none()
                            && let Err(e) = Python::attach(|py| py.check_signals())
                        {
                            raised = Some(e);
                            stop.store(true, Ordering::Relaxed);
                        }
                    }
                    Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => {
                        unreachable!("the worker sends before it ends")
                    }
                }
            }
        })
    });
    match raised {
        Some(e) => Err(e),
        None => result,
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
                Error::ForeignAxis {
                    path: p,
                    line,
                    column,
                    ..
                }
                | Error::BeyondRange {
                    path: p,
                    line,
                    column,
                    ..
                } => input_error(py, message, path(p), Some(*line), Some(*column)),
                Error::Unsupported { path: p, line, .. }
                | Error::NothingAnalysable { path: p, line } => {
                    input_error(py, message, path(p), Some(*line), None)
                }
                Error::Empty { path: p }
                | Error::NoRuns { path: p }
                | Error::NoRotary { path: p, .. } => input_error(py, message, path(p), None, None),
                Error::Point { index, .. } | Error::OutOfRange { index, .. } => {
                    exception(py, "InputError", message, |kw| kw.set_item("index", index))
                }
                Error::Cancelled => pyo3::exceptions::PyKeyboardInterrupt::new_err(message),
                Error::Path(_) => input_error(py, message, None, None, None),
                Error::Options(_) => PyValueError::new_err(message),
                Error::Machine { .. } => exception(py, "MachineError", message, |_| Ok(())),
                Error::Output(_) => PyOSError::new_err(message),
                Error::OutOfMemory { .. } => pyo3::exceptions::PyMemoryError::new_err(message),
                Error::Unverified {
                    path: p,
                    violations,
                } => {
                    let line = violations.first().map(|v| v.line).filter(|&l| l > 0);
                    exception(py, "VerificationError", message, |kw| {
                        kw.set_item("path", path(p))?;
                        kw.set_item("line", line)
                    })
                }
            }
        }
    }
}
