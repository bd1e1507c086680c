//! The path of a motion and its velocity limit curve on a grid of s.

use polepatch_kinematics::{Machine, feed_bound};
use polepatch_patcher::spline::{AnalysisSpline, SplineSystem};
use polepatch_patcher::validate;
use polepatch_patcher::{Path, PathError};

use crate::caps::Local;
use crate::error::SimError;
use crate::tolerances::{GRID_BATCH_POINTS, LIMIT_USE};

/// A motion's path: the parts (runs that follow one another without a stop) joined at
/// their shared points, one analysis spline per axis over all their points.
#[derive(Debug, Clone)]
pub struct Geometry {
    /// s of every point, mm, from 0 (the parts' own s shifted to follow one another).
    pub knots: Vec<f64>,
    splines: Vec<AnalysisSpline>,
    /// Index in `knots` of the last point of each part.
    pub part_end: Vec<usize>,
    /// Programmed feed of each part, mm/s.
    pub feed_mm_s: Vec<f64>,
}

impl Geometry {
    /// Join `parts` (each a valid path; each part's first point equal to the last point
    /// of the part before) and fit the analysis spline of each axis over all points.
    pub fn new(parts: &[Path]) -> Result<Geometry, SimError> {
        if parts.is_empty() {
            return Err(SimError::Empty);
        }
        let mut knots = Vec::new();
        let mut part_end = Vec::new();
        let mut feed_mm_s = Vec::new();
        for (k, p) in parts.iter().enumerate() {
            validate(p).map_err(|source| SimError::Path { part: k, source })?;
            let skip = if k == 0 {
                0
            } else {
                let end = *parts[k - 1].axes.last().expect("a part has points");
                if p.axes[0] != end {
                    return Err(SimError::NotJoined {
                        part: k,
                        previous: k - 1,
                        start: p.axes[0],
                        end,
                    });
                }
                1
            };
            let base = knots.last().copied().unwrap_or(0.0) - p.s_mm[0];
            knots.extend(p.s_mm[skip..].iter().map(|s| s + base));
            part_end.push(knots.len() - 1);
            feed_mm_s.push(p.feed_mm_min / 60.0);
        }
        // Shifted sums may lose strict increase only through rounding of huge s.
        if let Some(i) = (1..knots.len()).find(|&i| knots[i] <= knots[i - 1]) {
            return Err(SimError::Path {
                part: part_end.partition_point(|&e| e < i),
                source: PathError::NotIncreasing {
                    index: i,
                    value: knots[i],
                    previous: knots[i - 1],
                },
            });
        }
        // Each axis' values gathered from the parts as it is solved (no copy of every
        // point's five values held through the fits: peak memory).
        let splines = SplineSystem::new(&knots)
            .and_then(|sys| {
                sys.fit_axes(5, |a| {
                    let mut y = Vec::with_capacity(knots.len());
                    for (k, p) in parts.iter().enumerate() {
                        y.extend(p.axes[usize::from(k > 0)..].iter().map(|q| q[a]));
                    }
                    y
                })
            })
            .map_err(|source| SimError::Path { part: 0, source })?;
        Ok(Geometry {
            knots,
            splines,
            part_end,
            feed_mm_s,
        })
    }

    /// Path length, mm.
    pub fn length(&self) -> f64 {
        *self.knots.last().expect("a geometry has points")
    }

    /// `[q, q_s, q_ss, q_sss]` of each axis at `s`.
    pub fn derivs(&self, s: f64) -> [[f64; 4]; 5] {
        std::array::from_fn(|a| self.splines[a].eval_derivs(s))
    }

    /// [`Geometry::derivs`] and [`Geometry::feed_at`] at `s`, starting the searches
    /// where `cur` was left (for evaluations that move a little along s, either way).
    pub fn derivs_feed_near(&self, s: f64, cur: &mut Cursor) -> ([[f64; 4]; 5], f64) {
        cur.piece = self.splines[0].piece_near(s, cur.piece);
        let d = std::array::from_fn(|a| self.splines[a].eval_derivs_on(cur.piece, s));
        cur.knot = count_at_most(&self.knots, s, cur.knot);
        (d, self.feed_of(s, cur.knot))
    }

    /// Axis values X Y Z P C at `s`.
    pub fn axes(&self, s: f64) -> [f64; 5] {
        std::array::from_fn(|a| self.splines[a].eval(s))
    }

    /// The programmed feed at `s`, mm/s (at a shared point, the lower of the two parts').
    pub fn feed_at(&self, s: f64) -> f64 {
        self.feed_of(s, self.knots.partition_point(|&v| v <= s))
    }

