#!/usr/bin/env python3
"""Independent references for polepatch's simulator tests (issue 43 item 5).

Reads one JSON request on stdin, writes one JSON answer on stdout:

- {"kind": "ruckig", "length_mm": L, "v": V, "a": A, "j": J}
  -> {"time_s": T}: Ruckig's time-optimal jerk-limited rest-to-rest motion over L
  (one degree of freedom, the straight line's path parameter).
- {"kind": "topp", "s_mm": [...], "axes": [[X, Y, Z, P, C], ...], "feed_mm_s": F,
   "v": [5], "a": [5], "grid": N}
  -> {"time_s": T}: TOPP-RA's time-optimal parametrisation of the path under each
  axis' V and A and the feed (a sixth coordinate q = s with V = F), no jerk limit.
  The path is scipy's not-a-knot cubic spline through the points over s (the analysis
  spline polepatch simulates on). Without a jerk limit this is a lower bound on the
  time of any motion along the path within V, A and F, up to TOPP-RA's grid.

Needs the PyPI packages `ruckig` and `toppra` (`.ci/run` installs them into
target/reference-venv).
"""
import json
import sys


def ruckig_time(req):
    import ruckig

    inp = ruckig.InputParameter(1)
    inp.current_position = [0.0]
    inp.target_position = [req["length_mm"]]
    inp.max_velocity = [req["v"]]
    inp.max_acceleration = [req["a"]]
    inp.max_jerk = [req["j"]]
    otg = ruckig.Ruckig(1)
    traj = ruckig.Trajectory(1)
    result = otg.calculate(inp, traj)
    if result not in (ruckig.Result.Working, ruckig.Result.Finished):
        raise SystemExit(f"ruckig: {result}")
    return traj.duration


def topp_time(req):
    import numpy as np
    import toppra as ta
    import toppra.algorithm as algo
    import toppra.constraint as constraint

    ta.setup_logging("WARNING")
    s = np.asarray(req["s_mm"], dtype=float)
    q = np.asarray(req["axes"], dtype=float)
    q = np.concatenate([q, s[:, None]], axis=1)
    path = ta.SplineInterpolator(s, q)
    v = np.asarray(list(req["v"]) + [req["feed_mm_s"]], dtype=float)
    a = np.asarray(list(req["a"]) + [1e12], dtype=float)
    grid = np.unique(np.concatenate([s, np.linspace(s[0], s[-1], int(req["grid"]))]))
    inst = algo.TOPPRA(
        [
            constraint.JointVelocityConstraint(np.stack([-v, v], axis=1)),
            constraint.JointAccelerationConstraint(np.stack([-a, a], axis=1)),
        ],
        path,
        gridpoints=grid,
        parametrizer="ParametrizeConstAccel",
    )
    traj = inst.compute_trajectory(0, 0)
    if traj is None:
        raise SystemExit("toppra: no parametrisation")
    return traj.duration


def main():
    req = json.load(sys.stdin)
    kind = req["kind"]
    t = {"ruckig": ruckig_time, "topp": topp_time}[kind](req)
    json.dump({"time_s": float(t)}, sys.stdout)


if __name__ == "__main__":
    main()
