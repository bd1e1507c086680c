//! Equation-6 analysis of one run with the analysis spline (SPEC §2), and detection of
//! singular zones (SPEC §3 step 2).
//!
//! # Bounded work: per span, not per F·Tcy
//! The run is analysed span by span (a span is the stretch between two consecutive CL
//! points), never sample by sample:
//! - **Equation 6** on a span uses the exact largest `|q'|`, `|q''|`, `|q'''|` of each axis
//!   over the span ([`crate::spline::SpanCubic::peaks`]): one evaluation per span and axis.
//!   The span's ratio is then the exact lowest ratio over the span, which is at most the
//!   lowest ratio over SPEC §2's samples every F·Tcy (the maximum over the span is at least
//!   the maximum over any sample set): at least as strict, for any Tcy.
//! - **Time** ∫ds/ṡ over a span is exactly h/F when the span reaches feed everywhere (its
//!   lowest ratio is 1). Otherwise the integrand `1/ṡ(s) = max(1/F, max over axes and terms
//!   |q'|/V, √(|q''|/A), ∛(|q'''|/J))` is integrated by the trapezoidal rule on an adaptive
//!   bisection of the span: on each piece `[a, b]` it lies between the Equation-6 values of
//!   the exact smallest and the exact largest derivative sizes over the piece
//!   ([`crate::spline::SpanCubic::abs_range`]; each term is increasing in its derivative's
//!   size), and so do the trapezoid and the exact integral: the piece's error is at most
//!   `(upper − lower)·(b − a)`. A piece is bisected while that exceeds
//!   [`TIME_REL_TOL`] of its time, at most [`TIME_MAX_DEPTH`] times. The sum of those bounds
//!   is [`RunAnalysis::time_error_s`], a rigorous bound on the estimate's error.
//!
//! Work per span is therefore at most `2^TIME_MAX_DEPTH + 1` evaluations of Equation 6, and
//! one on a span at feed: bounded by the number of blocks, whatever the feed and the
//! length of the blocks ([`RunAnalysis::evaluations`] counts them). Memory is one running
//! reduction (and one record per span for [`analyze_spans`]).

use crate::path::{Path, PathError};
use crate::spline::{AnalysisSpline, SpanCubic, SplineSystem};
use crate::tolerances::{RATIO_TOL, TIME_MAX_DEPTH, TIME_REL_TOL};
use polepatch_kinematics::{
    Axis, FeedBound, LimitKind, Machine, PoleDistance, axis_feed_bound, feed_bound,
};

pub use crate::settings::{CONE_DEG, POLE_REACH_DEG};

/// Options of [`analyze_path`].
#[derive(Debug, Clone, PartialEq)]
pub struct AnalysisOptions {
    /// Singular cone: a stretch below feed with a point with |primary| ≤ this is a zone,
    /// degrees. Default [`CONE_DEG`] (5).
    pub cone_deg: f64,
    /// Pole reach, degrees: a stretch below feed whose closest point to the pole lies
    /// between the cone and this is a zone when the pole dominates its slowdown
    /// ([`pole_dominates`]); at or below `cone_deg`, only the cone counts. Default
    /// [`POLE_REACH_DEG`] (10).
    pub pole_reach_deg: f64,
    /// Interpolation cycle time override, seconds; `None` uses the machine's `tcy_s`. It
    /// does not change any figure: Equation 6 is bounded exactly over every span, which is
    /// at least as strict as sampling every F·Tcy for any Tcy (module docs). Kept for the
    /// callers that pass it (the C ABI's `PpOptions::tcy_ms`).
    pub tcy_s: Option<f64>,
    /// Keep the evaluation points in [`RunAnalysis::samples`] (for plots). Default false.
    pub keep_samples: bool,
}

impl Default for AnalysisOptions {
    fn default() -> Self {
        AnalysisOptions {
            cone_deg: CONE_DEG,
            pole_reach_deg: POLE_REACH_DEG,
            tcy_s: None,
            keep_samples: false,
        }
    }
}

impl AnalysisOptions {
    /// How far from the pole a zone can lie, degrees: the larger of the cone and the pole
    /// reach. A run with no point this close holds no zone.
    pub fn reach_deg(&self) -> f64 {
        self.cone_deg.max(self.pole_reach_deg)
    }
}

/// Kind of singular zone.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ZoneKind {
    /// The primary axis changes sign near zero (domain-rule posts, G16): C jumps up to 180°.
    AFlip,
    /// The primary axis keeps its sign and C swings fast near the pole (C17 `%SING`).
    CSwing,
}

impl ZoneKind {
    /// The name used in the text reports of `polepatch`: `A-flip`, `C-swing` (the JSON
    /// reports write `a_flip`, `c_swing`, as every report enum, in snake_case).
    pub fn name(self) -> &'static str {
        match self {
            ZoneKind::AFlip => "A-flip",
            ZoneKind::CSwing => "C-swing",
        }
    }
}

impl std::fmt::Display for ZoneKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A singular zone: where the C-limited ratio is below 1 because the tool axis passes near
/// the pole ([`detect_zones`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Zone {
    /// First point index of the zone (the point before the first sample with ratio < 1).
    pub first: usize,
    /// Last point index of the zone.
    pub last: usize,
    /// Index of the singular point (the point of least |primary|; for an A flip the point
    /// just before the sign change).
    pub singular: usize,
    /// Kind.
    pub kind: ZoneKind,
    /// Smallest |primary| over the zone's points, degrees.
    pub min_abs_primary_deg: f64,
    /// Smallest C-limited Equation-6 ratio over the zone.
    pub c_ratio_min: f64,
    /// C stays below feed before the zone's first point, where the pole does not dominate
    /// its slowdown (the program's own, [`detect_zones`]): the zone was cut there from a
    /// longer stretch, and its core takes no margin on that side ([`crate::zone_core`]).
    pub cut_before: bool,
    /// The same after the zone's last point.
    pub cut_after: bool,
}

/// One point where Equation 6 was evaluated (a span's start, or a piece of its time
/// integral).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Path parameter, mm.
    pub s_mm: f64,
    /// Per-axis ratio min(1, bound/F) in axis order.
    pub axis_ratio: [f64; 5],
    /// Overall bound here.
    pub bound: FeedBound,
}