    /// [`Geometry::feed_at`] given `k`, the number of knots at or before `s`.
    fn feed_of(&self, s: f64, k: usize) -> f64 {
        let span = k.saturating_sub(1).min(self.knots.len() - 2);
        let p = self.part_of_span(span);
        let f = self.feed_mm_s[p];
        if k >= 1 && k - 1 < self.knots.len() && self.knots[k - 1] == s && span > 0 {
            f.min(self.feed_mm_s[self.part_of_span(span - 1)])
        } else {
            f
        }
    }

    /// The part that span `k` (between points k and k + 1) belongs to.
    pub fn part_of_span(&self, k: usize) -> usize {
        self.part_end.partition_point(|&e| e <= k)
    }
}

/// Where the last evaluation along a [`Geometry`] was (see
/// [`Geometry::derivs_feed_near`]).
#[derive(Debug, Clone, Copy, Default)]
pub struct Cursor {
    piece: usize,
    knot: usize,
}

/// The number of elements of the sorted `xs` that are ≤ `x` (`xs.partition_point(|&p| p
/// ≤ x)`), searched outward from index `h` in steps that double: the path's knot from the
/// last cycle's, a ramp of the look-ahead a few cells from where the last one was (a search
/// over the whole motion's grid would miss the cache at every level).
pub(crate) fn count_at_most(xs: &[f64], x: f64, h: usize) -> usize {
    let n = xs.len();
    if h < n && xs[h] <= x {
        // The count is above h: double the step forward until an element is above x.
        let mut lo = h + 1;
        let mut step = 1;
        loop {
            let probe = lo + step - 1;
            if probe >= n {
                return lo + xs[lo..].partition_point(|&p| p <= x);
            }
            if xs[probe] <= x {
                lo = probe + 1;
                step *= 2;
            } else {
                return lo + xs[lo..probe].partition_point(|&p| p <= x);
            }
        }
    } else {
        // The count is at most h (or x is NaN: 0): double the step backward.
        let mut hi = h.min(n);
        let mut step = 1;
        loop {
            if hi < step {
                return xs[..hi].partition_point(|&p| p <= x);
            }
            let probe = hi - step;
            if xs[probe] <= x {
                return probe + 1 + xs[probe + 1..hi].partition_point(|&p| p <= x);
            }
            hi = probe;
            step *= 2;
        }
    }
}

/// The grid of s and the velocity limit curve on it.
#[derive(Debug, Clone)]
pub struct Grid {
    /// Grid points, mm: every point of the path and cells between.
    pub s: Vec<f64>,
    /// The velocity limit at each grid point, mm/s (module docs of [`crate`]).
    pub limit: Vec<f64>,
}

impl Grid {
    /// Cut each span into `⌈h/(F·Tcy)⌉` cells (at most `max_cells`), and bound the feed on
    /// each cell by Equation 6 (limits × [`LIMIT_USE`]) with the largest |q_s|, |q_ss|, |q_sss| of each axis over the
    /// cell (exact for the cubic pieces: q_s is quadratic, q_ss linear, q_sss constant on a
    /// span), capped by F. The limit at a grid point is the lower of its two cells', and the
    /// limit curve is linear between grid points: below Equation 6 everywhere on the cell.
    pub fn new(geo: &Geometry, machine: &Machine, tcy_s: f64, max_cells: usize) -> Grid {
        // Equation 6 with the limits the passes plan with.
        let mut planned = machine.clone();
        for l in &mut planned.limits {
            l.v *= LIMIT_USE;
            l.a *= LIMIT_USE;
            l.j *= LIMIT_USE;
        }
        let machine = &planned;
        let mut s = Vec::with_capacity(geo.knots.len());
        let mut cell = Vec::with_capacity(geo.knots.len());
        for_each_cell(geo, tcy_s, max_cells, &mut |c: &Cell| {
            s.push(c.s0_mm);
            cell.push(feed_bound(machine, &c.peaks, c.feed_mm_s).feed_mm_s);
        });
        s.push(geo.knots[geo.knots.len() - 1]);
        let m = cell.len();
        let limit = (0..s.len())
            .map(|i| {
                let l = if i > 0 { cell[i - 1] } else { f64::INFINITY };
                let r = if i < m { cell[i] } else { f64::INFINITY };
                l.min(r)
            })
            .collect();
        Grid { s, limit }
    }
}

/// One cell of the grid: where it is, the largest |q_s|, |q_ss|, |q_sss| of each axis
/// over it, and the programmed feed there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cell {
    /// Start of the cell, mm.
    pub s0_mm: f64,
    /// End of the cell, mm.
    pub s1_mm: f64,
    /// Per axis `[max |q_s|, max |q_ss|, |q_sss|]` over the cell.
    pub peaks: [[f64; 3]; 5],
    /// Programmed feed on the cell, mm/s.
    pub feed_mm_s: f64,
}

