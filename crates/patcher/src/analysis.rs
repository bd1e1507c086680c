//! Equation-6 analysis of one run.

/// Result of analysing one run (filled in by [`analyze_path`]).
#[derive(Debug, Clone, PartialEq)]
pub struct RunAnalysis {}

/// Analyse a path (stub).
pub fn analyze_path() -> RunAnalysis {
    RunAnalysis {}
}