/// Equation 6 over one span (exact over the span, module docs) and its time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpanFigures {
    /// Lowest ratio min(1, bound/F) of each axis over the span, axis order.
    pub axis_ratio: [f64; 5],
    /// The limit binding each axis' lowest ratio.
    pub axis_kind: [LimitKind; 5],
    /// The lowest overall bound over the span.
    pub bound: FeedBound,
    /// Where it is reached, mm.
    pub min_s_mm: f64,
    /// Estimated time ∫ds/ṡ over the span, s.
    pub time_s: f64,
    /// Bound on the error of `time_s`, s.
    pub time_error_s: f64,
}

/// Result of analysing one run.
#[derive(Debug, Clone, PartialEq)]
pub struct RunAnalysis {
    /// Path length, mm.
    pub length_mm: f64,
    /// Programmed feed, mm/min.
    pub feed_mm_min: f64,
    /// The lowest bound over the run.
    pub min: FeedBound,
    /// Where it occurs, mm.
    pub min_s_mm: f64,
    /// Lowest ratio per axis (axis order) and the limit that binds there.
    pub axis_min: [(f64, LimitKind); 5],
    /// Estimated time ∫ds/ṡ over the run, s.
    pub time_s: f64,
    /// Bound on the error of `time_s`, s (module docs).
    pub time_error_s: f64,
    /// L/F, s.
    pub ideal_time_s: f64,
    /// Peak speed per axis at the programmed feed: max |q_s|·F, mm/s or °/s.
    pub peak_speed: [f64; 5],
    /// Singular zones.
    pub zones: Vec<Zone>,
    /// Points where Equation 6 was evaluated (only with `keep_samples`).
    pub samples: Vec<Sample>,
    /// Evaluations of Equation 6 made (all axes at one point count one): at most
    /// `spans·(2^TIME_MAX_DEPTH + 2)`, whatever the feed.
    pub evaluations: usize,
}

/// Check a path's shape and values.
pub fn validate(path: &Path) -> Result<(), PathError> {
    let n = path.s_mm.len();
    if n != path.axes.len() {
        return Err(PathError::LengthMismatch {
            s: n,
            axes: path.axes.len(),
        });
    }
    if n < 2 {
        return Err(PathError::TooShort(n));
    }
    if !(path.feed_mm_min.is_finite() && path.feed_mm_min > 0.0) {
        return Err(PathError::BadFeed(path.feed_mm_min));
    }
    const NAMES: [&str; 5] = ["X", "Y", "Z", "primary", "C"];
    for (i, (s, q)) in path.s_mm.iter().zip(&path.axes).enumerate() {
        if !s.is_finite() {
            return Err(PathError::NotFinite {
                index: i,
                what: "s",
                value: *s,
            });
        }
        for (k, v) in q.iter().enumerate() {
            if !v.is_finite() {
                return Err(PathError::NotFinite {
                    index: i,
                    what: NAMES[k],
                    value: *v,
                });
            }
        }
        if i > 0 && *s <= path.s_mm[i - 1] {
            return Err(PathError::NotIncreasing {
                index: i,
                value: *s,
                previous: path.s_mm[i - 1],
            });
        }
    }
    Ok(())
}

/// The analysis splines of the five axes ([`crate::spline`]), on one factored system.
pub fn axis_splines(path: &Path) -> Result<Vec<AnalysisSpline>, PathError> {
    SplineSystem::new(&path.s_mm)?.fit_axes(5, |k| path.axes.iter().map(|q| q[k]).collect())
}

/// Analyse a run (module docs): the not-a-knot spline of each axis over s, Equation 6
/// exact over every span, the time, the zones.
pub fn analyze_path(
    path: &Path,
    machine: &Machine,
    opts: &AnalysisOptions,
) -> Result<RunAnalysis, PathError> {
    run_analysis(path, machine, opts, None)
}

/// [`analyze_path`], with each span's figures too (one record per span).
pub fn analyze_spans(
    path: &Path,
    machine: &Machine,
    opts: &AnalysisOptions,
) -> Result<(RunAnalysis, Vec<SpanFigures>), PathError> {
    let mut spans = Vec::with_capacity(path.s_mm.len().saturating_sub(1));
    let a = run_analysis(path, machine, opts, Some(&mut spans))?;
    Ok((a, spans))
}

fn run_analysis(
    path: &Path,
    machine: &Machine,
    opts: &AnalysisOptions,
    mut spans: Option<&mut Vec<SpanFigures>>,
) -> Result<RunAnalysis, PathError> {
    validate(path)?;
    let splines = axis_splines(path)?;
    let s = &path.s_mm;
    let feed_mm_s = path.feed_mm_min / 60.0;
    let mut acc = Accumulator::new(feed_mm_s, opts.keep_samples);
    for k in 0..s.len() - 1 {
        let h = s[k + 1] - s[k];
        let cubics: [SpanCubic; 5] = std::array::from_fn(|ax| splines[ax].span(s[k], h));
        let fig = acc.span(machine, k, s[k], &cubics, k + 2 == s.len());
        if let Some(out) = spans.as_deref_mut() {
            out.push(fig);
        }
    }
    let (mut analysis, below) = acc.finish(path);
    let side = pole_side_deg(path, machine);
    analysis.zones = detect_zones(&side, &below, opts.cone_deg, opts.pole_reach_deg);
    Ok(analysis)
}

/// Each point's signed distance from the pole, degrees ([`PoleDistance::signed_deg`]): its
/// magnitude the angle between the tool and the pole axis, its sign the side of the pole
/// the primary axis is on, so that a sign change is a pass through the pole onto the other
/// branch. On the standard form it is P itself, exactly; a pair that cannot reach the pole
/// is 180° from it everywhere.
pub fn pole_side_deg(path: &Path, machine: &Machine) -> Vec<f64> {
    let pole = PoleDistance::of(machine);
    path.axes
        .iter()
        .map(|q| pole.signed_deg(q[Axis::Primary.index()]))
        .collect()
}

/// A stretch of consecutive spans whose C-limited ratio is below 1.
#[derive(Debug, Clone, PartialEq)]
pub struct BelowFeed {
    /// First span.
    pub first_span: usize,
    /// Last span.
    pub last_span: usize,
    /// Lowest C ratio in the stretch.
    pub min_ratio: f64,
    /// C's limit that binds that lowest ratio (velocity, acceleration or jerk).
    pub kind: LimitKind,
    /// Each span's lowest C ratio and the limit binding it, `first_span..=last_span`:
    /// what decides which of the stretch's spans are the pole's ([`detect_zones`]).
    pub spans: Vec<(f64, LimitKind)>,
}

