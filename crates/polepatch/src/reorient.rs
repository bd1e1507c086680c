//! C17's avoidance: reorient the workpiece on a jig so that the tool orientations move away
//! from the pole, without changing them relative to the part.
//!
//! # Given angles ([`reorient_nc`])
//! For every move with TCPM on, the tool orientation `O_W = forward(P, C)` is rotated,
//! `Ō_W = R_x(θx)·R_z(θz)·O_W` (C17 eq. 7, [`polepatch_kinematics::JigRotation`]), and the
//! new primary and C come from the inverse kinematics, inside the primary range. Branch:
//! for |θx| below [`BRANCH_KEEP_DEG`] every move keeps the program's own branch (its side
//! of the pole), so θ = 0 changes nothing (byte for byte) and a tiny tilt keeps every
//! branch; from it on, the branch nearest to the previous move (continuous, C unwrapped;
//! the first move continues from its own original values). The tool tip is rotated
//! the same way about the pivot (default: the program's origin). Words are written in the
//! file's style with at least [`MIN_DECIMALS`] decimals; a block that relied on a modal
//! value gets a word only where its new value differs from what it now inherits.
//!
//! Explicit rules:
//! - |θx| ≤ [`MAX_THETA_X_DEG`] (90°) and |θz| ≤ [`MAX_THETA_Z_DEG`] (360°), finite;
//!   other angles are refused ([`Error::Options`]);
//! - blocks with TCPM off are machine-coordinate moves (approach, retract, home): left as
//!   they are, and the report lists their lines — check them against the jig;
//! - a program with no move under TCPM is refused (nothing could be reoriented safely);
//! - arcs (G2/G3) under TCPM, incremental mode (G91) and inch programs are refused with the
//!   line; a point whose new primary value leaves the machine's range is refused with the
//!   line; nothing is written then;
//! - datum shifts (`G54 X Y Z`) are not moves and stay: the jig's set-up is the user's.
//!
//! # Search ([`search`])
//! Without angles: the smallest tilt |θx| for which the whole program reaches the
//! programmed feed on both rotary axes by Equation 6 (every run's lowest primary and C
//! ratio ≥ 1, no singular zone), within the primary range. Levels of |θx| are tried in
//! [`SEARCH_STEP_DEG`] steps up to [`SEARCH_MAX_TILT_DEG`], both signs, θz every
//! [`SEARCH_THETA_Z_STEP_DEG`]; at the first level with a feasible candidate the search
//! refines |θx| between the previous level and it in [`SEARCH_REFINE_STEP_DEG`] steps (for
//! the θz that were feasible). Among feasible candidates of the smallest tilt the shortest
//! estimated time (∫ds/ṡ) wins, then the largest distance to the pole. Why this objective:
//! a jig tilt is a set-up cost and changes reach and clearance, so the smallest tilt that
//! does the job is preferred; the time is what the user gains, the pole distance a
//! tie-break margin. Every candidate evaluated is reported.

use crate::analyze::analyze_program;
use crate::error::Error;
use crate::program::LoadedProgram;
use crate::report::AnalyzeReport;
pub use crate::settings::MAX_THETA_X_DEG;
pub use crate::settings::MAX_THETA_Z_DEG;
pub use crate::settings::SEARCH_MAX_TILT_DEG;
pub use crate::settings::SEARCH_REFINE_STEP_DEG;
pub use crate::settings::SEARCH_STEP_DEG;
pub use crate::settings::SEARCH_THETA_Z_STEP_DEG;
use crate::stream::load_nc;
pub use crate::tolerances::BRANCH_KEEP_DEG;
pub use crate::tolerances::MIN_DECIMALS;
use polepatch_kinematics::inverse::unwrap_near_deg;
use polepatch_kinematics::{
    BranchRule, IkSolution, JigRotation, Machine, forward, inverse, inverse_path_from,
};
use polepatch_nc::modal::{X, Y, Z};
use polepatch_nc::{Edit, Motion, NumberStyle};
use polepatch_patcher::AnalysisOptions;
use serde::Serialize;
use std::collections::BTreeMap;

