//! The cycle time of a program: every run simulated as a jerk-limited controller would
//! move ([`polepatch_simulate`]), next to Equation 6's estimate and L/F.
//!
//! The program is read as `analyze` reads it (the one reader: every run a stretch,
//! the same runs and paths). Runs that follow one another without a stop — a feed change
//! between them, which makes them share a point — are one motion; every other break (a
//! G0/G2/G3 move, a stop, a TCPM switch, a tool change, a block without tool-tip motion,
//! the end) is a rest. With a machine's `[chain]` and a known work offset the axes are the
//! machine's (X Y Z in the machine frame, [`crate::machine_frame`]); else the program's
//! (under TCPM the tool tip in the part frame with the rotary axes following). Blocks
//! without tool-tip motion, rapid moves and arcs are not simulated: the times are those
//! of the G1 runs.

use crate::error::Error;
pub use crate::options::SimulateOptions;
use crate::report::{SimFrame, SimRun, SimTotals, SimulateReport};
use polepatch_kinematics::Machine;
use polepatch_nc::RunBreak;
use polepatch_patcher::Path;
use polepatch_simulate::{Geometry, Step, simulate};

/// What a program without G1 motion reports ([`SimulateReport::nothing_to_simulate`]).
pub const NO_G1_MOTION: &str = "the program has no G1 motion: rapid moves (G0), arcs and \
     blocks without tool-tip motion are not simulated";

/// One state of the simulated motion, for a trajectory or a plot.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimState {
    /// Run number, from 1.
    pub run: usize,
    /// Time from the start of the first simulated run (simulated runs only), s.
    pub t_s: f64,
    /// s from the start of the run, mm.
    pub s_mm: f64,
    /// s from the start of the first run, summed over the simulated runs, mm.
    pub s_total_mm: f64,
    /// Axis values X Y Z P C (mm, degrees) at this state.
    pub axes: [f64; 5],
    /// Feed, mm/min.
    pub feed_mm_min: f64,
    /// Each axis' use of its limits: the largest of |q̇|/V, |q̈|/A, |q⃛|/J.
    pub shares: [f64; 5],
    /// One interpolation cycle after the state before (false: a run's first state, its
    /// last partial cycle, or a jumped cruise).
    pub cycle: bool,
}

/// What the per-run reading keeps of a run.
struct RunIn {
    row: SimRun,
    point_lines: Vec<usize>,
    path: Option<Path>,
    feed_change_after: bool,
}

/// What the simulation keeps of a run read ([`crate::stream::each_run`]): the run itself
/// is dropped before its path is turned into the machine's frame (peak memory).
fn run_input(rr: crate::stream::RunRead, machine: &Machine) -> RunIn {
    let crate::stream::RunRead {
        number,
        run,
        path,
        point_lines,
        datum_mm,
    } = rr;
    let n = run.len();
    let mut row = SimRun {
        run: number,
        lines: [point_lines[0], point_lines[n - 1]],
        points: n,
        length_mm: run.length_mm(),
        feed_mm_min: path
            .as_ref()
            .ok()
            .map(|p| p.feed_mm_min)
            .or(run.feed_mm_min),
        error: None,
        time_s: 0.0,
        eq6_time_s: 0.0,
        ideal_time_s: 0.0,
        min_feed_mm_min: None,
        min_feed_line: None,
        joined: false,
        frame: SimFrame::Program,
    };
    let tcpm_on = run.tcpm.is_on();
    let feed_change_after = run.ended_by == RunBreak::FeedChange;
    drop(run);
    let path = match path {
        Err(problem) => {
            row.error = Some(problem.to_string());
            None
        }
        Ok(path) => {
            let frame = machine.chain.as_ref().and_then(|chain| {
                let datum = datum_mm?;
                Some(crate::machine_frame::machine_frame_path(
                    chain,
                    machine,
                    datum,
                    tcpm_on,
                    &path.axes,
                    &path.s_mm,
                    path.feed_mm_min,
                ))
            });
            if frame.is_some() {
                row.frame = SimFrame::Machine;
            }
            Some(frame.unwrap_or(path))
        }
    };
    RunIn {
        row,
        point_lines,
        path,
        feed_change_after,
    }
}

/// The simulation in progress: the motion being gathered and the report.
struct Simulating<'a, 'f> {
    machine: &'a Machine,
    opts: &'a SimulateOptions,
    chain: Vec<RunIn>,
    /// Complete motions (and rows) waiting to be simulated together ([`Self::take_all`]).
    ready: Vec<Item>,
    /// The path points of `ready`.
    ready_points: usize,
    report: SimulateReport,
    on_state: Option<&'f mut dyn FnMut(&SimState)>,
    t0_s: f64,
    s0_mm: f64,
}

