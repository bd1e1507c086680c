"""cl_to_joints and patch_joints on numpy arrays."""

from __future__ import annotations

import math
import numpy as np
import pytest

import polepatch
from conftest import MACHINES, ROOT


def angle_deg(a, b) -> float:
    """The angle between two vectors, degrees (atan2 of |a×b| and a·b: exact near 0)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return math.degrees(math.atan2(np.linalg.norm(np.cross(a, b)), float(np.dot(a, b))))


@pytest.mark.parametrize("machine", MACHINES)
def test_cl_to_joints_inverts_forward_kinematics_on_degenerate_cases(machine: str) -> None:
    m = polepatch.Machine.builtin(machine)
    rng = np.random.default_rng(7)
    joints = [(0.0, 0.0), (1e-7, 33.0), (0.5, 180.0), (0.5, -180.0), (90.0, 90.0)]
    joints += [(float(p), float(c)) for p, c in zip(rng.uniform(-60, 60, 40), rng.uniform(-180, 180, 40))]
    axes = np.array([m.tool_axis(p, c) for p, c in joints])
    # Rows of 7 with the CL data in a strided view, axes not normalised: both are allowed.
    big = np.zeros((len(joints), 7))
    big[:, 0] = np.arange(len(joints))
    big[:, 3:6] = 2.5 * axes
    before = big.copy()
    out = polepatch.cl_to_joints(big[:, :6], m)
    assert np.array_equal(big, before), "the input is not modified"
    assert out.shape == (len(joints), 5) and out.dtype == np.float64
    assert out.flags.c_contiguous
    assert np.array_equal(out[:, :3], big[:, :3])
    for k, row in enumerate(out):
        assert angle_deg(m.tool_axis(row[3], row[4]), axes[k]) < 1e-9, (k, joints[k], row)
    # Lists are arrays too.
    assert np.array_equal(polepatch.cl_to_joints(big[:, :6].tolist(), m), out)
    # C is continuous along the rows (the nearest rule): no step above 180°.
    assert np.all(np.abs(np.diff(out[:, 4])) <= 180.0 + 1e-9)


def sing_cl() -> np.ndarray:
    """The GOTO points of fixtures/cl/SING.apt at F2000 that pass the pole (x y z i j k)."""
    rows = []
    for line in (ROOT / "fixtures/cl/SING.apt").read_text().splitlines():
        if line.startswith("GOTO/"):
            rows.append([float(v) for v in line[5:].split(",")])
    a = np.array(rows)
    # The long run at z = -8 (the cut through the pole).
    return a[a[:, 2] == -8.0]


def test_patch_joints_reaches_feed_and_reports_the_deviation_it_made() -> None:
    m = polepatch.Machine.builtin("mikron-ucp710")
    cl = sing_cl()
    # C17's SING run: A stays on one side of the pole, C swings by 131° near it.
    joints = polepatch.cl_to_joints(cl, m)
    before = joints.copy()
    out, zones = polepatch.patch_joints(joints, m, 2000.0)
    assert np.array_equal(joints, before), "the input is not modified"
    assert out.shape == joints.shape and out.dtype == np.float64
    assert np.array_equal(out[:, :3], joints[:, :3]), "x y z unchanged"
    assert np.array_equal(out[0], joints[0]) and np.array_equal(out[-1], joints[-1])
    assert zones and all(z["outcome"] == "reached" for z in zones), zones
    assert zones[0]["before"]["c_ratio"] < 1.0 <= zones[0]["after"]["c_ratio"]
    changed = np.any(out[:, 3:] != joints[:, 3:], axis=1)
    assert changed.any()
    # New values are written with at most max_decimals (6) decimals.
    assert np.allclose(out[changed, 3:], np.round(out[changed, 3:], 6), atol=1e-12, rtol=0)
    dev = max(
        angle_deg(m.tool_axis(*out[k, 3:]), m.tool_axis(*joints[k, 3:])) for k in range(len(out))
    )
    assert dev <= max(z["max_deviation_deg"] for z in zones) + 1e-4
    # The same call with only_c changes C alone.
    out_c, zones_c = polepatch.patch_joints(joints, m, 2000.0, only_c=True)
    assert np.array_equal(out_c[:, 3], joints[:, 3])
    assert zones_c and zones_c[0]["before"]["c_ratio"] < 1.0


def test_far_from_the_pole_nothing_changes() -> None:
    m = polepatch.Machine.builtin("mikron-hsm600")
    n = 50
    xyzpc = np.column_stack(
        [np.linspace(0, 49, n), np.zeros(n), np.zeros(n), np.full(n, 30.0), np.linspace(0, 20, n)]
    )
    out, zones = polepatch.patch_joints(xyzpc, m, 3000.0)
    assert zones == [] and np.array_equal(out, xyzpc)
