//! Report documents (serde): what `analyze` prints, as data.

use crate::program::LoadedProgram;
use polepatch_kinematics::{Axis, LimitKind, Machine};
use polepatch_patcher::{AnalysisOptions, RunAnalysis, ZoneKind, analyze_path};
use serde::Serialize;
use std::collections::BTreeMap;

/// Axis letter as written in the program (primary: the letter in use).
pub fn axis_letter(axis: Axis, primary_letter: u8) -> String {
    match axis {
        Axis::X => "X".into(),
        Axis::Y => "Y".into(),
        Axis::Z => "Z".into(),
        Axis::Primary => (primary_letter as char).to_string(),
        Axis::C => "C".into(),
    }
}

/// Short name of a limit: `V`, `A`, `J`, or `F` (the programmed feed).
pub fn limit_name(kind: LimitKind) -> &'static str {
    match kind {
        LimitKind::Feed => "F",
        LimitKind::Velocity => "V",
        LimitKind::Acceleration => "A",
        LimitKind::Jerk => "J",
    }
}

/// Speed in the machine tables' units: m/min for a linear axis (from mm/s), rpm for a
/// rotary axis (from °/s).
pub fn machine_units(axis: Axis, internal: f64) -> f64 {
    if axis.is_rotary() {
        internal / 6.0
    } else {
        internal * 0.06
    }
}

/// A singular zone in a run.
#[derive(Debug, Clone, Serialize)]
pub struct ZoneSummary {
    /// File lines of the first and last point of the zone.
    pub lines: [usize; 2],
    /// `A-flip` or `C-swing`.
    pub kind: &'static str,
    /// File line of the singular point.
    pub singular_line: usize,
    /// Smallest |primary| in the zone, degrees.
    pub min_abs_primary_deg: f64,
    /// Lowest C-limited Equation-6 ratio in the zone.
    pub c_ratio_min: f64,
}

/// Name of a zone kind in reports.
pub fn zone_kind_name(kind: ZoneKind) -> &'static str {
    match kind {
        ZoneKind::AFlip => "A-flip",
        ZoneKind::CSwing => "C-swing",
    }
}

/// Equation-6 figures of an analysed run.
#[derive(Debug, Clone, Serialize)]
pub struct RunFigures {
    /// Lowest feed ratio over the run (bound / F).
    pub min_ratio: f64,
    /// Axis limiting there (`null`: the feed itself).
    pub limiting_axis: Option<String>,
    /// Limit binding there: `V`, `A`, `J` or `F`.
    pub limiting_limit: &'static str,
    /// Where, mm along the run.
    pub min_at_s_mm: f64,
    /// File line of the point at or just after that place.
    pub min_at_line: usize,
    /// Lowest ratio per axis letter.
    pub axis_min_ratio: BTreeMap<String, f64>,
    /// Binding limit per axis letter at its lowest ratio.
    pub axis_limit: BTreeMap<String, &'static str>,
    /// Estimated time ∫ds/ṡ, s.
    pub time_s: f64,
    /// L/F, s.
    pub ideal_time_s: f64,
    /// Peak speed of each axis at the programmed feed: rpm (rotary), m/min (linear).
    pub peak_speed: BTreeMap<String, f64>,
    /// Singular zones.
    pub zones: Vec<ZoneSummary>,
}

/// One run in the analysis report.
#[derive(Debug, Clone, Serialize)]
pub struct RunReport {
    /// Run number, from 1.
    pub run: usize,
    /// File lines of the first point (start position) and of the last block.
    pub lines: [usize; 2],
    /// CL points (blocks + 1).
    pub points: usize,
    /// Path length, mm.
    pub length_mm: f64,
    /// Feed used, mm/min (`null` if none).
    pub feed_mm_min: Option<f64>,
    /// Feed mode: `G94`, or `G93` (inverse time: the feed is each block's length over its
    /// time).
    pub feed_mode: &'static str,
    /// Why this run was not analysed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// The figures (absent when `error` is set).
    #[serde(flatten)]
    pub figures: Option<RunFigures>,
    /// With the machine's kinematic chain and a known work offset: the linear axes in
    /// the machine frame (what the controller moves).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub machine_frame: Option<MachineFrameFigures>,
}