/// A piece of the report in file order: a motion to simulate (runs that follow one
/// another without a stop), or the row of a run with nothing to simulate.
enum Item {
    Motion(Vec<RunIn>),
    Row(SimRun),
}

impl Item {
    /// The path points it holds.
    fn points(&self) -> usize {
        match self {
            Item::Motion(m) => m.iter().map(|r| r.row.points).sum(),
            Item::Row(_) => 0,
        }
    }
}

/// Without a state callback, complete motions wait until they hold this many path points
/// together (or the program ends) and are then simulated on all cores: few enough to
/// bound what waits, enough to share out (a longer motion is simulated alone, its plan
/// on all cores).
const MOTIONS_AT_ONCE_POINTS: usize = 20_000;

/// A motion simulated: its runs' rows with their figures (or the error), and what the
/// totals take from it.
struct Simulated {
    rows: Vec<SimRun>,
    /// `(time, length)` of the motion, s and mm, when it simulated.
    ok: Option<(f64, f64)>,
    clips: usize,
}

impl Simulating<'_, '_> {
    /// The runs of one batch of the reading, in file order. Without a state callback the
    /// motions the batch completes are simulated on all cores and taken in order (each
    /// motion's figures do not depend on the others', and the totals are summed in file
    /// order: the same report as one by one); with one, one by one as they complete.
    fn take_all(&mut self, runs: Vec<RunIn>) {
        for run in runs {
            let mut items = std::mem::take(&mut self.ready);
            let before = items.len();
            self.gather(run, &mut items);
            self.ready_points += items[before..].iter().map(Item::points).sum::<usize>();
            self.ready = items;
            if self.on_state.is_some() || self.ready_points >= MOTIONS_AT_ONCE_POINTS {
                let items = std::mem::take(&mut self.ready);
                self.ready_points = 0;
                self.settle(items);
            }
        }
    }

    /// Add a run to the motion being gathered; what it completes goes to `items`.
    fn gather(&mut self, run: RunIn, items: &mut Vec<Item>) {
        let joins = self.chain.last().is_some_and(|prev| {
            prev.feed_change_after
                && prev.path.is_some()
                && run.path.is_some()
                && prev.row.lines[1] == run.row.lines[0]
                && prev.row.frame == run.row.frame
                && prev.path.as_ref().and_then(|p| p.axes.last())
                    == run.path.as_ref().map(|p| &p.axes[0])
        });
        if !joins && !self.chain.is_empty() {
            items.push(Item::Motion(std::mem::take(&mut self.chain)));
        }
        if run.path.is_none() {
            items.push(Item::Row(run.row));
            return;
        }
        self.chain.push(run);
        if joins && let Some(r) = self.chain.last_mut() {
            r.row.joined = true;
        }
    }

    /// Simulate what is left: the motions waiting and the one being gathered (the end of
    /// the program).
    fn flush(&mut self) {
        let mut items = std::mem::take(&mut self.ready);
        self.ready_points = 0;
        if !self.chain.is_empty() {
            items.push(Item::Motion(std::mem::take(&mut self.chain)));
        }
        self.settle(items);
    }

    /// Simulate `items`' motions and put them in the report, in order.
    fn settle(&mut self, items: Vec<Item>) {
        let (machine, opts) = (self.machine, self.opts);
        let motions = items
            .iter()
            .filter(|i| matches!(i, Item::Motion(_)))
            .count();
        if self.on_state.is_none() && motions > 1 {
            use rayon::prelude::*;
            let done: Vec<Simulated> = items
                .into_par_iter()
                .map(|i| match i {
                    Item::Motion(m) => simulate_motion(m, machine, opts, None, 0.0, 0.0),
                    // A row alone: taken as it is, into no total.
                    Item::Row(r) => Simulated {
                        rows: vec![r],
                        ok: None,
                        clips: 0,
                    },
                })
                .collect();
            for d in done {
                self.record(d);
            }
            return;
        }
        for i in items {
            match i {
                Item::Motion(m) => {
                    let mut user = self.on_state.take();
                    let (t0, s0) = (self.t0_s, self.s0_mm);
                    let sim = simulate_motion(m, machine, opts, user.as_deref_mut(), t0, s0);
                    self.on_state = user;
                    self.record(sim);
                }
                Item::Row(r) => self.report.runs.push(r),
            }
        }
    }

    /// A simulated motion's rows and totals.
    fn record(&mut self, sim: Simulated) {
        if let Some((time_s, length_mm)) = sim.ok {
            for row in &sim.rows {
                let t = &mut self.report.total;
                t.time_s += row.time_s;
                t.eq6_time_s += row.eq6_time_s;
                t.ideal_time_s += row.ideal_time_s;
                t.runs += 1;
            }
            self.report.total.clips += sim.clips;
            self.t0_s += time_s;
            self.s0_mm += length_mm;
        }
        self.report.runs.extend(sim.rows);
    }
}

