"""Reference values for the not-a-knot interpolation test (tests/not_a_knot_reference.rs).

Generated once with scipy's CubicSpline (default bc_type='not-a-knot', extrapolate=True),
an implementation independent of ours (scipy solves the classic tridiagonal system for the
slopes in piecewise-polynomial form, we solve a banded collocation system in B-spline
form). Re-run with:

    python3 -m venv /tmp/spv && /tmp/spv/bin/pip install scipy numpy
    /tmp/spv/bin/python crates/bspline/tests/data/make_reference.py

which rewrites not_a_knot_reference.csv next to this script (committed: the Rust tests do
not need Python). Generated with scipy 1.17.1, numpy 2.4.6.

CSV columns: set, kind, x, v0, v1, v2, v3
  kind = data : x = s_i, v0 = y_i (v1..v3 empty)
  kind = eval : x = t, v0..v3 = f(t), f'(t), f''(t), f'''(t) from scipy
Numbers are written with 17 significant digits (round-trip exact for f64).
"""

import csv
import os

import numpy as np
from scipy.interpolate import CubicSpline


def sets():
    rng = np.random.default_rng(20240611)
    out = {}
    # n = 2 and 3: scipy gives the line and the parabola.
    out["n2"] = (np.array([0.5, 2.0]), np.array([1.0, -2.0]))
    out["n3"] = (np.array([0.0, 0.3, 1.5]), np.array([2.0, 1.0, 4.0]))
    # n = 4: the single cubic through four points; n = 5: the smallest true spline.
    out["n4"] = (np.array([0.0, 0.7, 1.1, 2.5]), np.array([0.0, 2.0, -1.0, 3.0]))
    out["n5"] = (np.array([-1.0, -0.2, 0.5, 0.6, 2.0]), np.array([1.0, 3.0, 2.0, 2.5, -4.0]))
    # Uneven spacing (ratios up to ~20) with a smooth function.
    s = np.cumsum(np.r_[0.0, rng.uniform(0.05, 1.0, 11)])
    out["uneven12"] = (s, np.sin(1.3 * s) * 10.0 + s * s)
    # n = 50, random data on random parameters.
    s = np.cumsum(np.r_[0.0, rng.uniform(0.2, 0.8, 49)])
    out["n50"] = (s, rng.normal(0.0, 5.0, 50))
    # A C-axis-like swing 114 -> 245 degrees over 30 CL points ~0.5 mm apart, the swing
    # concentrated near the pole crossing (as in C17's %SING program).
    s = np.cumsum(np.r_[0.0, rng.uniform(0.45, 0.55, 29)])
    mid, width = s[15] - 0.1, 0.6
    g = np.arctan((s - mid) / width)
    c = 114.0 + 131.0 * (g - g[0]) / (g[-1] - g[0])
    out["c_swing30"] = (s, np.round(c, 3))
    return out


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    path = os.path.join(here, "not_a_knot_reference.csv")
    with open(path, "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(["set", "kind", "x", "v0", "v1", "v2", "v3"])
        for name, (s, y) in sets().items():
            for si, yi in zip(s, y):
                w.writerow([name, "data", f"{si:.17g}", f"{yi:.17g}", "", "", ""])
            cs = CubicSpline(s, y)
            span = s[-1] - s[0]
            t = np.linspace(s[0] - 0.1 * span, s[-1] + 0.1 * span, 41)
            t = np.sort(np.r_[t, s, 0.5 * (s[1:] + s[:-1])])
            vals = [cs(t, nu) for nu in range(4)]
            for k, tk in enumerate(t):
                w.writerow([name, "eval", f"{tk:.17g}"] + [f"{v[k]:.17g}" for v in vals])
    print("wrote", path)


if __name__ == "__main__":
    main()
