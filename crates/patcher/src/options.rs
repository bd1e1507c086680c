//! Options of the patcher.

/// Options of [`crate::patch_path`]. Plain struct: every field public, documented default.
#[derive(Debug, Clone, PartialEq)]
pub struct PatchOptions {
    /// Singular cone, degrees: a zone needs a point with |primary| ≤ this. Default 5.
    pub cone_deg: f64,
    /// Largest orientation deviation allowed at any point, degrees; `None` = no limit
    /// (the deviation is still minimised). Default `None`.
    pub max_deviation_deg: Option<f64>,
    /// Interpolation cycle time override, seconds; `None` = the machine's. Default `None`.
    pub tcy_s: Option<f64>,
    /// Safety margin on the C limits: the QP uses (1 − margin)·V, A, J. Default 0.02.
    pub margin: f64,
    /// Ask for third-derivative continuity at the joins where feasible. Default true.
    pub third_derivative_continuity: bool,
    /// Decimal places of the file's C words (values are verified rounded to these).
    /// Default 3.
    pub c_decimals: usize,
    /// Decimal places of the file's primary-axis words (A or B). Default 3.
    pub p_decimals: usize,
    /// Most decimal places polepatch may write when the file's precision cannot hold
    /// Equation 6. Default 4.
    pub max_decimals: usize,
    /// Longest patch, mm; `None` = up to the whole run. Default `None`.
    pub max_patch_length_mm: Option<f64>,
    /// Allow a 360° multiple offset of C after the singular point when it shortens the
    /// join. The rest of the run then carries the offset, and the move after the run has to
    /// turn C the extra revolution back, so it is off by default. Default false.
    pub allow_c_offset: bool,
}

impl Default for PatchOptions {
    fn default() -> Self {
        PatchOptions {
            cone_deg: 5.0,
            max_deviation_deg: None,
            tcy_s: None,
            margin: 0.02,
            third_derivative_continuity: true,
            c_decimals: 3,
            p_decimals: 3,
            max_decimals: 4,
            max_patch_length_mm: None,
            allow_c_offset: false,
        }
    }
}

/// The value the controller receives when `v` is written with `decimals` places
/// (the same rounding as the NC writer: `format!("{:.*}", decimals, v)`).
pub fn round_written(v: f64, decimals: usize) -> f64 {
    format!("{v:.decimals$}").parse().unwrap_or(v)
}
