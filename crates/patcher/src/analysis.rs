//! Equation-6 analysis of one run with the analysis spline (SPEC §2), and detection of
//! singular zones (SPEC §3 step 2).

use crate::path::{Path, PathError};
use crate::spline::{AnalysisSpline, SplineSystem, span_offsets};
use polepatch_kinematics::{Axis, FeedBound, LimitKind, Machine, axis_feed_bound, feed_bound};

/// Options of [`analyze_path`].
#[derive(Debug, Clone, PartialEq)]
pub struct AnalysisOptions {
    /// Singular cone: a zone needs a point with |primary| ≤ this, degrees. Default 5.
    pub cone_deg: f64,
    /// Interpolation cycle time override, seconds; `None` uses the machine's `tcy_s`.
    pub tcy_s: Option<f64>,
    /// Keep every sample in [`RunAnalysis::samples`] (for plots). Default false.
    pub keep_samples: bool,
}

impl Default for AnalysisOptions {
    fn default() -> Self {
        AnalysisOptions {
            cone_deg: 5.0,
            tcy_s: None,
            keep_samples: false,
        }
    }
}

/// Kind of singular zone.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum ZoneKind {
    /// The primary axis changes sign near zero (domain-rule posts, G16): C jumps up to 180°.
    AFlip,
    /// The primary axis keeps its sign and C swings fast near the pole (C17 `%SING`).
    CSwing,
}

/// A singular zone: where the C-limited ratio is below 1 with the primary axis inside the
/// cone.
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
}

/// One analysis sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Path parameter, mm.
    pub s_mm: f64,
    /// Per-axis ratio min(1, bound/F) in axis order.
    pub axis_ratio: [f64; 5],
    /// Overall bound here.
    pub bound: FeedBound,
}

/// Result of analysing one run.
#[derive(Debug, Clone, PartialEq)]
pub struct RunAnalysis {
    /// Path length, mm.
    pub length_mm: f64,
    /// Programmed feed, mm/min.
    pub feed_mm_min: f64,
    /// Sampling step used, mm (F·Tcy).
    pub step_mm: f64,
    /// The lowest bound over the run.
    pub min: FeedBound,
    /// Where it occurs, mm.
    pub min_s_mm: f64,
    /// Lowest ratio per axis (axis order) and the limit that binds there.
    pub axis_min: [(f64, LimitKind); 5],
    /// Estimated time ∫ds/ṡ over the run, s.
    pub time_s: f64,
    /// L/F, s.
    pub ideal_time_s: f64,
    /// Peak speed per axis at the programmed feed: max |q_s|·F, mm/s or °/s.
    pub peak_speed: [f64; 5],
    /// Singular zones.
    pub zones: Vec<Zone>,
    /// Samples (only with `keep_samples`).
    pub samples: Vec<Sample>,
}

/// Samples evaluated per batch (bounds memory on long runs).
const CHUNK: usize = 4096;

/// Ratios below `1 − RATIO_TOL` count as "below feed" (absorbs round-off in the bound).
pub const RATIO_TOL: f64 = 1e-9;

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
    let sys = SplineSystem::new(&path.s_mm)?;
    (0..5)
        .map(|k| {
            let y: Vec<f64> = path.axes.iter().map(|q| q[k]).collect();
            sys.fit(&y)
        })
        .collect()
}

/// Sample parameters of span `i` ([`span_offsets`]: `[s_i, s_{i+1})`, plus `s_{n-1}` on
/// the last span), with the span index.
fn span_samples(
    s: &[f64],
    i: usize,
    step: f64,
    scratch: &mut Vec<f64>,
    out: &mut Vec<(f64, usize)>,
) {
    span_offsets(s[i + 1] - s[i], step, i + 2 == s.len(), scratch);
    out.extend(scratch.iter().map(|&t| (s[i] + t, i)));
}

/// Analyse a run: the not-a-knot spline of each axis over s, sampled every F·Tcy and at
/// every knot, Equation 6 at every sample, time by the trapezoidal rule on 1/ṡ, zones.
pub fn analyze_path(
    path: &Path,
    machine: &Machine,
    opts: &AnalysisOptions,
) -> Result<RunAnalysis, PathError> {
    validate(path)?;
    let splines = axis_splines(path)?;
    let s = &path.s_mm;
    let n = s.len();
    let feed_mm_s = path.feed_mm_min / 60.0;
    let tcy_s = opts.tcy_s.unwrap_or(machine.tcy_s);
    let step_mm = feed_mm_s * tcy_s;
    if !(step_mm.is_finite() && step_mm > 0.0) {
        return Err(PathError::BadFeed(path.feed_mm_min));
    }

    let mut acc = Accumulator::new(n, feed_mm_s, opts.keep_samples);
    let mut params: Vec<(f64, usize)> = Vec::with_capacity(CHUNK + 64);
    let mut scratch = Vec::new();
    let mut ts: Vec<f64> = Vec::with_capacity(CHUNK + 64);
    let mut derivs: Vec<Vec<[f64; 4]>> = (0..5).map(|_| Vec::with_capacity(CHUNK + 64)).collect();
    for i in 0..n - 1 {
        span_samples(s, i, step_mm, &mut scratch, &mut params);
        if params.len() >= CHUNK || i + 2 == n {
            ts.clear();
            ts.extend(params.iter().map(|p| p.0));
            for (k, sp) in splines.iter().enumerate() {
                derivs[k].resize(ts.len(), [0.0; 4]);
                sp.eval_derivs_sorted(&ts, &mut derivs[k]);
            }
            for (m, &(t, span)) in params.iter().enumerate() {
                let mut d = [[0.0; 3]; 5];
                for k in 0..5 {
                    let e = derivs[k][m];
                    d[k] = [e[1], e[2], e[3]];
                }
                acc.add(machine, t, span, &d);
            }
            params.clear();
        }
    }
    let (mut analysis, below) = acc.finish(path, step_mm);
    analysis.zones = detect_zones(path, &below, opts.cone_deg);
    Ok(analysis)
}

