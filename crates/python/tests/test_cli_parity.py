"""The package gives the CLI's bytes and reports: patch on every NC fixture and both
machines, analyze likewise, reorient with given angles and by search."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import polepatch
from conftest import MACHINES, ROOT, nc_fixtures, posted_for, read, run_cli, without_timing


def test_the_issue_check_sing_on_the_ucp710(cli: Path, tmp_path: Path) -> None:
    out, rep = tmp_path / "SING.I", tmp_path / "SING.json"
    code, _, err = run_cli(
        cli, "patch", "fixtures/c17/SING.I", "-m", "mikron-ucp710", "-o", str(out),
        "--report", str(rep),
    )
    assert code == 0, err
    data, report = polepatch.patch_nc(
        read("fixtures/c17/SING.I"), machine="mikron-ucp710", name="fixtures/c17/SING.I"
    )
    assert data == out.read_bytes()
    assert data != read("fixtures/c17/SING.I"), "SING has a zone to patch"
    cli_report = json.loads(rep.read_text())
    assert cli_report["output"] == str(out) and report["output"] is None
    assert without_timing(report) == without_timing(cli_report)
    assert report["zones"] and all(z["outcome"] == "reached" for z in report["zones"])


@pytest.mark.parametrize("machine", MACHINES)
def test_patch_nc_is_the_cli_on_every_fixture(cli: Path, tmp_path: Path, machine: str) -> None:
    # One batch run of the CLI over the fixtures folder: each output keeps its path under
    # --out-dir, the report lists the files it patched (a CL file there is refused).
    code, _, err = run_cli(
        cli, "patch", "fixtures", "--out-dir", str(tmp_path), "-m", machine,
        "--report", str(tmp_path / "report.json"),
    )
    cli_reports = {r["file"]: r for r in json.loads((tmp_path / "report.json").read_text())}
    errors = [line for line in err.splitlines() if line.startswith("polepatch: error: ")]
    assert code == (1 if errors else 0), err
    patched = 0
    for rel in nc_fixtures():
        try:
            data, report = polepatch.patch_nc(read(rel), machine, name=rel)
        except polepatch.InputError as e:
            # The CLI refused it with the same message, and wrote nothing.
            assert f"polepatch: error: {e}" in errors, (rel, str(e), err)
            assert e.path == rel
            assert not (tmp_path / rel).exists() and rel not in cli_reports
            continue
        assert data == (tmp_path / rel).read_bytes(), f"{rel} on {machine}"
        assert without_timing(report) == without_timing(cli_reports[rel]), rel
        patched += 1
    # Each machine patches the programs posted for it (A-C or B-C) and refuses the others
    # by name, with the same message as the CLI (checked above).
    assert patched >= 50, patched


def test_analyze_nc_is_the_cli_on_every_fixture(cli: Path) -> None:
    """Every fixture, on the two machines in turn (each machine sees every dialect and
    kind)."""
    fixtures = nc_fixtures()
    compared = 0
    for k, rel in enumerate(fixtures):
        machine = MACHINES[k % 2]
        if machine not in posted_for(read(rel)):
            machine = MACHINES[(k + 1) % 2]  # the machine the program was posted for
        code, out, err = run_cli(cli, "analyze", rel, "-m", machine, "--json")
        try:
            report = polepatch.analyze_nc(read(rel), machine, name=rel)
        except polepatch.InputError as e:
            assert code == 1 and f"polepatch: error: {e}" in err, (rel, err)
            continue
        assert report == json.loads(out), f"{rel} on {machine}"
        assert report["file"] == rel and report["runs"], rel
        # The file was read: runs that could not be analysed are in the report (with why)
        # and on stderr, and the CLI exits 0 (2 only with --strict, docs/user-guide.md).
        assert code == 0, err
        if any(r.get("error") for r in report["runs"]):
            assert "not analysed" in err, err
        compared += 1
    assert compared >= 90, compared


def test_reorient_is_the_cli(cli: Path, tmp_path: Path) -> None:
    rel = "fixtures/c17/SING.I"
    for args, kwargs in [
        (["--theta-x", "20", "--theta-z", "-35"], dict(theta_x=20.0, theta_z=-35.0)),
        ([], {}),  # the search for the smallest tilt
    ]:
        out = tmp_path / "out.I"
        code, stdout, err = run_cli(
            cli, "reorient", rel, "-m", "mikron-ucp710", "-o", str(out), "--json", *args
        )
        assert code == 0, err
        data, report = polepatch.reorient(read(rel), "mikron-ucp710", name=rel, **kwargs)
        assert data == out.read_bytes()
        assert report == json.loads(stdout)
        assert report["words_changed"] > 0
