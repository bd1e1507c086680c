//! The machine handed to every call (`polepatch.Machine` wraps it).

use crate::errors::{Failure, to_python};
use polepatch::kinematics::{Axis, Machine, forward};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// A machine (immutable, shared freely between threads).
#[pyclass(frozen, module = "polepatch._polepatch", name = "NativeMachine")]
pub(crate) struct NativeMachine(pub(crate) Machine);

#[pymethods]
impl NativeMachine {
    /// A built-in machine by name.
    #[staticmethod]
    fn builtin(py: Python<'_>, name: &str) -> PyResult<NativeMachine> {
        // A built-in name only (`Machine::load` would also read a file of that name:
        // `Machine.from_file` does that in Python).
        Machine::builtin(name).map(NativeMachine).ok_or_else(|| {
            let message = format!(
                "unknown built-in machine '{name}' (built-ins: {}); a machine file: Machine.from_file(path)",
                Machine::builtin_names().join(", ")
            );
            to_python(py, Failure::Message { class: "MachineError", message })
        })
    }

    /// A machine from the text of a machine TOML file; `origin` names it in errors.
    #[staticmethod]
    fn from_toml(py: Python<'_>, text: &str, origin: &str) -> PyResult<NativeMachine> {
        Machine::from_toml_str(text, origin)
            .map(NativeMachine)
            .map_err(|e| to_python(py, Failure::Machine(e)))
    }

    /// A machine file at `path`, read at most 1 MiB (a device such as `/dev/zero` is not
    /// read without limit).
    #[staticmethod]
    fn from_file(py: Python<'_>, path: std::path::PathBuf) -> PyResult<NativeMachine> {
        Machine::from_file(&path)
            .map(NativeMachine)
            .map_err(|e| to_python(py, Failure::Machine(e)))
    }

    /// Names of the built-in machines.
    #[staticmethod]
    fn builtin_names() -> Vec<&'static str> {
        Machine::builtin_names().to_vec()
    }

    #[getter]
    fn name(&self) -> &str {
        &self.0.name
    }

    #[getter]
    fn primary(&self) -> String {
        self.0.primary_letter().to_string()
    }

    #[getter]
    fn tcy_ms(&self) -> f64 {
        self.0.tcy_s * 1e3
    }

    #[getter]
    fn primary_range_deg(&self) -> (f64, f64) {
        self.0.primary_range_deg
    }

    #[getter]
    fn c_range_deg(&self) -> Option<(f64, f64)> {
        self.0.c_range_deg
    }

    /// `{letter: (v, a, j)}` per axis in internal units (mm/s, mm/s², mm/s³ for X Y Z;
    /// °/s, °/s², °/s³ for the primary axis and C).
    #[getter]
    fn limits<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for axis in Axis::ALL {
            let letter = self.0.letter(axis).to_string();
            let l = self.0.limit(axis);
            d.set_item(letter, (l.v, l.a, l.j))?;
        }
        Ok(d)
    }

    /// The tool axis (i, j, k) in the part frame at primary `p_deg` and `c_deg`.
    fn tool_axis(&self, p_deg: f64, c_deg: f64) -> (f64, f64, f64) {
        let o = forward(&self.0, p_deg, c_deg);
        (o[0], o[1], o[2])
    }
}