/// A stretch of consecutive samples whose C-limited ratio is below 1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BelowFeed {
    /// Span index of the first sample.
    pub first_span: usize,
    /// Span index of the last sample.
    pub last_span: usize,
    /// Lowest C ratio in the stretch.
    pub min_ratio: f64,
}

/// Running reductions over the samples of a run.
struct Accumulator {
    feed_mm_s: f64,
    min: Option<FeedBound>,
    min_s_mm: f64,
    axis_min: [(f64, LimitKind); 5],
    time_s: f64,
    prev: Option<(f64, f64)>,
    peak_slope: [f64; 5],
    keep: bool,
    samples: Vec<Sample>,
    below: Vec<BelowFeed>,
    open: Option<BelowFeed>,
}

impl Accumulator {
    fn new(_n: usize, feed_mm_s: f64, keep: bool) -> Self {
        Accumulator {
            feed_mm_s,
            min: None,
            min_s_mm: 0.0,
            axis_min: [(1.0, LimitKind::Feed); 5],
            time_s: 0.0,
            prev: None,
            peak_slope: [0.0; 5],
            keep,
            samples: Vec::new(),
            below: Vec::new(),
            open: None,
        }
    }

    fn add(&mut self, machine: &Machine, s_mm: f64, span: usize, d: &[[f64; 3]; 5]) {
        let bound = feed_bound(machine, d, self.feed_mm_s);
        if self.min.is_none_or(|m| bound.feed_mm_s < m.feed_mm_s) {
            self.min = Some(bound);
            self.min_s_mm = s_mm;
        }
        let mut axis_ratio = [1.0; 5];
        for axis in Axis::ALL {
            let k = axis.index();
            let b = axis_feed_bound(machine.limit(axis), d[k]);
            // = axis_feed_ratio(…): the bound is needed for its kind too.
            let r = (b.feed_mm_s / self.feed_mm_s).min(1.0);
            axis_ratio[k] = r;
            if r < self.axis_min[k].0 {
                self.axis_min[k] = (r, b.kind);
            }
            self.peak_slope[k] = self.peak_slope[k].max(d[k][0].abs());
        }
        let inv = 1.0 / bound.feed_mm_s;
        if let Some((s0, inv0)) = self.prev {
            self.time_s += 0.5 * (inv0 + inv) * (s_mm - s0);
        }
        self.prev = Some((s_mm, inv));
        let rc = axis_ratio[Axis::C.index()];
        if rc < 1.0 - RATIO_TOL {
            match &mut self.open {
                Some(b) => {
                    b.last_span = span;
                    b.min_ratio = b.min_ratio.min(rc);
                }
                None => {
                    self.open = Some(BelowFeed {
                        first_span: span,
                        last_span: span,
                        min_ratio: rc,
                    })
                }
            }
        } else if let Some(b) = self.open.take() {
            self.below.push(b);
        }
        if self.keep {
            self.samples.push(Sample {
                s_mm,
                axis_ratio,
                bound,
            });
        }
    }

    fn finish(mut self, path: &Path, step_mm: f64) -> (RunAnalysis, Vec<BelowFeed>) {
        if let Some(b) = self.open.take() {
            self.below.push(b);
        }
        let length_mm = path.s_mm[path.s_mm.len() - 1] - path.s_mm[0];
        let min = self.min.expect("a validated path has at least one sample");
        let peak_speed = self.peak_slope.map(|d| d * self.feed_mm_s);
        (
            RunAnalysis {
                length_mm,
                feed_mm_min: path.feed_mm_min,
                step_mm,
                min,
                min_s_mm: self.min_s_mm,
                axis_min: self.axis_min,
                time_s: self.time_s,
                ideal_time_s: length_mm / self.feed_mm_s,
                peak_speed,
                zones: Vec::new(),
                samples: self.samples,
            },
            self.below,
        )
    }
}

/// Zones from the stretches where C is below feed: each stretch covers the points of its
/// spans; overlapping or touching stretches merge; a stretch is a zone when a point in it
/// has |primary| ≤ `cone_deg`.
pub fn detect_zones(path: &Path, below: &[BelowFeed], cone_deg: f64) -> Vec<Zone> {
    let p = |i: usize| path.axes[i][Axis::Primary.index()];
    let mut merged: Vec<(usize, usize, f64)> = Vec::new();
    for b in below {
        let (first, last) = (b.first_span, b.last_span + 1);
        match merged.last_mut() {
            Some(m) if first <= m.1 => {
                m.1 = m.1.max(last);
                m.2 = m.2.min(b.min_ratio);
            }
            _ => merged.push((first, last, b.min_ratio)),
        }
    }
    let mut zones = Vec::new();
    for (first, last, c_ratio_min) in merged {
        let min_abs = (first..=last)
            .map(|i| p(i).abs())
            .fold(f64::INFINITY, f64::min);
        if min_abs > cone_deg {
            continue;
        }
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
        zones.push(Zone {
            first,
            last,
            singular,
            kind,
            min_abs_primary_deg: min_abs,
            c_ratio_min,
        });
    }
    zones
}