/// A jig tilt.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Tilt {
    /// θx, degrees.
    pub theta_x_deg: f64,
    /// θz, degrees.
    pub theta_z_deg: f64,
    /// Pivot of the positions, mm (program coordinates).
    pub pivot_mm: [f64; 3],
}

/// Figures of a program (before or after).
#[derive(Debug, Clone, Serialize)]
pub struct ProgramFigures {
    /// Least angle between a tool orientation under TCPM and the pole, degrees (= least
    /// |primary|).
    pub min_pole_distance_deg: f64,
    /// Peak speed per axis letter at the programmed feed over all runs: rpm (rotary),
    /// m/min (linear).
    pub peak_speed: BTreeMap<String, f64>,
    /// Lowest feed ratio per axis letter over all runs.
    pub min_ratio: BTreeMap<String, f64>,
    /// Estimated time ∫ds/ṡ over all runs, s.
    pub time_s: f64,
    /// L/F over all runs, s.
    pub ideal_time_s: f64,
    /// Singular zones.
    pub zones: usize,
}

impl ProgramFigures {
    /// Both rotary axes reach feed everywhere and no zone is left.
    pub fn reaches_feed_on_rotary_axes(&self, letters: polepatch_nc::RotaryLetters) -> bool {
        let ratio = |l: u8| self.min_ratio.get(&(l as char).to_string()).copied();
        self.zones == 0
            && ratio(letters.tilt).is_none_or(|r| r >= 1.0)
            && ratio(letters.pole).is_none_or(|r| r >= 1.0)
    }
}

/// One candidate of the search.
#[derive(Debug, Clone, Serialize)]
pub struct Alternative {
    /// θx, degrees.
    pub theta_x_deg: f64,
    /// θz, degrees.
    pub theta_z_deg: f64,
    /// Why it was not taken, or `null` when it is feasible.
    pub rejected: Option<String>,
    /// Lowest primary ratio, C ratio, estimated time (s), least pole distance (°), when
    /// evaluated.
    pub figures: Option<[f64; 4]>,
}

/// What `reorient` reports.
#[derive(Debug, Clone, Serialize)]
pub struct ReorientReport {
    /// Input.
    pub file: String,
    /// Machine.
    pub machine: String,
    /// θx, degrees.
    pub theta_x_deg: f64,
    /// θz, degrees.
    pub theta_z_deg: f64,
    /// Pivot, mm.
    pub pivot_mm: [f64; 3],
    /// Figures before.
    pub before: ProgramFigures,
    /// Figures after.
    pub after: ProgramFigures,
    /// Words changed or inserted.
    pub words_changed: usize,
    /// Lines of moves with TCPM off, left as they are (machine coordinates).
    pub untouched_lines: Vec<usize>,
    /// Candidates the search evaluated (empty for given angles).
    pub alternatives: Vec<Alternative>,
    /// How the angles were chosen.
    pub objective: String,
}

fn refuse(lp: &LoadedProgram, line: usize, what: impl Into<String>) -> Error {
    Error::Unsupported {
        path: lp.name.clone(),
        line,
        what: what.into(),
    }
}

/// The search tilts the jig about X and Z with the pole along the machine's Z, and
/// continues each branch as (P, C) / (−P, C + 180°): the standard form only
/// ([`Machine::standard_form`]); another pair is refused by name.
fn standard_only(machine: &Machine) -> Result<(), Error> {
    if machine.standard_form().is_some() {
        return Ok(());
    }
    Err(Error::machine(
        &machine.name,
        "reorient works on pairs with the pole axis along Z and the tilting axis \
         about X or Y so far (issue 29); this pair has an inclined axis or a tool not along Z \
         at zero",
    ))
}