/// Simulate one motion (`chain`, its runs), handing its states to `user` (times from
/// `t0`, s from `s0`).
fn simulate_motion<'f>(
    mut chain: Vec<RunIn>,
    machine: &Machine,
    opts: &SimulateOptions,
    mut user: Option<&mut (dyn FnMut(&SimState) + 'f)>,
    t0: f64,
    s0: f64,
) -> Simulated {
    let parts: Vec<Path> = chain.iter_mut().filter_map(|r| r.path.take()).collect();
    let runs: Vec<usize> = chain.iter().map(|r| r.row.run).collect();
    let mut sim_opts = opts.sim.clone();
    sim_opts.every_cycle &= user.is_some();
    let mut part_start_s = vec![0.0; parts.len()];
    let mut acc = 0.0;
    for (k, p) in parts.iter().enumerate() {
        part_start_s[k] = acc;
        acc += p.s_mm[p.s_mm.len() - 1] - p.s_mm[0];
    }
    let result = {
        let mut sink = |st: &Step, geo: &Geometry| {
            if let Some(f) = user.as_mut() {
                let d = geo.derivs(st.s_mm);
                let shares = polepatch_simulate::caps::shares(
                    machine,
                    &d,
                    st.feed_mm_s,
                    st.accel_mm_s2,
                    st.jerk_mm_s3,
                );
                f(&SimState {
                    run: runs[st.part],
                    t_s: t0 + st.t_s,
                    s_mm: st.s_mm - part_start_s[st.part],
                    s_total_mm: s0 + st.s_mm,
                    axes: d.map(|e| e[0]),
                    feed_mm_min: st.feed_mm_s * 60.0,
                    shares,
                    cycle: st.cycle,
                });
            }
        };
        simulate(&parts, machine, &sim_opts, &mut sink)
    };
    drop(parts);
    match result {
        Ok(sim) => {
            for (r, ps) in chain.iter_mut().zip(&sim.parts) {
                r.row.time_s = ps.time_s;
                r.row.eq6_time_s = ps.eq6_time_s;
                r.row.ideal_time_s = ps.ideal_time_s;
                if let Some(m) = ps.min_feed {
                    r.row.min_feed_mm_min = Some(m.feed_mm_s * 60.0);
                    r.row.min_feed_line = r.point_lines.get(m.point).copied();
                }
            }
            Simulated {
                rows: chain.into_iter().map(|r| r.row).collect(),
                ok: Some((sim.time_s, acc)),
                clips: sim.clips,
            }
        }
        Err(e) => {
            for r in &mut chain {
                r.row.error = Some(e.to_string());
            }
            Simulated {
                rows: chain.into_iter().map(|r| r.row).collect(),
                ok: None,
                clips: 0,
            }
        }
    }
}

/// Simulate every run of an NC program held in memory (module docs).
pub fn simulate_nc(
    bytes: &[u8],
    machine: &Machine,
    opts: &SimulateOptions,
) -> Result<SimulateReport, Error> {
    simulate_nc_with(bytes, machine, opts, None)
}

/// [`simulate_nc`], handing every state of the motion to `on_state` (every interpolation
/// cycle when `opts.sim.every_cycle`), in order, as it is computed: a trajectory is
/// written as it goes, never held.
pub fn simulate_nc_with(
    bytes: &[u8],
    machine: &Machine,
    opts: &SimulateOptions,
    on_state: Option<&mut dyn FnMut(&SimState)>,
) -> Result<SimulateReport, Error> {
    simulate_bytes(std::borrow::Cow::Borrowed(bytes), machine, opts, on_state)
}

/// [`simulate_nc_with`] taking the program's bytes: they are freed once read, before the
/// last motion is simulated (a program of one long run is simulated without its file in
/// memory).
pub fn simulate_nc_owned(
    bytes: Vec<u8>,
    machine: &Machine,
    opts: &SimulateOptions,
    on_state: Option<&mut dyn FnMut(&SimState)>,
) -> Result<SimulateReport, Error> {
    simulate_bytes(std::borrow::Cow::Owned(bytes), machine, opts, on_state)
}