impl BelowFeed {
    /// A stretch whose spans all have the stretch's lowest ratio and limit (tests).
    pub fn uniform(first_span: usize, last_span: usize, ratio: f64, kind: LimitKind) -> Self {
        BelowFeed {
            first_span,
            last_span,
            min_ratio: ratio,
            kind,
            spans: vec![(ratio, kind); last_span + 1 - first_span],
        }
    }
}

/// Equation 6 at one point of a span: `d[axis] = [q', q'', q''']`.
fn bound_at(machine: &Machine, cubics: &[SpanCubic; 5], tau: f64, feed_mm_s: f64) -> FeedBound {
    let d: [[f64; 3]; 5] = std::array::from_fn(|ax| cubics[ax].derivs(tau));
    feed_bound(machine, &d, feed_mm_s)
}

/// Running reductions over the spans of a run.
struct Accumulator {
    feed_mm_s: f64,
    min: Option<FeedBound>,
    min_s_mm: f64,
    axis_min: [(f64, LimitKind); 5],
    time_s: f64,
    time_error_s: f64,
    peak_slope: [f64; 5],
    keep: bool,
    samples: Vec<Sample>,
    below: Vec<BelowFeed>,
    open: Option<BelowFeed>,
    evaluations: usize,
}

impl Accumulator {
    fn new(feed_mm_s: f64, keep: bool) -> Self {
        Accumulator {
            feed_mm_s,
            min: None,
            min_s_mm: 0.0,
            axis_min: [(1.0, LimitKind::Feed); 5],
            time_s: 0.0,
            time_error_s: 0.0,
            peak_slope: [0.0; 5],
            keep,
            samples: Vec::new(),
            below: Vec::new(),
            open: None,
            evaluations: 0,
        }
    }

    fn sample(&mut self, machine: &Machine, s_mm: f64, cubics: &[SpanCubic; 5], tau: f64) {
        if !self.keep {
            return;
        }
        let d: [[f64; 3]; 5] = std::array::from_fn(|ax| cubics[ax].derivs(tau));
        let axis_ratio: [f64; 5] = std::array::from_fn(|ax| {
            let b = axis_feed_bound(machine.limit(Axis::ALL[ax]), d[ax]);
            (b.feed_mm_s / self.feed_mm_s).min(1.0)
        });
        self.samples.push(Sample {
            s_mm,
            axis_ratio,
            bound: feed_bound(machine, &d, self.feed_mm_s),
        });
    }

    /// Span `k` starting at `s0_mm` with the axes' cubics: its figures, folded into the
    /// run's.
    fn span(
        &mut self,
        machine: &Machine,
        k: usize,
        s0_mm: f64,
        cubics: &[SpanCubic; 5],
        last: bool,
    ) -> SpanFigures {
        let h = cubics[0].h;
        let mut peaks = [[0.0; 3]; 5];
        let mut at = [[0.0; 2]; 5];
        for ax in 0..5 {
            (peaks[ax], at[ax]) = cubics[ax].peaks();
        }
        self.evaluations += 1;
        // Equation 6 at the peaks: the exact lowest bound of each axis over the span.
        let mut axis_ratio = [1.0; 5];
        let mut axis_kind = [LimitKind::Feed; 5];
        let mut bound = FeedBound {
            feed_mm_s: self.feed_mm_s,
            ratio: 1.0,
            axis: None,
            kind: LimitKind::Feed,
        };
        let mut min_tau = 0.0;
        for axis in Axis::ALL {
            let ax = axis.index();
            let b = axis_feed_bound(machine.limit(axis), peaks[ax]);
            let r = (b.feed_mm_s / self.feed_mm_s).min(1.0);
            axis_ratio[ax] = if r.is_nan() { 0.0 } else { r };
            axis_kind[ax] = b.kind;
            if axis_ratio[ax] < self.axis_min[ax].0 {
                self.axis_min[ax] = (axis_ratio[ax], b.kind);
            }
            self.peak_slope[ax] = self.peak_slope[ax].max(peaks[ax][0]);
            if b.feed_mm_s < bound.feed_mm_s || b.feed_mm_s.is_nan() {
                bound.feed_mm_s = if b.feed_mm_s.is_nan() {
                    0.0
                } else {
                    b.feed_mm_s
                };
                bound.axis = Some(axis);
                bound.kind = b.kind;
                min_tau = match b.kind {
                    LimitKind::Velocity => at[ax][0],
                    LimitKind::Acceleration => at[ax][1],
                    _ => 0.0,
                };
            }
        }
        bound.ratio = bound.feed_mm_s / self.feed_mm_s;
        if self.min.is_none_or(|m| bound.feed_mm_s < m.feed_mm_s) {
            self.min = Some(bound);
            self.min_s_mm = s0_mm + min_tau;
        }
        // Time: exact at feed, else adaptive trapezoid with a rigorous bracket.
        let (time_s, time_error_s) = if bound.ratio >= 1.0 {
            self.sample(machine, s0_mm, cubics, 0.0);
            (h / self.feed_mm_s, 0.0)
        } else {
            let g = |acc: &mut Accumulator, tau: f64| {
                acc.evaluations += 1;
                1.0 / bound_at(machine, cubics, tau, acc.feed_mm_s).feed_mm_s
            };
            let (g0, gh) = (g(self, 0.0), g(self, h));
            let mut out = (0.0, 0.0);
            self.piece(machine, cubics, s0_mm, (0.0, g0), (h, gh), 0, &mut out);
            out
        };
        if last {
            self.sample(machine, s0_mm + h, cubics, h);
        }
        self.time_s += time_s;
        self.time_error_s += time_error_s;
        let rc = axis_ratio[Axis::C.index()];
        let kc = axis_kind[Axis::C.index()];
        if rc < 1.0 - RATIO_TOL {
            match &mut self.open {
                Some(b) => {
                    b.last_span = k;
                    b.spans.push((rc, kc));
                    if rc < b.min_ratio {
                        b.min_ratio = rc;
                        b.kind = kc;
                    }
                }
                None => self.open = Some(BelowFeed::uniform(k, k, rc, kc)),
            }
        } else if let Some(b) = self.open.take() {
            self.below.push(b);
        }
        SpanFigures {
            axis_ratio,
            axis_kind,
            bound,
            min_s_mm: s0_mm + min_tau,
            time_s,
            time_error_s,
        }
    }