/// Step 1 of [`reorient_edits`]: the moves under TCPM with their full positions (block,
/// X Y Z P C), and the lines of moves with TCPM off; what cannot be reoriented refused at
/// its line.
#[allow(clippy::type_complexity)]
fn moves_under_tcpm(lp: &LoadedProgram) -> Result<(Vec<(usize, [f64; 5])>, Vec<usize>), Error> {
    let program = &lp.program;
    let (p_idx, c_idx) = (lp.primary_index(), lp.pole_index());
    let mut moves: Vec<(usize, [f64; 5])> = Vec::new();
    let mut untouched = Vec::new();
    for (b, block) in program.blocks.iter().enumerate() {
        if !block.is_move {
            continue;
        }
        let st = program.state(b);
        if !st.tcpm.is_on() {
            untouched.push(block.line);
            continue;
        }
        if matches!(st.motion, Motion::ArcCw | Motion::ArcCcw) {
            return Err(refuse(
                lp,
                block.line,
                "an arc (G2/G3) under TCPM cannot be reoriented (its plane would turn); polepatch reorients G0/G1 programs",
            ));
        }
        if st.incremental {
            return Err(refuse(
                lp,
                block.line,
                "incremental mode (G91) is not supported by reorient",
            ));
        }
        if let Some(w) = program
            .block_words(b)
            .iter()
            .find(|w| w.form.is_directional())
        {
            return Err(refuse(
                lp,
                block.line,
                format!(
                    "{}={}(…) (a Sinumerik direction form) is not supported by reorient",
                    w.letter as char,
                    w.form.name()
                ),
            ));
        }
        if st.inch {
            return Err(refuse(
                lp,
                block.line,
                "inch programs are not supported by reorient",
            ));
        }
        let v = |i: usize| st.pos[i];
        match (v(X), v(Y), v(Z), v(p_idx), v(c_idx)) {
            (Some(x), Some(y), Some(z), Some(p), Some(c)) => moves.push((b, [x, y, z, p, c])),
            _ => {
                return Err(refuse(
                    lp,
                    block.line,
                    "a move under TCPM from a position or rotary value the program does not state",
                ));
            }
        }
    }
    if moves.is_empty() {
        return Err(Error::Unsupported {
            path: lp.name.clone(),
            line: 1,
            what: "no move with TCPM on (M128, TRAORI, G43.4): without it X Y Z are machine \
                   coordinates and a reorientation cannot be computed from the program"
                .into(),
        });
    }
    Ok((moves, untouched))
}

