//! The report of a simulation (the JSON of `polepatch simulate --json`), and the simulated
//! times before and after a patch that the patch report carries.

use serde::Serialize;

/// One run in the simulation report.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct SimRun {
    /// Run number, from 1.
    pub run: usize,
    /// File lines of its first point and last block.
    pub lines: [usize; 2],
    /// CL points.
    pub points: usize,
    /// Path length, mm.
    pub length_mm: f64,
    /// Feed, mm/min (`null` if none).
    pub feed_mm_min: Option<f64>,
    /// Why it was not simulated.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// Simulated time, s.
    pub time_s: f64,
    /// Equation 6's estimate ∫ds/ṡ, s.
    pub eq6_time_s: f64,
    /// L/F, s.
    pub ideal_time_s: f64,
    /// The lowest feed at one of its points (first and last excluded), mm/min.
    pub min_feed_mm_min: Option<f64>,
    /// The file line of that point.
    pub min_feed_line: Option<usize>,
    /// Moves on from the run before without a stop (a feed change between them).
    pub joined: bool,
    /// `machine` (X Y Z through the machine's chain) or `program` (the values as written).
    pub frame: SimFrame,
}

/// The frame a run was simulated in ([`SimRun::frame`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SimFrame {
    /// X Y Z through the machine's kinematic chain (what the controller moves).
    Machine,
    /// The values as written.
    Program,
}

impl SimFrame {
    /// `machine` or `program`: its serde form.
    pub fn name(self) -> &'static str {
        match self {
            SimFrame::Machine => "machine",
            SimFrame::Program => "program",
        }
    }
}

impl std::fmt::Display for SimFrame {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Totals of a simulation report.
#[derive(Debug, Clone, Copy, Serialize, PartialEq, Default)]
pub struct SimTotals {
    /// Simulated, s.
    pub time_s: f64,
    /// Equation 6's estimate, s.
    pub eq6_time_s: f64,
    /// L/F, s.
    pub ideal_time_s: f64,
    /// Runs simulated.
    pub runs: usize,
    /// Cycles where the simulator had to put the motion on its ceiling (see
    /// `polepatch_simulate::Simulation::clips`).
    pub clips: usize,
}

/// The whole simulation document.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct SimulateReport {
    /// File name.
    pub file: String,
    /// Machine name.
    pub machine: String,
    /// Interpolation cycle time used, s.
    pub tcy_s: f64,
    /// The tilting letter the program uses.
    pub primary: String,
    /// Notes for the user.
    pub warnings: Vec<String>,
    /// Why nothing was simulated, for a program with no G1 motion at all (`None`
    /// otherwise; runs that cannot be simulated say why in their `error`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nothing_to_simulate: Option<String>,
    /// Runs in file order.
    pub runs: Vec<SimRun>,
    /// Totals over the simulated runs.
    pub total: SimTotals,
}

/// The simulated times of a program before and after a patch, for the patch report.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct SimulatedTimes {
    /// Simulated time of the input, s.
    pub before_s: f64,
    /// Simulated time of the output, s.
    pub after_s: f64,
    /// Equation 6's estimate of the input, s.
    pub eq6_before_s: f64,
    /// Equation 6's estimate of the output, s.
    pub eq6_after_s: f64,
    /// The runs whose simulated time changed.
    pub runs: Vec<RunTimes>,
}

/// One run of [`SimulatedTimes`].
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct RunTimes {
    /// Run number, from 1.
    pub run: usize,
    /// File lines of its first point and last block.
    pub lines: [usize; 2],
    /// Simulated, before and after, s.
    pub time_s: [f64; 2],
    /// Equation 6's estimate, before and after, s.
    pub eq6_time_s: [f64; 2],
}

/// The times of `before` and `after` (the same program before and after a patch: the
/// same runs) side by side.
pub fn compare(before: &SimulateReport, after: &SimulateReport) -> SimulatedTimes {
    let runs = before
        .runs
        .iter()
        .zip(&after.runs)
        .filter(|(b, a)| b.run == a.run && (b.time_s != a.time_s || b.eq6_time_s != a.eq6_time_s))
        .map(|(b, a)| RunTimes {
            run: b.run,
            lines: b.lines,
            time_s: [b.time_s, a.time_s],
            eq6_time_s: [b.eq6_time_s, a.eq6_time_s],
        })
        .collect();
    SimulatedTimes {
        before_s: before.total.time_s,
        after_s: after.total.time_s,
        eq6_before_s: before.total.eq6_time_s,
        eq6_after_s: after.total.eq6_time_s,
        runs,
    }
}
