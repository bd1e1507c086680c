//! The keyword options of the Python calls, as the library's option structs.
//!
//! `polepatch/__init__.py` passes each call's keywords as one dict; the structs here read
//! it by key (`from_item_all`), and turn into the library's options. The same structs,
//! made from the library's `Default`s, are `_polepatch.defaults()`: the tests check that
//! the keyword defaults of the Python signatures are those.

use polepatch::kinematics::BranchRule;
use polepatch::nc::Dialect;
use polepatch::patcher::{self, PatchAxes};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// The patcher's options (`polepatch::patcher::PatchOptions`) by their Python names.
#[derive(Debug, Clone, FromPyObject, IntoPyObject)]
#[pyo3(from_item_all)]
pub(crate) struct PatcherKw {
    /// Change C only (G16's method) instead of both rotary axes.
    only_c: bool,
    /// Singular cone, degrees.
    cone_deg: f64,
    /// Largest orientation change allowed, degrees (None: no limit).
    max_deviation_deg: Option<f64>,
    /// Interpolation cycle time, ms (None: the machine's).
    tcy_ms: Option<f64>,
    /// Safety margin on the limits, a fraction.
    margin: f64,
    /// Most decimals written for a rotary value when the file's are not enough.
    max_decimals: usize,
    /// Longest patch, mm (None: up to the whole run).
    max_patch_length_mm: Option<f64>,
    /// Third-derivative continuity at the joins where feasible.
    jerk_continuity: bool,
    /// Allow a 360° multiple offset of C after a zone.
    allow_c_offset: bool,
}

impl PatcherKw {
    fn of(p: &patcher::PatchOptions) -> PatcherKw {
        PatcherKw {
            only_c: p.axes == PatchAxes::OnlyC,
            cone_deg: p.cone_deg,
            max_deviation_deg: p.max_deviation_deg,
            tcy_ms: p.tcy_s.map(|s| s * 1e3),
            margin: p.margin,
            max_decimals: p.max_decimals,
            max_patch_length_mm: p.max_patch_length_mm,
            jerk_continuity: p.third_derivative_continuity,
            allow_c_offset: p.allow_c_offset,
        }
    }

    /// The patcher's options, checked by the patcher's one rule set
    /// (`PatchOptions::validate`): a refusal is a `ValueError` naming the keyword.
    pub(crate) fn patcher(&self) -> PyResult<patcher::PatchOptions> {
        let opts = patcher::PatchOptions {
            cone_deg: self.cone_deg,
            axes: if self.only_c {
                PatchAxes::OnlyC
            } else {
                PatchAxes::Both
            },
            max_deviation_deg: self.max_deviation_deg,
            tcy_s: self.tcy_ms.map(|ms| ms / 1e3),
            margin: self.margin,
            third_derivative_continuity: self.jerk_continuity,
            max_decimals: self.max_decimals,
            max_patch_length_mm: self.max_patch_length_mm,
            allow_c_offset: self.allow_c_offset,
            ..patcher::PatchOptions::default()
        };
        opts.validate().map_err(|e| self.refusal(&e))?;
        Ok(opts)
    }

    /// The patcher's refusal in the keywords' terms (`tcy_ms` in milliseconds).
    fn refusal(&self, e: &patcher::OptionsError) -> PyErr {
        use patcher::OptionField as F;
        let message = match e.field {
            F::TcyS => format!(
                "tcy_ms must be a positive number of milliseconds, got {}",
                self.tcy_ms.unwrap_or(f64::NAN)
            ),
            F::ThirdDerivativeContinuity => e.message("jerk_continuity"),
            F::AllowCOffset => e.message("allow_c_offset"),
            F::ConeDeg
            | F::PoleReachDeg
            | F::MaxDeviationDeg
            | F::Margin
            | F::MaxDecimals
            | F::MaxPatchLengthMm
            | F::KeepCentreRadiusMm
            | F::KeepCentreUnitMm => e.to_string(),
        };
        PyValueError::new_err(message)
    }
}

/// The analysis options (`polepatch::patcher::AnalysisOptions`) by their Python names.
#[derive(Debug, Clone, FromPyObject, IntoPyObject)]
#[pyo3(from_item_all)]
pub(crate) struct AnalysisKw {
    /// Singular cone, degrees.
    cone_deg: f64,
    /// Interpolation cycle time, ms (None: the machine's).
    tcy_ms: Option<f64>,
}

