"""The tool keywords (issue 27): ``tool=``, ``tool_point=`` and ``surface_tolerance_mm=``
are the CLI's ``--tool``, ``--tool-point`` and ``--surface-tolerance``, read by the same
parser; ``post_cl`` takes the CL file's ``CUTTER/`` as ``polepatch post`` does."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import polepatch
from conftest import ROOT, read, run_cli, without_timing

SING = "fixtures/c17/SING.I"
FLAT = "fixtures/tools/fusion-ac-swing-d0.5-flat.nc"
APT = "fixtures/tools/camworks_ball_swing.apt"


@pytest.mark.parametrize(
    "rel, flags, kwargs, tool",
    [
        (SING, ["--tool", "ball:10", "--tool-point", "tip"], dict(tool="ball:10", tool_point="tip"), "ball D10"),
        (SING, ["--tool", "ball:10"], dict(tool="ball:10"), "ball D10"),
        (FLAT, ["--tool", "flat:10", "--surface-tolerance", "0.01"], dict(tool="flat:10", surface_tolerance_mm=0.01), "flat D10"),
        (FLAT, ["--tool", "bull:10,2"], dict(tool="bull:10,2"), "bull D10 R2"),
        (FLAT, [], {}, "flat D12"),  # from the program's Fusion tool comment
    ],
)
def test_tool_keywords_are_the_cli_flags(
    cli: Path, tmp_path: Path, rel: str, flags: list, kwargs: dict, tool: str
) -> None:
    out, rep = tmp_path / "out", tmp_path / "r.json"
    code, _, err = run_cli(
        cli, "patch", rel, "-m", "mikron-ucp710", "-o", str(out), "--report", str(rep), *flags
    )
    assert code == 0, err
    data, report = polepatch.patch_nc(read(rel), "mikron-ucp710", name=rel, **kwargs)
    assert data == out.read_bytes(), (rel, flags)
    assert without_timing(report) == without_timing(json.loads(rep.read_text()))
    assert report["zones"], rel
    for z in report["zones"]:
        assert z["tool"] == tool, (z["tool"], z["tool_source"])
        if tool.startswith(("flat", "bull")):
            # Fusion's 0.5° swing needs more than a flat or bull-nose cutter's cap.
            assert z["reason"] == "tool_limited" and z["needed_deviation_deg"] > 0.4, z


def test_a_ball_at_its_tip_rewrites_x_y_z_and_at_its_centre_not() -> None:
    """SING is an M128 program: X Y Z state the ball's centre unless told otherwise."""
    data = read(SING)
    centre, rc = polepatch.patch_nc(data, "mikron-ucp710", tool="ball:10")
    tip, rt = polepatch.patch_nc(data, "mikron-ucp710", tool="ball:10", tool_point="tip")
    assert all(z["tool_point"] == "centre" for z in rc["zones"])
    assert all(z["tool_point"] == "tip" and z["tool_point_source"] == "--tool-point" for z in rt["zones"])
    assert all(z["outcome"] == "reached" for z in rt["zones"])

    def xyz(b: bytes) -> list:
        return [
            [w for w in line.split() if w[:1] in (b"X", b"Y", b"Z")]
            for line in b.splitlines()
        ]

    assert xyz(centre) == xyz(data)
    assert xyz(tip) != xyz(data)
    # The centre is kept: at most rounding in the file's decimals away.
    assert all(z["max_cutter_shift_mm"] <= 0.001 + 1e-9 for z in rt["zones"])


def test_post_cl_reads_the_cutter_and_takes_the_keywords(cli: Path, tmp_path: Path) -> None:
    out, rep = tmp_path / "out.I", tmp_path / "r.json"
    code, _, err = run_cli(
        cli, "post", APT, "-m", "mikron-ucp710", "--dialect", "heidenhain", "-o", str(out),
        "--report", str(rep),
    )
    assert code == 0, err
    cl = (ROOT / APT).read_bytes()
    assert polepatch.post_cl(cl, "mikron-ucp710", name=APT) == out.read_bytes()
    zones = json.loads(rep.read_text())["zones"]
    assert zones and all(z["tool"] == "ball D10" and z["tool_point"] == "tip" for z in zones)
    # The same tool given: the same program.
    given = polepatch.post_cl(cl, "mikron-ucp710", name=APT, tool="ball:10", tool_point="tip")
    assert given == out.read_bytes()


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(tool="ball"), "is not ball:D, flat:D or bull:D,R"),
        (dict(tool="bull:10,5"), "is not ball:D, flat:D or bull:D,R"),
        (dict(tool="cone:5"), "is not ball:D, flat:D or bull:D,R"),
        (dict(tool_point="side"), "is not tip or centre"),
        (dict(surface_tolerance_mm=0.0), "surface_tolerance_mm must be a positive number"),
        (dict(surface_tolerance_mm=float("nan")), "surface_tolerance_mm"),
    ],
)
def test_bad_tool_keywords_are_value_errors(kwargs: dict, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        polepatch.patch_nc(read(SING), "mikron-ucp710", **kwargs)
    with pytest.raises(ValueError, match=message):
        polepatch.post_cl((ROOT / APT).read_bytes(), "mikron-ucp710", **kwargs)
