"""post_cl: the CLI's bytes in every dialect, the same as posting then patching, and a
round trip joints → tool axes → CL → post → joints."""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import List, Tuple

import numpy as np
import pytest

import polepatch
from conftest import MACHINES, ROOT, run_cli

APT = "fixtures/cl/SING.apt"
DIALECTS = {"heidenhain": "I", "sinumerik": "mpf", "fanuc": "nc"}


@pytest.mark.parametrize("machine", MACHINES)
def test_post_cl_is_the_cli_in_every_dialect(cli: Path, tmp_path: Path, machine: str) -> None:
    cl = (ROOT / APT).read_text()
    for dialect, ext in DIALECTS.items():
        for patch in (True, False):
            out = tmp_path / f"out.{ext}"
            flags = [] if patch else ["--no-patch"]
            code, _, err = run_cli(
                cli, "post", APT, "-m", machine, "--dialect", dialect, "-o", str(out), *flags
            )
            assert code == 0, err
            got = polepatch.post_cl(cl, machine, dialect, patch=patch, name=APT)
            assert got == out.read_bytes(), (dialect, patch)


@pytest.mark.parametrize("machine", MACHINES)
def test_posting_then_patching_is_posting_with_the_patch(machine: str) -> None:
    cl = (ROOT / APT).read_bytes()
    for dialect in DIALECTS:
        raw = polepatch.post_cl(cl, machine, dialect, patch=False, name=APT)
        patched, report = polepatch.patch_nc(raw, machine, name=APT)
        assert polepatch.post_cl(cl, machine, dialect, name=APT) == patched
        assert report["zones"] and patched != raw, dialect


def rotary_words(program: bytes, primary: str) -> List[Tuple[float, float]]:
    """(primary, C) of every Heidenhain ISO motion block of a posted program."""
    out = []
    for line in program.decode().splitlines():
        if ";" in line:  # a comment line
            continue
        p = re.search(rf"\b{primary}([+-]?[0-9.]+)", line)
        c = re.search(r"\bC([+-]?[0-9.]+)", line)
        if p and c:
            out.append((float(p.group(1)), float(c.group(1))))
    return out


@pytest.mark.parametrize("machine", MACHINES)
def test_round_trip_joints_to_cl_to_posted_joints(machine: str) -> None:
    m = polepatch.Machine.builtin(machine)
    n = 41
    # A path that sweeps C by 270° at a tilt of 2° to 40° (off the pole: one joint
    # solution per branch, P > 0 on the branch the nearest rule starts on).
    p = np.linspace(40.0, 2.0, n)
    c = np.linspace(-100.0, 170.0, n)
    rows = []
    for k in range(n):
        i, j, kk = m.tool_axis(p[k], c[k])
        rows.append(f"{k * 0.5!r},{-3.0 + k * 0.1!r},{10.0!r},{i!r},{j!r},{kk!r},1500")
    posted = polepatch.post_cl(
        "\n".join(rows) + "\n", m, "heidenhain", patch=False, rotary_decimals=6
    )
    words = rotary_words(posted, m.primary)
    assert len(words) == n
    for k, (pw, cw) in enumerate(words):
        assert abs(pw - p[k]) <= 1e-6 and abs(cw - c[k]) <= 1e-6, (k, pw, p[k], cw, c[k])
    # cl_to_joints gives the same joints, unrounded.
    xyzijk = np.array([[float(v) for v in r.split(",")[:6]] for r in rows])
    joints = polepatch.cl_to_joints(xyzijk, m)
    assert np.allclose(joints[:, 3], p, atol=1e-9) and np.allclose(joints[:, 4], c, atol=1e-9)
    assert np.array_equal(joints[:, :3], xyzijk[:, :3])
    assert math.isclose(float(joints[0, 3]), 40.0, abs_tol=1e-9)