    /// The time over the piece `[a, b]` of a span (with `1/ṡ` there), bisected while its
    /// bracket is wider than [`TIME_REL_TOL`] (module docs); adds (estimate, error bound)
    /// to `out`.
    #[allow(clippy::too_many_arguments)]
    fn piece(
        &mut self,
        machine: &Machine,
        cubics: &[SpanCubic; 5],
        s0_mm: f64,
        (a, ga): (f64, f64),
        (b, gb): (f64, f64),
        depth: u32,
        out: &mut (f64, f64),
    ) {
        let mut lo = [[0.0; 3]; 5];
        let mut hi = [[0.0; 3]; 5];
        for ax in 0..5 {
            (lo[ax], hi[ax]) = cubics[ax].abs_range(a, b);
        }
        // 1/ṡ is increasing in every derivative's size: its values over the piece lie
        // between these two.
        let g_lo = 1.0 / feed_bound(machine, &lo, self.feed_mm_s).feed_mm_s;
        let g_hi = 1.0 / feed_bound(machine, &hi, self.feed_mm_s).feed_mm_s;
        let w = b - a;
        if (g_hi - g_lo) * w <= TIME_REL_TOL * g_lo * w || depth >= TIME_MAX_DEPTH {
            self.sample(machine, s0_mm + a, cubics, a);
            out.0 += 0.5 * (ga + gb) * w;
            out.1 += (g_hi - g_lo) * w;
            return;
        }
        let m = 0.5 * (a + b);
        self.evaluations += 1;
        let gm = 1.0 / bound_at(machine, cubics, m, self.feed_mm_s).feed_mm_s;
        self.piece(machine, cubics, s0_mm, (a, ga), (m, gm), depth + 1, out);
        self.piece(machine, cubics, s0_mm, (m, gm), (b, gb), depth + 1, out);
    }

    fn finish(mut self, path: &Path) -> (RunAnalysis, Vec<BelowFeed>) {
        if let Some(b) = self.open.take() {
            self.below.push(b);
        }
        let length_mm = path.s_mm[path.s_mm.len() - 1] - path.s_mm[0];
        let min = self.min.expect("a validated path has at least one span");
        let peak_speed = self.peak_slope.map(|d| d * self.feed_mm_s);
        (
            RunAnalysis {
                length_mm,
                feed_mm_min: path.feed_mm_min,
                min,
                min_s_mm: self.min_s_mm,
                axis_min: self.axis_min,
                time_s: self.time_s,
                time_error_s: self.time_error_s,
                ideal_time_s: length_mm / self.feed_mm_s,
                peak_speed,
                zones: Vec::new(),
                samples: self.samples,
                evaluations: self.evaluations,
            },
            self.below,
        )
    }
}

/// Whether the pole dominates the slowdown of a stretch where C's lowest ratio is
/// `c_ratio`, bound by C's limit `kind`, and the primary axis comes within `min_abs_deg` of
/// the pole (SPEC §3 step 2; docs/method.md, "What a zone is").
///
/// Near the pole C turns the tool axis' azimuth: for a given motion of the tool axis, C's
/// derivatives of every order are those of the tool axis' own angular motion times
/// 1/sin|P| (C17 eq. 5, Ċ = Θ̇/sin A). Equation 6's bound on C scales as the e-th root of
/// the derivative it limits (e = 1 velocity, 2 acceleration, 3 jerk), so the pole alone
/// multiplies C's feed bound by sin(|P|)^(1/e), and C's lowest ratio is
/// `c_ratio = sin(|P|)^(1/e) · rest`, `rest` being what the tool axis' own motion would
/// allow on an axis with C's limits. The pole dominates when its factor is at most the
/// rest — it accounts for at least half of the slowdown, in ratio:
/// `sin(|P|)^(1/e) ≤ c_ratio / sin(|P|)^(1/e)`, i.e. `sin(|P|)^(2/e) ≤ c_ratio`. Both
/// sides follow from the machine's C limits and the program's feed (which limit binds,
/// and how far below feed), none from a chosen angle.
pub fn pole_dominates(min_abs_deg: f64, c_ratio: f64, kind: LimitKind) -> bool {
    let e = match kind {
        LimitKind::Velocity => 1.0,
        LimitKind::Acceleration => 2.0,
        LimitKind::Jerk => 3.0,
        LimitKind::Feed => return false,
    };
    let s = min_abs_deg.to_radians().sin().abs();
    s.powf(2.0 / e) <= c_ratio
}

/// Whether span `k` of a stretch below feed is the pole's doing: one of its ends lies in the
/// cone, or the pole dominates the span's own slowdown ([`pole_dominates`] on the span's
/// closest end to the pole, its lowest C ratio and the limit binding it).
fn pole_span(p: &impl Fn(usize) -> f64, k: usize, ratio: f64, kind: LimitKind, cone: f64) -> bool {
    let d = p(k).abs().min(p(k + 1).abs());
    d <= cone || pole_dominates(d, ratio, kind)
}

/// The zone over points `first..=last` (its spans' lowest C ratio `c_ratio_min`): its kind
/// and singular point.
fn zone_over(
    p: &impl Fn(usize) -> f64,
    first: usize,
    last: usize,
    c_ratio_min: f64,
    (cut_before, cut_after): (bool, bool),
) -> Zone {
    let min_abs = (first..=last)
        .map(|i| p(i).abs())
        .fold(f64::INFINITY, f64::min);
    // A flip: the primary changes sign between two points (or passes through 0 with
    // opposite signs either side) inside the zone.
    let mut flip = None;
    let mut last_nonzero: Option<usize> = None;
    for i in first..=last {
        if p(i) == 0.0 {
            continue;
        }
        if let Some(j) = last_nonzero
            && p(j).signum() != p(i).signum()
        {
            flip = Some(j);
            break;
        }
        last_nonzero = Some(i);
    }
    let least = (first..=last)
        .min_by(|&a, &b| p(a).abs().total_cmp(&p(b).abs()))
        .unwrap_or(first);
    let (kind, singular) = match flip {
        Some(j) => (ZoneKind::AFlip, j),
        None => (ZoneKind::CSwing, least),
    };
    Zone {
        first,
        last,
        singular,
        kind,
        min_abs_primary_deg: min_abs,
        c_ratio_min,
        cut_before,
        cut_after,
    }
}

