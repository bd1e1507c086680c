//! `polepatch._polepatch`: the native module of the `polepatch` Python package.
//!
//! A thin layer over the `polepatch` library (not over the C ABI): each function here is
//! one library call, made with the GIL released and under `catch_unwind`
//! ([`errors::detached`]). The public Python API — signatures, keyword defaults, docs —
//! is `python/polepatch/__init__.py`, which calls these with its keywords as a dict
//! ([`options`]). Reports cross as the library's own JSON (`serde_json` of the report
//! struct the CLI writes), which `__init__.py` turns into a dict with `json.loads`: one
//! serialisation, so the dict is the CLI's `--report` document.

mod errors;
mod machine;
mod options;

use errors::{Failure, detached, detached_cancellable};
use machine::NativeMachine;
use numpy::ndarray::Array2;
use numpy::{PyArray1, PyArray2, PyReadonlyArray2};
use options::{AnalysisKw, FileKw, PatcherKw, PostKw, ToolKw};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::pybacked::PyBackedBytes;
use pyo3::types::{PyBytes, PyDict};
use serde::Serialize;

/// The JSON of a report (serialising our own report types cannot fail: string keys,
/// numbers, strings).
fn json<T: Serialize>(report: &T) -> String {
    serde_json::to_string(report).expect("reports serialise to JSON")
}

/// `polepatch::patch_nc`: (bytes, report JSON).
#[pyfunction]
fn patch_nc<'py>(
    py: Python<'py>,
    data: PyBackedBytes,
    machine: &NativeMachine,
    options: &Bound<'py, PyDict>,
) -> PyResult<(Bound<'py, PyBytes>, String)> {
    let p: PatcherKw = options.extract()?;
    let f: FileKw = options.extract()?;
    let t: ToolKw = options.extract()?;
    let mut opts = f.patch(&p)?;
    opts.tool = t.tool()?;
    let m = &machine.0;
    // Ctrl-C stops the patch between stretches (`detached_cancellable`).
    let (out, report) = detached_cancellable(py, |cancelled| {
        let mut out = Vec::new();
        let hooks = polepatch::Hooks {
            progress: &|_, _| {},
            cancelled,
        };
        polepatch::patch_nc_hooked(&data, m, &opts, &mut out, hooks)
            .map(|report| (out, json(&report)))
            .map_err(Failure::library(f.named()))
    })?;
    Ok((PyBytes::new(py, &out), report))
}

/// `polepatch::analyze_nc`: the report JSON.
#[pyfunction]
fn analyze_nc(
    py: Python<'_>,
    data: PyBackedBytes,
    machine: &NativeMachine,
    options: &Bound<'_, PyDict>,
) -> PyResult<String> {
    let a: AnalysisKw = options.extract()?;
    let f: FileKw = options.extract()?;
    let opts = f.analyze(&a);
    let m = &machine.0;
    detached(py, || {
        polepatch::analyze_nc(&data, m, &opts)
            .map(|r| json(&r))
            .map_err(Failure::library(f.named()))
    })
}

/// `polepatch::post::read_cl` + `post_cl`: the NC bytes.
#[pyfunction]
fn post_cl<'py>(
    py: Python<'py>,
    cl: PyBackedBytes,
    machine: &NativeMachine,
    options: &Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyBytes>> {
    let p: PatcherKw = options.extract()?;
    let f: FileKw = options.extract()?;
    let post: PostKw = options.extract()?;
    let t: ToolKw = options.extract()?;
    let mut patch = f.patch(&p)?;
    patch.tool = t.tool()?;
    let opts = post.post(patch)?;
    let m = &machine.0;
    let out = detached(py, || {
        let post = || -> Result<Vec<u8>, polepatch::Error> {
            let program = polepatch::post::read_cl(&cl, &opts.patch_options.read.name)?;
            // The CL file's CUTTER/ and the tip, where the keywords did not say them.
            let mut opts = opts.clone();
            polepatch::post::tool_from_cl(&cl, &program, &mut opts);
            polepatch::post::post_cl(&program, m, &opts).map(|(out, _)| out)
        };
        post().map_err(Failure::library(f.named()))
    })?;
    Ok(PyBytes::new(py, &out))
}