impl AnalysisKw {
    fn of(a: &patcher::AnalysisOptions) -> AnalysisKw {
        AnalysisKw {
            cone_deg: a.cone_deg,
            tcy_ms: a.tcy_s.map(|s| s * 1e3),
        }
    }
}

/// What the file-level calls add: feed fallback, work offset, the input's name.
#[derive(Debug, Clone, FromPyObject, IntoPyObject)]
#[pyo3(from_item_all)]
pub(crate) struct FileKw {
    /// Feed, mm/min, for runs with no F in force.
    feed_fallback_mm_min: Option<f64>,
    /// Work offset X Y Z, mm, for a machine with a kinematic chain.
    work_offset_mm: Option<(f64, f64, f64)>,
    /// Name of the input in messages and in the report (None: the library's, "input").
    name: Option<String>,
}

impl FileKw {
    /// Whether the caller named the input (else errors carry no path).
    pub(crate) fn named(&self) -> bool {
        self.name.is_some()
    }

    /// The input's name in messages and reports.
    pub(crate) fn name(&self) -> String {
        self.name
            .clone()
            .unwrap_or_else(|| polepatch::ReadOptions::default().name)
    }

    /// How the library reads the input: these keywords (a program without units in mm).
    pub(crate) fn read(&self) -> polepatch::ReadOptions {
        polepatch::ReadOptions {
            name: self.name(),
            feed_fallback_mm_min: self.feed_fallback_mm_min,
            work_offset_mm: self.work_offset_mm.map(|(x, y, z)| [x, y, z]),
            inch: false,
        }
    }

    /// The library's patch options with the patcher's `p`.
    pub(crate) fn patch(&self, p: &PatcherKw) -> PyResult<polepatch::PatchOptions> {
        Ok(polepatch::PatchOptions {
            read: self.read(),
            patch: p.patcher()?,
            ..polepatch::PatchOptions::default()
        })
    }

    /// The library's analysis options with the analysis's `a`.
    pub(crate) fn analyze(&self, a: &AnalysisKw) -> polepatch::AnalyzeOptions {
        polepatch::AnalyzeOptions {
            analysis: patcher::AnalysisOptions {
                cone_deg: a.cone_deg,
                tcy_s: a.tcy_ms.map(|ms| ms / 1e3),
                ..patcher::AnalysisOptions::default()
            },
            read: self.read(),
        }
    }
}

/// The cutter and the point X Y Z state (`polepatch::tool::ToolOptions`), as the CLI's
/// `--tool`, `--tool-point` and `--surface-tolerance`.
#[derive(Debug, Clone, FromPyObject, IntoPyObject)]
#[pyo3(from_item_all)]
pub(crate) struct ToolKw {
    /// `"ball:10"`, `"flat:12"`, `"bull:10,2"` (None: per run, from the program).
    tool: Option<String>,
    /// `"tip"` or `"centre"` (None: the machine file's, else the TCPM code's).
    tool_point: Option<String>,
    /// How far a flat or bull-nose cutter's surface may move at a CL point, mm.
    surface_tolerance_mm: f64,
}

impl ToolKw {
    fn of(t: &polepatch::tool::ToolOptions) -> ToolKw {
        ToolKw {
            tool: None,
            tool_point: None,
            surface_tolerance_mm: t.surface_tolerance_mm,
        }
    }

    /// The library's tool options, read by the library's own parsers of `--tool` and
    /// `--tool-point` ([`polepatch::tool::Tool::parse`], [`polepatch::tool::ToolPoint::parse`]):
    /// what they refuse is a `ValueError` with their message.
    pub(crate) fn tool(&self) -> PyResult<polepatch::tool::ToolOptions> {
        use polepatch::tool::{Tool, ToolOptions, ToolPoint};
        let tool = self
            .tool
            .as_deref()
            .map(Tool::parse)
            .transpose()
            .map_err(PyValueError::new_err)?;
        let point = self
            .tool_point
            .as_deref()
            .map(ToolPoint::parse)
            .transpose()
            .map_err(PyValueError::new_err)?;
        Ok(ToolOptions {
            tool,
            point,
            surface_tolerance_mm: self.surface_tolerance_mm,
            ..ToolOptions::default()
        })
    }
}