/// The edits that reorient `lp` by `tilt`, and the lines of moves with TCPM off.
pub fn reorient_edits(
    lp: &LoadedProgram,
    machine: &Machine,
    tilt: &Tilt,
) -> Result<(Vec<Edit>, Vec<usize>), Error> {
    let program = &lp.program;
    standard_only(machine)?;
    let rot = JigRotation::new(tilt.theta_x_deg, tilt.theta_z_deg);
    let (moves, untouched) = moves_under_tcpm(lp)?;
    let axes: Vec<[f64; 3]> = moves
        .iter()
        .map(|(_, q)| rot.apply(forward(machine, q[3], q[4])))
        .collect();
    let originals: Vec<IkSolution> = moves
        .iter()
        .map(|(_, q)| IkSolution {
            p_deg: q[3],
            c_deg: q[4],
        })
        .collect();
    let ik = continue_branch(machine, &axes, &originals, tilt);
    let (lo, hi) = machine.primary_range_deg;
    let letters = [b'X', b'Y', b'Z', lp.primary_letter, lp.pole_letter];
    let decimals: Vec<usize> = letters
        .iter()
        .map(|&l| NumberStyle::of(program, l).decimals.max(MIN_DECIMALS))
        .collect();
    let round = |v: f64, d: usize| {
        let k = 10f64.powi(d as i32);
        (v * k).round() / k
    };
    // The new program's modal values, block by block.
    let mut cur: [Option<f64>; 5] = [None; 5];
    let idx_of = |letter: u8| letters.iter().position(|&l| l == letter);
    let mut next_move = 0;
    let mut edits = Vec::new();
    for (b, _) in program.blocks.iter().enumerate() {
        if next_move < moves.len() && moves[next_move].0 == b {
            let (_, q) = moves[next_move];
            let s = ik[next_move];
            next_move += 1;
            if !(s.p_deg.is_finite() && lo <= s.p_deg && s.p_deg <= hi) {
                return Err(refuse(
                    lp,
                    program.blocks[b].line,
                    format!(
                        "the reoriented tool axis needs {}{:.3}, outside the machine's range [{lo}, {hi}]",
                        lp.primary_letter as char, s.p_deg
                    ),
                ));
            }
            let tip = rot.apply_about(tilt.pivot_mm, [q[0], q[1], q[2]]);
            let new = [tip[0], tip[1], tip[2], s.p_deg, s.c_deg];
            for (i, &letter) in letters.iter().enumerate() {
                let target = round(new[i], decimals[i]);
                match program.word(b, letter) {
                    Some(w) => {
                        if w.value != target {
                            edits.push(Edit {
                                block: b,
                                letter,
                                value: target,
                                decimals: decimals[i],
                            });
                        }
                    }
                    None => {
                        if cur[i] != Some(target) {
                            edits.push(Edit {
                                block: b,
                                letter,
                                value: target,
                                decimals: decimals[i],
                            });
                        }
                    }
                }
                cur[i] = Some(target);
            }
        } else {
            // Not reoriented: its own words set the values the next block inherits.
            for w in program.block_words(b) {
                if let Some(i) = idx_of(w.letter) {
                    cur[i] = Some(w.value);
                }
            }
            // Other tilting letter or positions reset by the block: follow the state.
            let st = program.state(b);
            for (i, axis) in [X, Y, Z].into_iter().enumerate() {
                if st.pos[axis].is_none() {
                    cur[i] = None;
                }
            }
        }
    }
    edits.sort_by_key(|e| (e.block, e.letter));
    Ok((edits, untouched))
}

/// The joint values of the reoriented moves: `axes` are the new tool axes, `originals`
/// the program's own values of the same moves.
///
/// - |θx| < [`BRANCH_KEEP_DEG`]: every move keeps the program's branch, the solution whose
///   primary has the sign of the program's own value there, C unwrapped near the
///   program's C turned with the table (`C + sc·θz`). Such a tilt moves no tool axis by
///   more than θx, so a move keeps its side of the pole unless it was that close to it;
///   for θx = 0 the result is exactly `(P, C + sc·θz)` at every move: θ = 0 changes
///   nothing, and the program's own branch changes (a domain-rule flip) stay where they
///   are. On the pole (C does not change the tool axis) a move whose program axis is on
///   the pole too keeps its C turned with the table; any other keeps the previous C.
/// - Otherwise [`inverse_path_from`] the first move's own values, branch
///   [`BranchRule::Nearest`]: each move takes the solution nearest to the move before it,
///   so a tilted path that no longer passes the pole is continuous, whatever flips the
///   program made near the pole.
///
/// In both, a solution outside the primary range gives way to the other one.
fn continue_branch(
    machine: &Machine,
    axes: &[[f64; 3]],
    originals: &[IkSolution],
    tilt: &Tilt,
) -> Vec<IkSolution> {
    if tilt.theta_x_deg.abs() >= BRANCH_KEEP_DEG {
        return inverse_path_from(
            machine,
            axes,
            BranchRule::Nearest,
            originals.first().copied(),
        );
    }
    let (lo, hi) = machine.primary_range_deg;
    let in_range = |s: &IkSolution| lo <= s.p_deg && s.p_deg <= hi;
    let mut out: Vec<IkSolution> = Vec::with_capacity(axes.len());
    for (&o, orig) in axes.iter().zip(originals) {
        let turned_c = orig.c_deg + machine.c_sense * tilt.theta_z_deg;
        let Some(mut cands) = inverse(machine, o) else {
            let orig_on_pole = inverse(machine, forward(machine, orig.p_deg, orig.c_deg)).is_none();
            let c_deg = match out.last() {
                Some(p) if !orig_on_pole && p.c_deg.is_finite() => p.c_deg,
                _ => turned_c,
            };
            let p_deg = match (o[2] < 0.0, orig.p_deg < 0.0) {
                (false, _) => 0.0,
                (true, false) => 180.0,
                (true, true) => -180.0,
            };
            out.push(IkSolution { p_deg, c_deg });
            continue;
        };
        for s in &mut cands {
            s.c_deg = unwrap_near_deg(s.c_deg, turned_c);
        }
        // The program's side of the pole (cands[0] has P > 0, cands[1] P < 0); a program
        // value on the pole: the solution nearest to its C.
        let pick = if orig.p_deg != 0.0 {
            usize::from(orig.p_deg < 0.0)
        } else {
            usize::from((cands[1].c_deg - turned_c).abs() < (cands[0].c_deg - turned_c).abs())
        };
        let pick = if !in_range(&cands[pick]) && in_range(&cands[1 - pick]) {
            1 - pick
        } else {
            pick
        };
        out.push(cands[pick]);
    }
    out
}