/// `polepatch::reorient::reorient_nc` (both angles given) or `search` (neither): (bytes,
/// report JSON).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn reorient<'py>(
    py: Python<'py>,
    data: PyBackedBytes,
    machine: &NativeMachine,
    theta_x: Option<f64>,
    theta_z: Option<f64>,
    pivot_mm: Option<(f64, f64, f64)>,
    cone_deg: f64,
    name: Option<String>,
) -> PyResult<(Bound<'py, PyBytes>, String)> {
    let named = name.is_some();
    let name = name.unwrap_or_else(|| polepatch::ReadOptions::default().name);
    let pivot_mm = pivot_mm.map_or([0.0; 3], |(x, y, z)| [x, y, z]);
    let m = &machine.0;
    let tilt = match (theta_x, theta_z) {
        (Some(theta_x_deg), Some(theta_z_deg)) => Some(polepatch::reorient::Tilt {
            theta_x_deg,
            theta_z_deg,
            pivot_mm,
        }),
        (None, None) => None,
        _ => {
            return Err(PyValueError::new_err(
                "give both theta_x and theta_z (degrees), or neither to search for the smallest tilt",
            ));
        }
    };
    let (out, report) = detached(py, || {
        match &tilt {
            Some(tilt) => polepatch::reorient::reorient_nc(&data, m, tilt, &name, cone_deg),
            None => polepatch::reorient::search(&data, m, pivot_mm, &name, cone_deg),
        }
        .map(|(out, report)| (out, json(&report)))
        .map_err(Failure::library(named))
    })?;
    Ok((PyBytes::new(py, &out), report))
}

/// One run of [`feed_profile`], computed without the GIL.
struct RunSamples {
    run: usize,
    lines: [usize; 2],
    feed_mm_min: Option<f64>,
    s_mm: Vec<f64>,
    ratio: Vec<f64>,
    axis_ratio: Vec<[f64; 5]>,
    point_s_mm: Vec<f64>,
    point_lines: Vec<usize>,
    error: Option<String>,
}

/// One run of [`feed_profile`] as Python gets it (a dict, numpy arrays).
#[derive(IntoPyObject)]
struct RunProfile<'py> {
    run: usize,
    lines: [usize; 2],
    feed_mm_min: Option<f64>,
    s_mm: Bound<'py, PyArray1<f64>>,
    ratio: Bound<'py, PyArray1<f64>>,
    axis_ratio: Bound<'py, PyArray2<f64>>,
    axes: Vec<String>,
    point_s_mm: Bound<'py, PyArray1<f64>>,
    point_lines: Vec<usize>,
    error: Option<String>,
}

/// Equation 6 sampled along every run (`patcher::analyze_path` with `keep_samples` on
/// each run of `program::load_nc`), with each CL point's s and file line.
#[pyfunction]
fn feed_profile<'py>(
    py: Python<'py>,
    data: PyBackedBytes,
    machine: &NativeMachine,
    options: &Bound<'py, PyDict>,
) -> PyResult<Vec<RunProfile<'py>>> {
    use polepatch::kinematics::Axis;
    let a: AnalysisKw = options.extract()?;
    let f: FileKw = options.extract()?;
    let opts = f.analyze(&a);
    let m = &machine.0;
    let (runs, axes) = detached(py, || {
        let profile = || -> Result<(Vec<RunSamples>, Vec<String>), polepatch::Error> {
            opts.check()?;
            let lp = polepatch::load_nc(&data, &opts.read.name, m, opts.read.feed_fallback_mm_min)?;
            let analysis = polepatch::patcher::AnalysisOptions {
                keep_samples: true,
                ..opts.analysis.clone()
            };
            let runs = lp
                .runs
                .iter()
                .enumerate()
                .map(|(r, rp)| {
                    let analysed = match &rp.path {
                        Ok(p) => polepatch::patcher::analyze_path(p, m, &analysis)
                            .map_err(|e| e.to_string()),
                        Err(problem) => Err(problem.to_string()),
                    };
                    let (samples, error) = match analysed {
                        Ok(a) => (a.samples, None),
                        Err(e) => (Vec::new(), Some(e)),
                    };
                    RunSamples {
                        run: lp.run_number(r),
                        lines: lp.lines_of_run(r),
                        feed_mm_min: rp.path.as_ref().ok().map(|p| p.feed_mm_min),
                        s_mm: samples.iter().map(|x| x.s_mm).collect(),
                        ratio: samples.iter().map(|x| x.bound.ratio).collect(),
                        axis_ratio: samples.iter().map(|x| x.axis_ratio).collect(),
                        point_s_mm: rp.run.s_mm.clone(),
                        point_lines: (0..rp.run.len()).map(|k| lp.line_of(r, k)).collect(),
                        error,
                    }
                })
                .collect();
            let axes = Axis::ALL
                .iter()
                .map(|&a| polepatch::report::axis_letter(a, lp.letters()))
                .collect();
            Ok((runs, axes))
        };
        profile().map_err(Failure::library(f.named()))
    })?;
    Ok(runs
        .into_iter()
        .map(|r| RunProfile {
            run: r.run,
            lines: r.lines,
            feed_mm_min: r.feed_mm_min,
            s_mm: PyArray1::from_vec(py, r.s_mm),
            ratio: PyArray1::from_vec(py, r.ratio),
            axis_ratio: array(py, r.axis_ratio),
            axes: axes.clone(),
            point_s_mm: PyArray1::from_vec(py, r.point_s_mm),
            point_lines: r.point_lines,
            error: r.error,
        })
        .collect())
}