/// Zones from the stretches where C is below feed (docs/method.md, "What a zone is").
///
/// `pole_side_deg` is each point's signed distance from the pole ([`pole_side_deg`]: the
/// primary value on the standard form); below, |primary| means its magnitude.
///
/// Each stretch covers the points of its spans; overlapping or touching stretches merge. A
/// stretch holds a zone when a point in it has |primary| ≤ `cone_deg`, or — out to
/// `pole_reach_deg` — when the pole dominates its slowdown ([`pole_dominates`], on the
/// stretch's closest approach, lowest C ratio and the limit binding it).
///
/// **The zone is the pole passage, not the whole stretch** (issue: a stretch that starts at
/// the pole and sweeps C through 1800° while the primary axis goes out to 89° was one zone,
/// and its patch turned tool axes 60–90° from the pole by up to 94°). From the stretch's
/// spans in the cone (or, for a stretch the reach admits, the span(s) at its closest
/// approach) the zone grows outward span by span while each span is the pole's: an end
/// within the pole reach (the analysis spline carries a flip's turn of C into the spans
/// beside it), a branch switch (re-selection undoes it with no change of orientation), or
/// the pole dominating that span's own slowdown (`pole_span`). It stops at
/// the first span that is not: there C crawls by the program's own doing (the table turning
/// round with the tool far from the pole), which a patch near the pole neither causes nor
/// can cure at a small change of tool axis. A zone cut so is marked on that side
/// ([`Zone::cut_before`], [`Zone::cut_after`]); the rest of the stretch is no zone. One
/// stretch may so hold several zones (passes into and out of the cone); the driver merges
/// close ones.
///
/// A zone the reach admits and the zone before it are one zone when the primary axis stays
/// within the reach between them (one pass by the pole); zones the cone admits are never
/// joined to each other here (the driver merges close ones).
pub fn detect_zones(
    pole_side_deg: &[f64],
    below: &[BelowFeed],
    cone_deg: f64,
    pole_reach_deg: f64,
) -> Vec<Zone> {
    let p = |i: usize| pole_side_deg[i];
    // Touching stretches merged: first and last point, lowest ratio and its limit, and
    // every span's (ratio, limit) from the first point on.
    struct Stretch {
        first: usize,
        last: usize,
        min_ratio: f64,
        kind: LimitKind,
        spans: Vec<(f64, LimitKind)>,
    }
    let mut merged: Vec<Stretch> = Vec::new();
    for b in below {
        let (first, last) = (b.first_span, b.last_span + 1);
        let spans = || {
            (0..=b.last_span - b.first_span)
                .map(|k| b.spans.get(k).copied().unwrap_or((b.min_ratio, b.kind)))
        };
        match merged.last_mut() {
            Some(m) if first <= m.last => {
                for (j, sp) in spans().enumerate() {
                    let k = first + j - m.first;
                    match m.spans.get_mut(k) {
                        Some(x) if x.0 <= sp.0 => {}
                        Some(x) => *x = sp,
                        None => m.spans.push(sp),
                    }
                }
                m.last = m.last.max(last);
                if b.min_ratio < m.min_ratio {
                    m.min_ratio = b.min_ratio;
                    m.kind = b.kind;
                }
            }
            _ => merged.push(Stretch {
                first,
                last,
                min_ratio: b.min_ratio,
                kind: b.kind,
                spans: spans().collect(),
            }),
        }
    }
    let reach = pole_reach_deg.max(cone_deg);
    let mut zones: Vec<Zone> = Vec::new();
    for st in merged {
        let (first, last) = (st.first, st.last);
        let min_abs = (first..=last)
            .map(|i| p(i).abs())
            .fold(f64::INFINITY, f64::min);
        let in_cone = min_abs <= cone_deg;
        let dominated = min_abs <= pole_reach_deg && pole_dominates(min_abs, st.min_ratio, st.kind);
        if !(in_cone || dominated) {
            continue;
        }
        // The stretch's spans (k from `first`), which are the pole's, and the seeds.
        let span = |k: usize| st.spans[k - first];
        let near = |k: usize| p(k).abs().min(p(k + 1).abs());
        // Within the reach every span below feed is the pole's: the analysis spline carries
        // a flip's or a swing's turn of C into the spans either side of it (seeded case 36:
        // spans 5°–8° from the pole at 0.73 → 0.03 of feed before an A flip, which no
        // span-by-span test of dominance attributes to the pole, yet which the patch of the
        // flip lifts to 0.98 — and `analyze` of its output then found a zone there).
        // A branch switch (the pole side changes sign across the span) in the stretch is
        // the zone's too, however far from the pole: re-selecting the branch undoes it with
        // no change of orientation.
        let switch = |k: usize| p(k) * p(k + 1) < 0.0;
        let is_pole = |k: usize| {
            near(k) <= reach || switch(k) || pole_span(&p, k, span(k).0, span(k).1, cone_deg)
        };
        let mut seeds: Vec<usize> = (first..last).filter(|&k| near(k) <= cone_deg).collect();
        if seeds.is_empty() {
            let least = (first..=last)
                .min_by(|&a, &b| p(a).abs().total_cmp(&p(b).abs()))
                .unwrap_or(first);
            seeds.push(least.min(last - 1));
        }
        let mut grown: Vec<(usize, usize)> = Vec::new();
        for seed in seeds {
            if grown.last().is_some_and(|g| seed <= g.1) {
                continue;
            }
            let (mut a, mut b) = (seed, seed);
            while a > first && is_pole(a - 1) {
                a -= 1;
            }
            while b + 1 < last && is_pole(b + 1) {
                b += 1;
            }
            grown.push((a, b));
        }
        for (a, b) in grown {
            let c_ratio_min = (a..=b).map(|k| span(k).0).fold(f64::INFINITY, f64::min);
            let zone = zone_over(&p, a, b + 1, c_ratio_min, (a > first, b + 1 < last));
            let zone_in_cone = zone.min_abs_primary_deg <= cone_deg;
            // One pass by the pole is one zone: a zone the reach admits joins the zone
            // before it (and a zone joins such a zone) when the primary axis stays within
            // the reach between them — the same pass, patched in one go.
            if let Some(prev) = zones.last_mut()
                && (!zone_in_cone || prev.min_abs_primary_deg > cone_deg)
                && (prev.last..=zone.first).all(|i| p(i).abs() <= reach)
            {
                let keep_prev = prev.min_abs_primary_deg <= zone.min_abs_primary_deg;
                *prev = Zone {
                    first: prev.first,
                    last: zone.last,
                    singular: if keep_prev {
                        prev.singular
                    } else {
                        zone.singular
                    },
                    kind: if keep_prev { prev.kind } else { zone.kind },
                    min_abs_primary_deg: prev.min_abs_primary_deg.min(zone.min_abs_primary_deg),
                    c_ratio_min: prev.c_ratio_min.min(zone.c_ratio_min),
                    cut_before: prev.cut_before,
                    cut_after: zone.cut_after,
                };
                continue;
            }
            zones.push(zone);
        }
    }
    zones
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::{machine, planted};

    /// The primary column: the signed pole distance on the standard form.
    fn side(path: &Path) -> Vec<f64> {
        path.axes.iter().map(|q| q[3]).collect()
    }

    /// A straight line of X only, at any feed: every ratio is 1, the time is exactly L/F,
    /// no zone.
    #[test]
    fn a_straight_line_runs_at_feed() {
        let m = machine("mikron-ucp710");
        let path = Path {
            s_mm: (0..21).map(f64::from).collect(),
            axes: (0..21)
                .map(|i| [f64::from(i), 0.0, 0.0, 20.0, 30.0])
                .collect(),
            feed_mm_min: 3000.0,
        };
        let a = analyze_path(&path, &m, &AnalysisOptions::default()).unwrap();
        assert_eq!(a.min.ratio, 1.0);
        assert!((a.time_s - a.ideal_time_s).abs() < 1e-12, "{a:?}");
        assert!((a.ideal_time_s - 20.0 / 50.0).abs() < 1e-12);
        assert!(a.zones.is_empty());
        assert_eq!(a.evaluations, 20, "one evaluation per span at feed");
        assert_eq!(a.time_error_s, 0.0);
    }

    /// Issue 19 §4: work is bounded by the blocks, not by run time ÷ Tcy. A program at
    /// F0.0001 (its run time is 5.5 days for 48 mm) and a single 46 m G1 move are analysed
    /// with a number of Equation-6 evaluations bounded per span (at F·Tcy sampling they
    /// took 5·10⁸ and 2.8·10⁶ samples at F1000, 2.8·10¹⁰ at F0.0001 for 46 m).
    #[test]
    fn slow_feeds_and_long_moves_take_bounded_work() {
        let m = machine("mikron-ucp710");
        let per_span = (1usize << TIME_MAX_DEPTH) + 2;
        // A near-pole pass at F0.0001: nothing binds but the feed.
        let mut slow = planted(97, 0.5, 0.5, false, 0.0001);
        slow.feed_mm_min = 0.0001;
        let a = analyze_path(&slow, &m, &AnalysisOptions::default()).unwrap();
        assert!(a.evaluations <= 96 * per_span, "{}", a.evaluations);
        assert_eq!(a.evaluations, 96, "every span at feed: one evaluation each");
        assert!((a.time_s - a.ideal_time_s).abs() <= 1e-9 * a.ideal_time_s);
        // One 46 m move (2 points) with the rotary axes turning along it.
        for feed in [0.0001, 1000.0, 20000.0] {
            let long = Path {
                s_mm: vec![0.0, 46_000.0],
                axes: vec![
                    [0.0, 0.0, 0.0, 10.0, 0.0],
                    [46_000.0, 0.0, 0.0, 30.0, 720.0],
                ],
                feed_mm_min: feed,
            };
            let a = analyze_path(
                &long,
                &m,
                &AnalysisOptions {
                    keep_samples: true,
                    ..AnalysisOptions::default()
                },
            )
            .unwrap();
            assert!(a.evaluations <= per_span, "F{feed}: {}", a.evaluations);
            assert!(a.samples.len() <= per_span, "F{feed}: {}", a.samples.len());
        }
        // The same at F·Tcy sampling would have been 46 m / (F·Tcy) samples: at F1000,
        // 2.76 million.
        assert!(46_000.0 / (1000.0 / 60.0 * m.tcy_s) > 2.7e6);
    }

    /// The time estimate against an independent fine integration (midpoint rule on 2 000
    /// points per span of 1/ṡ from Equation 6 at each point), on zones that slow down: the
    /// estimate is within its stated error bound of it, and that bound is small.
    #[test]
    fn time_estimate_is_within_its_stated_error() {
        let m = machine("mikron-ucp710");
        for (d, flip) in [(0.5, false), (2.0, true), (0.01, false)] {
            let path = planted(121, 0.5, d, flip, 2000.0);
            let a = analyze_path(&path, &m, &AnalysisOptions::default()).unwrap();
            assert!(a.min.ratio < 0.5, "the planted pass slows down");
            let splines = axis_splines(&path).unwrap();
            let f = path.feed_mm_min / 60.0;
            let mut fine = 0.0;
            for w in path.s_mm.windows(2) {
                let h = w[1] - w[0];
                let cubics: [SpanCubic; 5] = std::array::from_fn(|ax| splines[ax].span(w[0], h));
                for i in 0..2000 {
                    let t = h * (i as f64 + 0.5) / 2000.0;
                    fine += h / 2000.0 / bound_at(&m, &cubics, t, f).feed_mm_s;
                }
            }
            let err = (a.time_s - fine).abs();
            assert!(
                err <= a.time_error_s + 1e-6 * fine,
                "d {d}: {err} > {}",
                a.time_error_s
            );
            assert!(
                a.time_error_s <= 0.02 * a.time_s,
                "d {d}: bound {} of {}",
                a.time_error_s,
                a.time_s
            );
            assert!(err <= 2e-3 * fine, "d {d}: error {err} of {fine}");
        }
    }

    /// Planted constant slowdown: C turning at twice V/F everywhere halves the feed, so the
    /// estimated time is exactly 2·L/F and C's velocity limits (no zone: the primary axis
    /// is far from the pole).
    #[test]
    fn time_estimate_of_a_planted_slowdown() {
        let m = machine("mikron-ucp710");
        let feed = 1000.0;
        let v = m.limit(Axis::C).v / (feed / 60.0); // V/F, °/mm
        let path = Path {
            s_mm: (0..41).map(|i| 0.5 * f64::from(i)).collect(),
            axes: (0..41)
                .map(|i| {
                    let s = 0.5 * f64::from(i);
                    [s, 0.0, 0.0, 30.0, 2.0 * v * s]
                })
                .collect(),
            feed_mm_min: feed,
        };
        let a = analyze_path(&path, &m, &AnalysisOptions::default()).unwrap();
        assert!((a.min.ratio - 0.5).abs() < 1e-12, "{:?}", a.min);
        assert_eq!(
            (a.min.axis, a.min.kind),
            (Some(Axis::C), LimitKind::Velocity)
        );
        assert!((a.time_s - 2.0 * a.ideal_time_s).abs() < 1e-9, "{a:?}");
        assert!(a.zones.is_empty(), "P = 30° is outside the cone");
        assert!((a.peak_speed[Axis::C.index()] - 2.0 * m.limit(Axis::C).v).abs() < 1e-9);
    }

    /// A domain-rule flip is an A-flip zone whose singular point is the last point before
    /// the sign change; the continuous branch of the same pass is a C-swing zone whose
    /// singular point is the point of least |P|; both need a point within the cone.
    #[test]
    fn zone_kinds_and_singular_points() {
        let m = machine("mikron-ucp710");
        let flip = planted(241, 0.5, 1.0, true, 1000.0);
        let a = analyze_path(&flip, &m, &AnalysisOptions::default()).unwrap();
        assert_eq!(a.zones.len(), 1);
        let z = &a.zones[0];
        assert_eq!(z.kind, ZoneKind::AFlip);
        let p = |i: usize| flip.axes[i][Axis::Primary.index()];
        assert!(p(z.singular) * p(z.singular + 1) < 0.0, "{z:?}");
        assert!((z.min_abs_primary_deg - 1.0).abs() < 0.01, "{z:?}");
        assert!(z.first < z.singular && z.singular < z.last && z.c_ratio_min < 1.0);

        let swing = planted(241, 0.5, 1.0, false, 1000.0);
        let a = analyze_path(&swing, &m, &AnalysisOptions::default()).unwrap();
        assert_eq!(a.zones.len(), 1);
        let z = &a.zones[0];
        assert_eq!(z.kind, ZoneKind::CSwing);
        let least = (z.first..=z.last)
            .min_by(|&i, &j| swing.axes[i][3].abs().total_cmp(&swing.axes[j][3].abs()))
            .unwrap();
        assert_eq!(z.singular, least);

        // The same swing with a cone of 0.5°: C still crawls, but no point is in the cone.
        let narrow = AnalysisOptions {
            cone_deg: 0.5,
            pole_reach_deg: 0.5,
            ..AnalysisOptions::default()
        };
        let a = analyze_path(&swing, &m, &narrow).unwrap();
        assert!(a.zones.is_empty());
        assert!(a.axis_min[Axis::C.index()].0 < 1.0);
    }

    /// Stretches of C below feed that touch merge into one zone; `detect_zones` on planted
    /// stretches.
    #[test]
    fn touching_stretches_merge() {
        let path = planted(41, 1.0, 1.0, false, 1000.0);
        let below = [
            BelowFeed::uniform(10, 14, 0.5, LimitKind::Velocity),
            BelowFeed::uniform(15, 22, 0.2, LimitKind::Jerk),
            BelowFeed::uniform(30, 31, 0.9, LimitKind::Acceleration),
        ];
        let zones = detect_zones(&side(&path), &below, 50.0, 50.0);
        assert_eq!(zones.len(), 2, "{zones:?}");
        assert_eq!((zones[0].first, zones[0].last), (10, 23));
        assert_eq!(zones[0].c_ratio_min, 0.2);
        assert_eq!((zones[1].first, zones[1].last), (30, 32));
        // With a 0.1° cone neither has a point in it.
        assert!(detect_zones(&side(&path), &below, 0.1, 0.1).is_empty());
    }

    /// Issue 30 item 12: out to the pole reach, a stretch is a zone where the pole's factor
    /// sin(|P|)^(1/e) on C's bound is at most the rest of its slowdown.
    #[test]
    fn the_pole_dominates_near_it_and_not_far() {
        use LimitKind::{Acceleration, Jerk, Velocity};
        // The corners of a real Haas UMC program at B ≈ 6.3° (UCP710: C's acceleration,
        // ratio 0.30; HSM600: jerk, 0.73) and the table turning round a part at 58°–81°
        // (0.03–0.19): the first are the pole's, the second the program's.
        assert!(pole_dominates(6.311, 0.302, Acceleration));
        assert!(pole_dominates(6.311, 0.732, Jerk));
        assert!(!pole_dominates(58.3, 0.177, Acceleration));
        assert!(!pole_dominates(81.7, 0.031, Acceleration));
        // A branch flip 20° from the pole (C jumps 180° at once: V, ratio 0.008) is not.
        assert!(!pole_dominates(20.0, 0.008, Velocity));
        // The boundary: sin(P)^(2/e) = ratio.
        for (e, kind) in [(1.0, Velocity), (2.0, Acceleration), (3.0, Jerk)] {
            let p = 10.0f64;
            let r = p.to_radians().sin().powf(2.0 / e);
            assert!(pole_dominates(p, r * 1.001, kind));
            assert!(!pole_dominates(p, r * 0.999, kind));
        }
        // At the pole any slowdown is the pole's; a limit that is not C's never is.
        assert!(pole_dominates(0.0, 1e-6, Jerk));
        assert!(!pole_dominates(0.0, 0.5, LimitKind::Feed));
    }

    /// A stretch between the cone and the reach is a zone only when the pole dominates.
    #[test]
    fn the_reach_keeps_dominated_stretches_only() {
        let mut path = planted(41, 1.0, 1.0, false, 1000.0);
        for q in &mut path.axes {
            q[3] = q[3].abs() + 9.0;
        }
        let below = |r: f64| [BelowFeed::uniform(10, 14, r, LimitKind::Acceleration)];
        // min |P| is 9° + the planted pass's own least |P|.
        let least = (10..=15)
            .map(|i| path.axes[i][3])
            .fold(f64::INFINITY, f64::min);
        let threshold = least.to_radians().sin();
        assert_eq!(
            detect_zones(&side(&path), &below(threshold * 1.01), 5.0, 15.0).len(),
            1
        );
        assert!(detect_zones(&side(&path), &below(threshold * 0.99), 5.0, 15.0).is_empty());
        assert!(
            detect_zones(&side(&path), &below(0.99), 5.0, 5.0).is_empty(),
            "beyond the reach"
        );
        assert_eq!(
            detect_zones(&side(&path), &below(0.01), 12.0, 12.0).len(),
            1,
            "in the cone"
        );
    }

    /// A branch switch in the stretch is the zone's wherever it lies (re-selection undoes it
    /// with no change of orientation): a post's own flip just beyond the reach, next to the
    /// spans within it (seeded case 279: B +10.27° → −11.45°, C 180° round, at 0.10 of feed).
    #[test]
    fn a_branch_switch_next_to_the_zone_is_the_zones() {
        // P = 0, 1, …, 9, then 10.5 → −11.5 (the switch), −12.5, … : 20 points.
        let p: Vec<f64> = (0..20)
            .map(|i| match i {
                0..=9 => f64::from(i),
                _ => (f64::from(i) + 0.5) * if i == 10 { 1.0 } else { -1.0 },
            })
            .collect();
        let below = [BelowFeed::uniform(0, 18, 0.001, LimitKind::Jerk)];
        let zones = detect_zones(&p, &below, 5.0, 10.0);
        assert_eq!(zones.len(), 1, "{zones:?}");
        // Spans 0..=9 within the reach, span 10 the switch; span 11 is neither.
        assert_eq!((zones[0].first, zones[0].last), (0, 11), "{zones:?}");
        assert!(
            zones[0].cut_after && zones[0].kind == ZoneKind::AFlip,
            "{zones:?}"
        );
        // Without the switch (10.5 → 11.5, on one branch), the zone ends at the reach.
        let q: Vec<f64> = p.iter().map(|x| x.abs()).collect();
        let zones = detect_zones(&q, &below, 5.0, 10.0);
        assert_eq!((zones[0].first, zones[0].last), (0, 10), "{zones:?}");
    }

    /// A stretch below feed that starts at the pole and goes on far from it (the shape of a
    /// real NX post's run, B 0 → 62° with C turning all along): the zone is the stretch's
    /// spans that are the pole's — grown from the cone span by span while the pole
    /// dominates each span's own slowdown — and is marked cut where the stretch goes on.
    #[test]
    fn a_zone_stops_where_the_pole_no_longer_dominates() {
        // P = 1° a point, 0 → 40°.
        let path = Path {
            s_mm: (0..41).map(f64::from).collect(),
            axes: (0..41)
                .map(|i| [f64::from(i), 0.0, 0.0, f64::from(i), 0.0])
                .collect(),
            feed_mm_min: 1000.0,
        };
        // C at 2 % of feed by its velocity on every span: the pole dominates while
        // sin²P ≤ 0.02, P ≤ 8.13° (spans 0..=8), and every span within the 10° reach is the
        // pole's: spans 0..=10 (their nearer end ≤ 10°), points 0..=11.
        let zones = detect_zones(
            &side(&path),
            &[BelowFeed::uniform(0, 39, 0.02, LimitKind::Velocity)],
            5.0,
            10.0,
        );
        assert_eq!(zones.len(), 1, "{zones:?}");
        let z = &zones[0];
        assert_eq!((z.first, z.last), (0, 11), "{z:?}");
        assert!(!z.cut_before && z.cut_after);
        // Beyond the reach only dominance grows it: with a 6° reach, spans 0..=8.
        let zones = detect_zones(
            &side(&path),
            &[BelowFeed::uniform(0, 39, 0.02, LimitKind::Velocity)],
            5.0,
            6.0,
        );
        assert_eq!((zones[0].first, zones[0].last), (0, 9), "{zones:?}");
        // At 50 % the pole dominates out to 45°: the whole stretch, not cut.
        let zones = detect_zones(
            &side(&path),
            &[BelowFeed::uniform(0, 39, 0.5, LimitKind::Velocity)],
            5.0,
            10.0,
        );
        assert_eq!((zones[0].first, zones[0].last), (0, 40));
        assert!(!zones[0].cut_before && !zones[0].cut_after);
        // Each span's own ratio counts: one span far below feed (a corner of the program's
        // own) ends the zone there.
        let mut below = BelowFeed::uniform(0, 39, 0.5, LimitKind::Velocity);
        below.spans[20] = (0.01, LimitKind::Velocity);
        below.min_ratio = 0.01;
        let zones = detect_zones(&side(&path), &[below], 5.0, 10.0);
        assert_eq!((zones[0].first, zones[0].last), (0, 20), "{zones:?}");
        assert!(zones[0].cut_after && zones[0].c_ratio_min == 0.5);
        // With a fixed cone (the reach at it) and a slowdown the pole dominates nowhere
        // beyond it, the zone is the cone's spans.
        let zones = detect_zones(
            &side(&path),
            &[BelowFeed::uniform(0, 39, 0.001, LimitKind::Jerk)],
            5.0,
            5.0,
        );
        assert_eq!((zones[0].first, zones[0].last), (0, 6), "{zones:?}");
    }

    /// Bad paths are errors, never a panic or a silent result.
    #[test]
    fn bad_paths_are_errors() {
        let m = machine("mikron-ucp710");
        let ok = planted(5, 1.0, 1.0, false, 1000.0);
        let mut bad = ok.clone();
        bad.s_mm[2] = bad.s_mm[1];
        assert!(matches!(
            analyze_path(&bad, &m, &AnalysisOptions::default()),
            Err(PathError::NotIncreasing { index: 2, .. })
        ));
        let mut bad = ok.clone();
        bad.axes[3][4] = f64::INFINITY;
        assert!(matches!(
            analyze_path(&bad, &m, &AnalysisOptions::default()),
            Err(PathError::NotFinite {
                index: 3,
                what: "C",
                ..
            })
        ));
        let mut bad = ok.clone();
        bad.feed_mm_min = 0.0;
        assert!(analyze_path(&bad, &m, &AnalysisOptions::default()).is_err());
        let one = Path {
            s_mm: vec![0.0],
            axes: vec![[0.0; 5]],
            feed_mm_min: 1000.0,
        };
        assert_eq!(
            analyze_path(&one, &m, &AnalysisOptions::default()),
            Err(PathError::TooShort(1))
        );
    }
}