/// [`simulate_nc_with`] and [`simulate_nc_owned`]: owned bytes dropped once read.
fn simulate_bytes(
    bytes: std::borrow::Cow<'_, [u8]>,
    machine: &Machine,
    opts: &SimulateOptions,
    on_state: Option<&mut dyn FnMut(&SimState)>,
) -> Result<SimulateReport, Error> {
    let tcy_s = opts.sim.tcy_s.unwrap_or(machine.tcy_s);
    let mut sim = Simulating {
        machine,
        opts,
        chain: Vec::new(),
        ready: Vec::new(),
        ready_points: 0,
        report: SimulateReport {
            file: opts.read.name.clone(),
            machine: machine.name.clone(),
            tcy_s,
            primary: String::new(),
            warnings: Vec::new(),
            nothing_to_simulate: None,
            runs: Vec::new(),
            total: SimTotals::default(),
        },
        on_state,
        t0_s: 0.0,
        s0_mm: 0.0,
    };
    let reading = crate::options::AnalyzeOptions {
        read: opts.read.clone(),
        ..crate::options::AnalyzeOptions::default()
    };
    let read = crate::stream::each_run(
        &bytes,
        machine,
        &reading,
        |rr| run_input(rr, machine),
        |runs| {
            sim.take_all(runs);
            Ok(())
        },
    );
    let primary = match read {
        Ok(p) => p,
        // A program without G1 motion has nothing to simulate: said as the result, not
        // as a failure of whatever output was asked for.
        Err(Error::NoRuns { .. }) => {
            sim.report.primary = machine.primary_letter().to_string();
            sim.report.nothing_to_simulate = Some(NO_G1_MOTION.to_string());
            return Ok(sim.report);
        }
        Err(e) => return Err(e),
    };
    // Read: the last motion is simulated without the file (peak memory).
    drop(bytes);
    sim.flush();
    sim.report.primary = primary.to_string();
    Ok(sim.report)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The program's bytes handed over (freed once read) or lent give the same report and
    /// the same states: on a program of several motions, and on one whose last motion is
    /// simulated after the file is dropped.
    #[test]
    fn owned_bytes_simulate_as_borrowed_ones() {
        let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
        let machine = Machine::builtin("mikron-ucp710").expect("built-in machine");
        for file in ["fixtures/c17/SING.I", "fixtures/c17/NON_SING.I"] {
            let bytes = std::fs::read(root.join(file)).expect("fixture");
            let mut opts = SimulateOptions::default();
            opts.sim.every_cycle = true;
            let (mut lent, mut owned) = (Vec::new(), Vec::new());
            let a = simulate_nc_with(&bytes, &machine, &opts, Some(&mut |s| lent.push(*s)));
            let b = simulate_nc_owned(bytes, &machine, &opts, Some(&mut |s| owned.push(*s)));
            let (a, b) = (a.expect("simulates"), b.expect("simulates"));
            assert!(!a.runs.is_empty(), "{file}");
            assert_eq!(a, b, "{file}");
            assert!(!lent.is_empty() && lent == owned, "{file}");
        }
    }

    /// Motions simulated side by side (no state callback) report what they report one by
    /// one in order (a callback): a program of 30 motions, 30 000 points in all (more
    /// than wait together, so motions are settled both along the way and at the end), with
    /// a run that has nothing to simulate (a feed too low) among them, its row in place.
    #[test]
    fn motions_side_by_side_report_as_one_by_one() {
        use std::fmt::Write as _;
        let mut p = String::from("%\nO1000\nG90 G21 G94\nT1 M6\nS1000 M3\nG43.4 H1\n");
        for m in 0..30 {
            let y = 5.0 * f64::from(m);
            let f = if m == 12 { "F0.00001" } else { "F1000" };
            writeln!(p, "G0 X0 Y{y} Z5 A10 C{}", 2 * m).unwrap();
            writeln!(p, "G1 Z0 {f}").unwrap();
            for i in 1..=1000 {
                writeln!(
                    p,
                    "X{:.1} Y{:.3}",
                    0.1 * f64::from(i),
                    y + 0.2 * (0.01 * f64::from(i)).sin()
                )
                .unwrap();
            }
            writeln!(p, "G0 Z5").unwrap();
        }
        p.push_str("M30\n%\n");
        const { assert!(30 * 1000 > MOTIONS_AT_ONCE_POINTS) };
        let machine = Machine::builtin("mikron-ucp710").expect("built-in machine");
        let opts = SimulateOptions::default();
        let side = simulate_nc(p.as_bytes(), &machine, &opts).expect("simulates");
        let mut states = 0usize;
        let one = simulate_nc_with(p.as_bytes(), &machine, &opts, Some(&mut |_| states += 1))
            .expect("simulates");
        assert!(states > 0);
        assert_eq!(side, one);
        assert!(side.total.runs >= 29, "{:?}", side.total);
        let rows: Vec<_> = side.runs.iter().map(|r| r.error.is_some()).collect();
        assert_eq!(rows.iter().filter(|&&e| e).count(), 1, "{rows:?}");
        assert!(side.runs.windows(2).all(|w| w[0].run < w[1].run));
    }
}