/// Equation 6 on the machine-frame X Y Z of a run ([`crate::machine_frame`]).
#[derive(Debug, Clone, Serialize)]
pub struct MachineFrameFigures {
    /// Work offset used (machine coordinates of the program's zero), mm.
    pub datum_mm: [f64; 3],
    /// Peak speed of X Y Z at the programmed feed, m/min.
    pub peak_speed: BTreeMap<String, f64>,
    /// Lowest ratio of X Y Z.
    pub axis_min_ratio: BTreeMap<String, f64>,
    /// Binding limit of X Y Z at their lowest ratio.
    pub axis_limit: BTreeMap<String, &'static str>,
}

/// The whole analysis document.
#[derive(Debug, Clone, Serialize)]
pub struct AnalyzeReport {
    /// File name.
    pub file: String,
    /// Machine name.
    pub machine: String,
    /// Singular cone used, degrees.
    pub cone_deg: f64,
    /// Pole reach used, degrees ([`polepatch_patcher::pole_dominates`]).
    pub pole_reach_deg: f64,
    /// The tilting letter the program uses as the primary axis (`A` or `B`).
    pub primary: String,
    /// Notes for the user.
    pub warnings: Vec<String>,
    /// Lines carried through without analysis ([`crate::notes`]).
    pub not_analysed: Vec<crate::notes::NotAnalysed>,
    /// Runs in file order (last: the CLI prints the report as it goes).
    pub runs: Vec<RunReport>,
}

impl AnalyzeReport {
    /// What `analyze --strict` counts as a failure: runs that could not be analysed and
    /// lines carried through without analysis.
    pub fn strict_failures(&self) -> usize {
        self.runs.iter().filter(|r| r.error.is_some()).count() + self.not_analysed.len()
    }
}

/// Summarise one analysed run.
pub fn run_figures(lp: &LoadedProgram, r: usize, a: &RunAnalysis) -> RunFigures {
    let pl = lp.primary_letter;
    let s = &lp.runs[r].run.s_mm;
    let k = s
        .partition_point(|&v| v < a.min_s_mm - 1e-9)
        .min(s.len() - 1);
    let mut axis_min_ratio = BTreeMap::new();
    let mut axis_limit = BTreeMap::new();
    let mut peak_speed = BTreeMap::new();
    for axis in Axis::ALL {
        let l = axis_letter(axis, pl);
        axis_min_ratio.insert(l.clone(), a.axis_min[axis.index()].0);
        axis_limit.insert(l.clone(), limit_name(a.axis_min[axis.index()].1));
        peak_speed.insert(l, machine_units(axis, a.peak_speed[axis.index()]));
    }
    RunFigures {
        min_ratio: a.min.ratio,
        limiting_axis: a.min.axis.map(|x| axis_letter(x, pl)),
        limiting_limit: limit_name(a.min.kind),
        min_at_s_mm: a.min_s_mm,
        min_at_line: lp.line_of(r, k),
        axis_min_ratio,
        axis_limit,
        time_s: a.time_s,
        ideal_time_s: a.ideal_time_s,
        peak_speed,
        zones: a
            .zones
            .iter()
            .map(|z| ZoneSummary {
                lines: [lp.line_of(r, z.first), lp.line_of(r, z.last)],
                kind: zone_kind_name(z.kind),
                singular_line: lp.line_of(r, z.singular),
                min_abs_primary_deg: z.min_abs_primary_deg,
                c_ratio_min: z.c_ratio_min,
            })
            .collect(),
    }
}