/// A feasible candidate of the search: the tilt, the program, its figures, the words
/// changed and the untouched lines.
type Candidate = (Tilt, Vec<u8>, ProgramFigures, usize, Vec<usize>);

/// Figures of a loaded program for the report.
pub fn program_figures(
    lp: &LoadedProgram,
    machine: &Machine,
    opts: &AnalysisOptions,
) -> ProgramFigures {
    let report: AnalyzeReport = analyze_program(lp, machine, opts);
    let mut f = ProgramFigures {
        min_pole_distance_deg: f64::INFINITY,
        peak_speed: BTreeMap::new(),
        min_ratio: BTreeMap::new(),
        time_s: 0.0,
        ideal_time_s: 0.0,
        zones: 0,
    };
    for run in &report.runs {
        let Some(fig) = &run.figures else { continue };
        for (l, v) in &fig.peak_speed {
            let e = f.peak_speed.entry(l.clone()).or_insert(0.0);
            *e = e.max(*v);
        }
        for (l, v) in &fig.axis_min_ratio {
            let e = f.min_ratio.entry(l.clone()).or_insert(f64::INFINITY);
            *e = e.min(*v);
        }
        f.time_s += fig.time_s;
        f.ideal_time_s += fig.ideal_time_s;
        f.zones += fig.zones.len();
    }
    let pi = lp.primary_index();
    for (b, block) in lp.program.blocks.iter().enumerate() {
        let st = lp.program.state(b);
        if block.is_move && st.tcpm.is_on() {
            if let Some(p) = st.pos[pi] {
                f.min_pole_distance_deg = f.min_pole_distance_deg.min(p.abs());
            }
        }
    }
    f
}

/// The analysis options of a cone, checked; and the pivot, checked.
fn analysis_options(cone_deg: f64, pivot_mm: [f64; 3]) -> Result<AnalysisOptions, Error> {
    crate::options::positive("cone_deg", "degrees", cone_deg)?;
    if pivot_mm.iter().any(|v| !v.is_finite()) {
        return Err(crate::error::OptionError::new(
            "pivot_mm",
            format_args!("must be three finite numbers of mm, got {pivot_mm:?}"),
        )
        .into());
    }
    Ok(AnalysisOptions {
        cone_deg,
        ..AnalysisOptions::default()
    })
}

