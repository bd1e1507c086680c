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
    report: SimulateReport,
    on_state: Option<&'f mut dyn FnMut(&SimState)>,
    t0_s: f64,
    s0_mm: f64,
}

impl Simulating<'_, '_> {
    fn take(&mut self, run: RunIn) {
        let joins = self.chain.last().is_some_and(|prev| {
            prev.feed_change_after
                && prev.path.is_some()
                && run.path.is_some()
                && prev.row.lines[1] == run.row.lines[0]
                && prev.row.frame == run.row.frame
                && prev.path.as_ref().and_then(|p| p.axes.last())
                    == run.path.as_ref().map(|p| &p.axes[0])
        });
        if !joins {
            self.flush();
        }
        if run.path.is_none() {
            self.report.runs.push(run.row);
            return;
        }
        self.chain.push(run);
        if joins && let Some(r) = self.chain.last_mut() {
            r.row.joined = true;
        }
    }

    fn flush(&mut self) {
        if self.chain.is_empty() {
            return;
        }
        let mut chain = std::mem::take(&mut self.chain);
        let parts: Vec<Path> = chain.iter_mut().filter_map(|r| r.path.take()).collect();
        let runs: Vec<usize> = chain.iter().map(|r| r.row.run).collect();
        let (t0, s0) = (self.t0_s, self.s0_mm);
        let machine = self.machine;
        let mut sim_opts = self.opts.sim.clone();
        let mut user = self.on_state.take();
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
        self.on_state = user;
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
                    let t = &mut self.report.total;
                    t.time_s += ps.time_s;
                    t.eq6_time_s += ps.eq6_time_s;
                    t.ideal_time_s += ps.ideal_time_s;
                    t.runs += 1;
                }
                self.report.total.clips += sim.clips;
                self.t0_s += sim.time_s;
                self.s0_mm += acc;
            }
            Err(e) => {
                for r in &mut chain {
                    r.row.error = Some(e.to_string());
                }
            }
        }
        self.report.runs.extend(chain.into_iter().map(|r| r.row));
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
            for r in runs {
                sim.take(r);
            }
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
}