/// Rows of a `(n, N)` float64 array, copied out of Python's memory (so that the work can
/// run without the GIL while Python threads may write to the array).
fn rows<const N: usize>(a: &PyReadonlyArray2<'_, f64>, what: &str) -> PyResult<Vec<[f64; N]>> {
    let view = a.as_array();
    if view.ncols() != N {
        return Err(PyValueError::new_err(format!(
            "{what} must have shape (n, {N}), got {:?}",
            view.shape()
        )));
    }
    Ok(view
        .rows()
        .into_iter()
        .map(|r| std::array::from_fn(|i| r[i]))
        .collect())
}

/// `(n, N)` rows as a numpy array, without a copy (the array takes the vector).
fn array<'py, const N: usize>(py: Python<'py>, rows: Vec<[f64; N]>) -> Bound<'py, PyArray2<f64>> {
    let n = rows.len();
    let flat = rows.into_flattened();
    let a = Array2::from_shape_vec((n, N), flat).expect("n rows of N values");
    PyArray2::from_owned_array(py, a)
}

/// `polepatch::joints::cl_to_joints`: `(n, 6)` x y z i j k → `(n, 5)` x y z p c.
#[pyfunction]
fn cl_to_joints<'py>(
    py: Python<'py>,
    xyzijk: PyReadonlyArray2<'py, f64>,
    machine: &NativeMachine,
    branch: &str,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let rule = options::branch_rule(branch)?;
    let cl = rows::<6>(&xyzijk, "xyzijk")?;
    let m = &machine.0;
    let joints = detached(py, || {
        polepatch::joints::cl_to_joints(m, &cl, rule).map_err(Failure::library(false))
    })?;
    Ok(array(py, joints))
}

/// `polepatch::joints::patch_joints`: (`(n, 5)` array, zone reports JSON).
#[pyfunction]
fn patch_joints<'py>(
    py: Python<'py>,
    xyzpc: PyReadonlyArray2<'py, f64>,
    machine: &NativeMachine,
    feed_mm_min: f64,
    options: &Bound<'py, PyDict>,
) -> PyResult<(Bound<'py, PyArray2<f64>>, String)> {
    let p: PatcherKw = options.extract()?;
    let opts = p.patcher()?;
    let points = rows::<5>(&xyzpc, "xyzpc")?;
    let m = &machine.0;
    let result = detached(py, || {
        polepatch::joints::patch_joints(m, &points, feed_mm_min, &opts)
            .map_err(Failure::library(false))
    })?;
    Ok((array(py, result.xyzpc), json(&result.zones)))
}

/// For the test suite: a panic inside the boundary, which must arrive as
/// `polepatch.InternalError` (never an abort).
#[pyfunction]
fn _panic_for_test(py: Python<'_>, message: String) -> PyResult<()> {
    detached(py, || -> Result<(), Failure> { panic!("{message}") })
}

/// The native part of the polepatch Python package (use `polepatch`, not this module).
#[pymodule]
fn _polepatch(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<NativeMachine>()?;
    m.add_function(wrap_pyfunction!(patch_nc, m)?)?;
    m.add_function(wrap_pyfunction!(analyze_nc, m)?)?;
    m.add_function(wrap_pyfunction!(feed_profile, m)?)?;
    m.add_function(wrap_pyfunction!(post_cl, m)?)?;
    m.add_function(wrap_pyfunction!(reorient, m)?)?;
    m.add_function(wrap_pyfunction!(cl_to_joints, m)?)?;
    m.add_function(wrap_pyfunction!(patch_joints, m)?)?;
    m.add_function(wrap_pyfunction!(options::defaults, m)?)?;
    m.add_function(wrap_pyfunction!(_panic_for_test, m)?)?;
    Ok(())
}
