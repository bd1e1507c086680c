"""Shared helpers of the polepatch Python tests: the repository, its NC fixtures, the CLI."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path
from typing import Any, Dict, List, Tuple

import pytest

ROOT = Path(__file__).resolve().parents[3]
MACHINES = ["mikron-ucp710", "mikron-hsm600"]

# The extensions of `polepatch_fixturegen::nc_files`, the fixture list the Rust suites share.
NC_EXTENSIONS = {".I", ".H", ".mpf", ".MPF", ".nc", ".NC", ".ngc", ".tap"}


def posted_for(data: bytes) -> List[str]:
    """The built-in machines a program was posted for: those whose rotary letters it uses
    (on the others it is refused by name, issue 29 — checked here)."""
    import polepatch

    fit = []
    for m in MACHINES:
        try:
            polepatch.analyze_nc(data, m)
        except polepatch.InputError as e:
            if " is not an axis of machine " in str(e):
                assert e.line >= 1 and e.column >= 1, str(e)
                continue
        fit.append(m)
    return fit


def nc_fixtures() -> List[str]:
    """Every NC program under fixtures/ (recursively, by extension), sorted, as paths
    relative to the repository root (the names the CLI prints in its reports)."""
    found = [
        p.relative_to(ROOT).as_posix()
        for p in (ROOT / "fixtures").rglob("*")
        if p.is_file() and p.suffix in NC_EXTENSIONS
    ]
    assert found, "no NC fixtures under fixtures/"
    return sorted(found)


@pytest.fixture(scope="session")
def cli() -> Path:
    """The `polepatch` binary to compare with: $POLEPATCH_CLI (.ci/run sets it; it must
    exist), else target/release/polepatch, else target/debug/polepatch of this checkout."""
    given = os.environ.get("POLEPATCH_CLI")
    if given:
        path = Path(given)
        assert path.is_file(), f"POLEPATCH_CLI={given} does not exist"
        return path
    for p in (ROOT / "target/release/polepatch", ROOT / "target/debug/polepatch"):
        if p.is_file():
            return p
    pytest.skip(
        "the polepatch CLI is not built: run `cargo build --release -p polepatch-cli` "
        "(or set POLEPATCH_CLI) to compare the package with it"
    )


def run_cli(cli: Path, *args: str) -> Tuple[int, str, str]:
    """Run the CLI in the repository root: (exit code, stdout, stderr)."""
    r = subprocess.run(
        [str(cli), *args], cwd=ROOT, capture_output=True, text=True, check=False
    )
    return r.returncode, r.stdout, r.stderr


def without_timing(report: Dict[str, Any]) -> Dict[str, Any]:
    """A patch report without what is measured (solve times) or names the output file
    (the Python call writes none)."""
    r = json.loads(json.dumps(report))
    r.pop("output", None)
    for z in r["zones"]:
        z.pop("solve_time_ms")
    return r


def read(rel: str) -> bytes:
    return (ROOT / rel).read_bytes()