/// The machine-frame figures of run `r`, when the machine has a chain and the work offset
/// is known.
fn machine_frame_figures(
    lp: &LoadedProgram,
    r: usize,
    path: &polepatch_patcher::Path,
    machine: &Machine,
    opts: &AnalysisOptions,
) -> Option<MachineFrameFigures> {
    let chain = machine.chain.as_ref()?;
    let datum_mm = crate::machine_frame::run_datum(lp, r)?;
    let mp = crate::machine_frame::machine_frame_path(
        chain,
        machine,
        datum_mm,
        lp.runs[r].run.tcpm.is_on(),
        &path.axes,
        &path.s_mm,
        path.feed_mm_min,
    );
    let a = analyze_path(&mp, machine, opts).ok()?;
    let mut f = MachineFrameFigures {
        datum_mm,
        peak_speed: BTreeMap::new(),
        axis_min_ratio: BTreeMap::new(),
        axis_limit: BTreeMap::new(),
    };
    for axis in [Axis::X, Axis::Y, Axis::Z] {
        let l = axis_letter(axis, lp.primary_letter);
        f.peak_speed
            .insert(l.clone(), machine_units(axis, a.peak_speed[axis.index()]));
        f.axis_min_ratio
            .insert(l.clone(), a.axis_min[axis.index()].0);
        f.axis_limit
            .insert(l, limit_name(a.axis_min[axis.index()].1));
    }
    Some(f)
}

/// Analyse every run of a loaded program.
pub fn analyze_program(
    lp: &LoadedProgram,
    machine: &Machine,
    opts: &AnalysisOptions,
) -> AnalyzeReport {
    let runs = lp
        .runs
        .iter()
        .enumerate()
        .map(|(r, rp)| {
            let n = rp.run.len();
            let mut rep = RunReport {
                run: lp.run_number(r),
                lines: [lp.line_of(r, 0), lp.line_of(r, n - 1)],
                points: n,
                length_mm: rp.run.length_mm(),
                // The run's F also when it is not analysed.
                feed_mm_min: rp
                    .path
                    .as_ref()
                    .ok()
                    .map(|p| p.feed_mm_min)
                    .or(rp.run.feed_mm_min),
                feed_mode: crate::patch::feed_mode_name(rp.run.feed_mode),
                error: None,
                figures: None,
                machine_frame: None,
            };
            match &rp.path {
                Err(problem) => rep.error = Some(problem.to_string()),
                Ok(path) => match analyze_path(path, machine, opts) {
                    Ok(a) => {
                        rep.figures = Some(run_figures(lp, r, &a));
                        rep.machine_frame = machine_frame_figures(lp, r, path, machine, opts);
                    }
                    Err(e) => rep.error = Some(e.to_string()),
                },
            }
            rep
        })
        .collect();
    let (not_analysed, notes_warnings) =
        lp.notes
            .finish(lp.primary_index(), opts.reach_deg(), &lp.name);
    AnalyzeReport {
        file: lp.name.clone(),
        machine: machine.name.clone(),
        cone_deg: opts.cone_deg,
        pole_reach_deg: opts.pole_reach_deg,
        primary: (lp.primary_letter as char).to_string(),
        warnings: lp.warnings.iter().cloned().chain(notes_warnings).collect(),
        not_analysed,
        runs,
    }
}

/// A feed for people, mm/min: at most 3 decimals, trailing zeros dropped (`248.92`, not
/// `248.92000000000002`, the inch feed F9.8 × 25.4 as computed).
pub fn feed_text(feed_mm_min: f64) -> String {
    let s = format!("{feed_mm_min:.3}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.to_string() }
}

#[cfg(test)]
mod tests {
    use super::feed_text;

    /// Issue 30 item 9: feeds are printed rounded for people.
    #[test]
    fn feeds_for_people() {
        assert_eq!(feed_text(9.8 * 25.4), "248.92");
        assert_eq!(feed_text(2000.0), "2000");
        assert_eq!(feed_text(78.7 * 2.54), "199.898");
        assert_eq!(feed_text(0.0004), "0");
        assert_eq!(feed_text(1500.5), "1500.5");
    }
}