/// Every cell of the path in order: each span cut into `⌈h/(F·Tcy)⌉` cells (at most
/// `max_cells`), with the largest |q_s|, |q_ss|, |q_sss| of each axis over the cell (exact
/// for the cubic pieces: q_s is quadratic, q_ss linear, q_sss constant on a span).
pub fn for_each_cell(geo: &Geometry, tcy_s: f64, max_cells: usize, f: &mut dyn FnMut(&Cell)) {
    let n = geo.knots.len();
    let mut s = Vec::with_capacity(GRID_BATCH_POINTS + 1);
    let mut derivs: Vec<[[f64; 4]; 5]> = Vec::with_capacity(GRID_BATCH_POINTS + 1);
    let mut buf = vec![[0.0; 4]; GRID_BATCH_POINTS + 1];
    // The spans' cell boundaries are generated in batches of about GRID_BATCH_POINTS:
    // a batch ends at a span's end (the last point is the next batch's first).
    let mut k = 0usize;
    while k + 1 < n {
        s.clear();
        let batch_first_span = k;
        while k + 1 < n && s.len() < GRID_BATCH_POINTS {
            let f = geo.feed_mm_s[geo.part_of_span(k)];
            let (a, b) = (geo.knots[k], geo.knots[k + 1]);
            let cells = ((b - a) / (f * tcy_s))
                .ceil()
                .clamp(1.0, max_cells.max(1) as f64) as usize;
            for i in 0..cells {
                s.push(a + (b - a) * i as f64 / cells as f64);
            }
            k += 1;
        }
        s.push(geo.knots[k]);
        derivs.clear();
        derivs.resize(s.len(), [[0.0; 4]; 5]);
        if buf.len() < s.len() {
            buf.resize(s.len(), [0.0; 4]);
        }
        for a in 0..5 {
            geo.splines[a].eval_derivs_sorted(&s, &mut buf[..s.len()]);
            for (d, e) in derivs.iter_mut().zip(&buf) {
                d[a] = *e;
            }
        }
        let mut span = batch_first_span;
        for i in 0..s.len() - 1 {
            let t0 = s[i];
            while geo.knots[span + 1] <= t0 {
                span += 1;
            }
            let feed_mm_s = geo.feed_mm_s[geo.part_of_span(span)];
            let h = s[i + 1] - t0;
            let mut peaks = [[0.0; 3]; 5];
            for a in 0..5 {
                let [_, q1, q2, q3] = derivs[i][a];
                let e = derivs[i + 1][a];
                // End of the cell from the left piece (the right end may be a knot,
                // where the next piece starts with another q_sss).
                let q1e = q1 + q2 * h + 0.5 * q3 * h * h;
                let q2e = q2 + q3 * h;
                let mut m1 = q1.abs().max(q1e.abs()).max(e[1].abs());
                if q3 != 0.0 {
                    let u = -q2 / q3;
                    if u > 0.0 && u < h {
                        m1 = m1.max((q1 + q2 * u + 0.5 * q3 * u * u).abs());
                    }
                }
                peaks[a] = [m1, q2.abs().max(q2e.abs()).max(e[2].abs()), q3.abs()];
            }
            f(&Cell {
                s0_mm: t0,
                s1_mm: s[i + 1],
                peaks,
                feed_mm_s,
            });
        }
    }
}

/// The local limits at `s`.
pub fn local_at(geo: &Geometry, s: f64) -> (Local, [[f64; 4]; 5]) {
    let d = geo.derivs(s);
    (Local::from_derivs(&d), d)
}

#[cfg(test)]
mod tests {
    /// The search from a hint is the partition point, from every hint, with repeated
    /// elements, outside the elements and at NaN.
    #[test]
    fn the_search_from_a_hint_is_the_partition_point() {
        let xs = [0.0, 1.0, 1.0, 1.5, 4.0, 4.0, 4.0, 9.0, 10.0, 11.0, 20.0];
        for x in [
            -1.0,
            0.0,
            0.5,
            1.0,
            1.2,
            1.5,
            3.0,
            4.0,
            8.9,
            9.0,
            10.5,
            11.0,
            20.0,
            25.0,
            f64::NAN,
        ] {
            let want = xs.partition_point(|&p| p <= x);
            for h in 0..14 {
                assert_eq!(super::count_at_most(&xs, x, h), want, "x={x} h={h}");
            }
        }
        assert_eq!(super::count_at_most(&[], 1.0, 0), 0);
    }
}