/// What `post_cl` adds (`polepatch::post::PostOptions`).
#[derive(Debug, Clone, FromPyObject, IntoPyObject)]
#[pyo3(from_item_all)]
pub(crate) struct PostKw {
    /// `heidenhain`, `sinumerik` or `fanuc`.
    dialect: String,
    /// IK branch rule: `nearest`, `domain`, `positive` or `negative`.
    branch: String,
    /// Patch the posted program.
    patch: bool,
    /// Decimals of rotary words.
    rotary_decimals: usize,
    /// Decimals of linear words.
    linear_decimals: usize,
}

/// Dialect names, as the CLI's `--dialect`.
const DIALECTS: [(&str, Dialect); 3] = [
    ("heidenhain", Dialect::Heidenhain),
    ("sinumerik", Dialect::Sinumerik),
    ("fanuc", Dialect::Fanuc),
];

/// Branch rule names, as the CLI's `--branch`.
const BRANCHES: [(&str, BranchRule); 4] = [
    ("nearest", BranchRule::Nearest),
    ("domain", BranchRule::DomainRule),
    ("positive", BranchRule::PreferPositive),
    ("negative", BranchRule::PreferNegative),
];

fn name_of<T: PartialEq + Copy>(table: &[(&'static str, T)], v: T) -> &'static str {
    table.iter().find(|(_, t)| *t == v).map_or("?", |(n, _)| n)
}

fn by_name<T: Copy>(table: &[(&'static str, T)], what: &str, name: &str) -> PyResult<T> {
    table
        .iter()
        .find(|(n, _)| *n == name)
        .map(|&(_, t)| t)
        .ok_or_else(|| {
            let names: Vec<&str> = table.iter().map(|(n, _)| *n).collect();
            PyValueError::new_err(format!(
                "{what} must be one of {}, got '{name}'",
                names.join(", ")
            ))
        })
}

/// The branch rule called `name`.
pub(crate) fn branch_rule(name: &str) -> PyResult<BranchRule> {
    by_name(&BRANCHES, "branch", name)
}

impl PostKw {
    fn of(p: &polepatch::post::PostOptions) -> PostKw {
        PostKw {
            dialect: name_of(&DIALECTS, p.dialect).to_string(),
            branch: name_of(&BRANCHES, p.branch).to_string(),
            patch: p.patch,
            rotary_decimals: p.rotary_decimals,
            linear_decimals: p.linear_decimals,
        }
    }

    /// The library's post options with the patch options `patch`.
    pub(crate) fn post(
        &self,
        patch: polepatch::PatchOptions,
    ) -> PyResult<polepatch::post::PostOptions> {
        for (what, v) in [
            ("rotary_decimals", self.rotary_decimals),
            ("linear_decimals", self.linear_decimals),
        ] {
            if v > polepatch::MAX_WRITTEN_DECIMALS {
                return Err(PyValueError::new_err(format!(
                    "{what} must be at most {}, got {v}",
                    polepatch::MAX_WRITTEN_DECIMALS
                )));
            }
        }
        Ok(polepatch::post::PostOptions {
            dialect: by_name(&DIALECTS, "dialect", &self.dialect)?,
            branch: branch_rule(&self.branch)?,
            patch: self.patch,
            patch_options: patch,
            rotary_decimals: self.rotary_decimals,
            linear_decimals: self.linear_decimals,
            ..polepatch::post::PostOptions::default()
        })
    }
}

/// The library's defaults by Python keyword: `{"patch": …, "file": …, "tool": …,
/// "post": …, "analyze": …}` (what the keyword defaults of `polepatch/__init__.py` must be).
#[pyfunction]
pub(crate) fn defaults(py: Python<'_>) -> PyResult<Bound<'_, pyo3::types::PyDict>> {
    let patch = polepatch::PatchOptions::default();
    let analyze = polepatch::AnalyzeOptions::default();
    let d = pyo3::types::PyDict::new(py);
    d.set_item("patch", PatcherKw::of(&patch.patch))?;
    d.set_item(
        "file",
        FileKw {
            feed_fallback_mm_min: patch.read.feed_fallback_mm_min,
            work_offset_mm: patch.read.work_offset_mm.map(|[x, y, z]| (x, y, z)),
            name: None,
        },
    )?;
    d.set_item("tool", ToolKw::of(&patch.tool))?;
    d.set_item("post", PostKw::of(&polepatch::post::PostOptions::default()))?;
    d.set_item("analyze", AnalysisKw::of(&analyze.analysis))?;
    Ok(d)
}