/// Reorient a program held in memory by `tilt`: the new bytes (only the changed or
/// inserted words differ) and the report.
pub fn reorient_nc(
    bytes: &[u8],
    machine: &Machine,
    tilt: &Tilt,
    name: &str,
    cone_deg: f64,
) -> Result<(Vec<u8>, ReorientReport), Error> {
    check_tilt(tilt)?;
    standard_only(machine)?;
    let opts = analysis_options(cone_deg, tilt.pivot_mm)?;
    let lp = load_nc(bytes, name, machine, None)?;
    let before = program_figures(&lp, machine, &opts);
    let (out, after, words, untouched) = apply(&lp, machine, tilt, &opts)?;
    let report = ReorientReport {
        file: name.to_string(),
        machine: machine.name.clone(),
        theta_x_deg: tilt.theta_x_deg,
        theta_z_deg: tilt.theta_z_deg,
        pivot_mm: tilt.pivot_mm,
        before,
        after,
        words_changed: words,
        untouched_lines: untouched,
        alternatives: Vec::new(),
        objective: "given angles".into(),
    };
    Ok((out, report))
}

/// The angles of a tilt within the accepted ranges (module docs).
pub fn check_tilt(tilt: &Tilt) -> Result<(), Error> {
    for (name, v, max) in [
        ("θx", tilt.theta_x_deg, MAX_THETA_X_DEG),
        ("θz", tilt.theta_z_deg, MAX_THETA_Z_DEG),
    ] {
        if !(v.is_finite() && v.abs() <= max) {
            return Err(crate::error::OptionError::new(
                name,
                format_args!("= {v:?}° is outside the accepted range −{max}° to {max}°"),
            )
            .into());
        }
    }
    if tilt.pivot_mm.iter().any(|v| !v.is_finite()) {
        return Err(crate::error::OptionError::with_message(
            "pivot_mm",
            format!("the pivot {:?} mm must be finite", tilt.pivot_mm),
        )
        .into());
    }
    Ok(())
}

/// Reorient and analyse the result: (bytes, figures after, words changed, untouched lines).
fn apply(
    lp: &LoadedProgram,
    machine: &Machine,
    tilt: &Tilt,
    opts: &AnalysisOptions,
) -> Result<(Vec<u8>, ProgramFigures, usize, Vec<usize>), Error> {
    let (edits, untouched) = reorient_edits(lp, machine, tilt)?;
    let out = polepatch_nc::write(&lp.program, &edits);
    let lp2 = load_nc(&out, &lp.name, machine, None)?;
    let after = program_figures(&lp2, machine, opts);
    Ok((out, after, edits.len(), untouched))
}

