//! The crate's error type.

/// Bad input to a constructor or fit. Numerical outcomes are never errors.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SplineError {
    /// Too few data points for the requested operation.
    #[error("need at least {needed} points, got {got}")]
    TooFewPoints {
        /// Minimum.
        needed: usize,
        /// Given.
        got: usize,
    },
    /// Parameters must be strictly increasing.
    #[error("parameters must be strictly increasing: s[{index}] = {value} after {previous}")]
    NotIncreasing {
        /// Index of the offending parameter.
        index: usize,
        /// Its value.
        value: f64,
        /// The value before it.
        previous: f64,
    },
    /// A parameter, value or weight is NaN or infinite.
    #[error("{what}[{index}] is not finite ({value})")]
    NotFinite {
        /// Which input (`s`, `y`, `w`, `knots`, …).
        what: &'static str,
        /// Index.
        index: usize,
        /// The value.
        value: f64,
    },
    /// A least-squares weight is negative.
    #[error("weight w[{index}] = {value} is negative")]
    NegativeWeight {
        /// Index of the weight.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// Lengths of inputs disagree.
    #[error("length mismatch: {what}")]
    LengthMismatch {
        /// Description.
        what: String,
    },
    /// Knot vector invalid (not non-decreasing, wrong multiplicity, too short).
    #[error("invalid knot vector: {what}")]
    InvalidKnots {
        /// Description.
        what: String,
    },
    /// The system is singular (e.g. least squares with an empty knot span).
    #[error("singular system: {what}")]
    Singular {
        /// Description.
        what: String,
    },
}
