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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::{machine, planted};

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
        assert_eq!(a.step_mm, 50.0 * m.tcy_s);
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
            BelowFeed {
                first_span: 10,
                last_span: 14,
                min_ratio: 0.5,
            },
            BelowFeed {
                first_span: 15,
                last_span: 22,
                min_ratio: 0.2,
            },
            BelowFeed {
                first_span: 30,
                last_span: 31,
                min_ratio: 0.9,
            },
        ];
        let zones = detect_zones(&path, &below, 50.0);
        assert_eq!(zones.len(), 2, "{zones:?}");
        assert_eq!((zones[0].first, zones[0].last), (10, 23));
        assert_eq!(zones[0].c_ratio_min, 0.2);
        assert_eq!((zones[1].first, zones[1].last), (30, 32));
        // With a 0.1° cone neither has a point in it.
        assert!(detect_zones(&path, &below, 0.1).is_empty());
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