/// Find the smallest jig tilt that makes the program reach feed on both rotary axes
/// (module docs), and reorient by it. A search that finds no such tilt is an
/// [`Error::Unsupported`] naming the largest tilt tried (nothing is written).
pub fn search(
    bytes: &[u8],
    machine: &Machine,
    pivot_mm: [f64; 3],
    name: &str,
    cone_deg: f64,
) -> Result<(Vec<u8>, ReorientReport), Error> {
    standard_only(machine)?;
    let opts = analysis_options(cone_deg, pivot_mm)?;
    let lp = load_nc(bytes, name, machine, None)?;
    let before = program_figures(&lp, machine, &opts);
    let letters = lp.letters();
    let mut alternatives: Vec<Alternative> = Vec::new();
    let evaluate = |tx: f64, tz: f64, alts: &mut Vec<Alternative>| {
        let tilt = Tilt {
            theta_x_deg: tx,
            theta_z_deg: tz,
            pivot_mm,
        };
        match apply(&lp, machine, &tilt, &opts) {
            Ok((out, after, words, untouched)) => {
                let ok = after.reaches_feed_on_rotary_axes(letters);
                let (pl, cl) = (
                    (letters.tilt as char).to_string(),
                    (letters.pole as char).to_string(),
                );
                alts.push(Alternative {
                    theta_x_deg: tx,
                    theta_z_deg: tz,
                    rejected: (!ok).then(|| "does not reach feed on the rotary axes".to_string()),
                    figures: Some([
                        after.min_ratio.get(&pl).copied().unwrap_or(1.0),
                        after.min_ratio.get(&cl).copied().unwrap_or(1.0),
                        after.time_s,
                        after.min_pole_distance_deg,
                    ]),
                });
                ok.then_some((tilt, out, after, words, untouched))
            }
            Err(e) => {
                alts.push(Alternative {
                    theta_x_deg: tx,
                    theta_z_deg: tz,
                    rejected: Some(e.to_string()),
                    figures: None,
                });
                None
            }
        }
    };
    let better = |a: &ProgramFigures, b: &ProgramFigures| {
        (a.time_s, -a.min_pole_distance_deg) < (b.time_s, -b.min_pole_distance_deg)
    };
    let n_z = (360.0 / SEARCH_THETA_Z_STEP_DEG).round() as usize;
    let mut found = None;
    let mut prev_level = 0.0;
    let mut level = SEARCH_STEP_DEG;
    while level <= SEARCH_MAX_TILT_DEG + 1e-9 && found.is_none() {
        let mut feasible_z: Vec<f64> = Vec::new();
        for k in 0..n_z {
            let tz = k as f64 * SEARCH_THETA_Z_STEP_DEG;
            for tx in [level, -level] {
                if evaluate(tx, tz, &mut alternatives).is_some() {
                    feasible_z.push(tz);
                }
            }
        }
        if !feasible_z.is_empty() {
            feasible_z.dedup();
            // Refine |θx| between the previous level and this one.
            let steps = ((level - prev_level) / SEARCH_REFINE_STEP_DEG).round() as usize;
            'refine: for s in 1..=steps {
                let mag = prev_level + s as f64 * SEARCH_REFINE_STEP_DEG;
                let mut best: Option<Candidate> = None;
                for &tz in &feasible_z {
                    for tx in [mag, -mag] {
                        if let Some(c) = evaluate(tx, tz, &mut alternatives)
                            && best.as_ref().is_none_or(|b| better(&c.2, &b.2))
                        {
                            best = Some(c);
                        }
                    }
                }
                if best.is_some() {
                    found = best;
                    break 'refine;
                }
            }
        }
        prev_level = level;
        level += SEARCH_STEP_DEG;
    }
    let Some((tilt, out, after, words, untouched)) = found else {
        return Err(Error::Unsupported {
            path: name.to_string(),
            line: 1,
            what: format!(
                "no jig tilt up to {SEARCH_MAX_TILT_DEG}° makes the program reach feed on both \
                 rotary axes within the primary range ({} candidates tried)",
                alternatives.len()
            ),
        });
    };
    let report = ReorientReport {
        file: name.to_string(),
        machine: machine.name.clone(),
        theta_x_deg: tilt.theta_x_deg,
        theta_z_deg: tilt.theta_z_deg,
        pivot_mm,
        before,
        after,
        words_changed: words,
        untouched_lines: untouched,
        alternatives,
        objective: "smallest |θx| reaching feed on both rotary axes; then shortest time; then \
                    largest pole distance"
            .into(),
    };
    Ok((out, report))
}

/// The tool orientations under TCPM in the part frame (for the sphere plot).
pub fn tool_axes(lp: &LoadedProgram, machine: &Machine) -> Vec<[f64; 3]> {
    let (pi, ci) = (lp.primary_index(), lp.pole_index());
    (0..lp.program.blocks.len())
        .filter(|&b| lp.program.blocks[b].is_move)
        .filter_map(|b| {
            let st = lp.program.state(b);
            (st.tcpm.is_on())
                .then(|| Some(forward(machine, st.pos[pi]?, st.pos[ci]?)))
                .flatten()
        })
        .collect()
}

/// The pole of the machine (P = 0) seen in the part frame after the tilt: `Rᵀ·ẑ`.
pub fn pole_after(tilt: &Tilt) -> [f64; 3] {
    JigRotation::new(tilt.theta_x_deg, tilt.theta_z_deg).apply_inverse([0.0, 0.0, 1.0])
}
