"""The examples run: the FreeCAD post (with a stand-in for FreeCAD's base post, and as a
script) and the notebook (when matplotlib is installed: the `examples` extra)."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
import types
from pathlib import Path

import pytest

import polepatch
from conftest import ROOT, read


def load_post():
    path = ROOT / "examples/freecad/polepatch_post.py"
    spec = importlib.util.spec_from_file_location("polepatch_post", path)
    module = importlib.util.module_from_spec(spec)
    assert spec.loader is not None
    spec.loader.exec_module(module)
    return module


def test_the_freecad_post_patches_the_base_posts_program(tmp_path: Path, monkeypatch) -> None:
    post = load_post()
    # A B-C program for --polepatch-machine mikron-hsm600; C17's SING (A-C) for the
    # post's default MACHINE.
    bc = read("fixtures/generated/heidenhain-bc-swing-d0.1.I").decode("ascii")
    sing = read("fixtures/c17/SING.I").decode("ascii")
    program = [bc]
    calls = []

    def base_export(objectslist, filename, argstring):
        calls.append((objectslist, filename, argstring))
        return program[0]

    fake = types.ModuleType("standin_post")
    fake.export = base_export
    monkeypatch.setitem(sys.modules, "standin_post", fake)
    out = tmp_path / "job.I"
    args = "--polepatch-base standin --polepatch-machine mikron-hsm600 --no-header --precision 4"
    returned = post.export(["op"], str(out), args)
    # The base post got its own arguments and "-" (return, do not write).
    assert calls == [(["op"], "-", "--no-header --precision 4")]
    want, report = polepatch.patch_nc(bc.encode(), "mikron-hsm600")
    assert report["zones"] and want != bc.encode()
    assert out.read_bytes() == want and returned == want.decode()
    # "-": returned, not written; the default machine.
    program[0] = sing
    assert post.export([], "-", "--polepatch-base standin") == polepatch.patch_nc(
        sing.encode(), post.MACHINE
    )[0].decode()


def test_the_freecad_post_as_a_script_keeps_non_utf8_bytes(tmp_path: Path) -> None:
    rel = "fixtures/dialects/heidenhain_latin1.I"
    out = tmp_path / "out.I"
    r = subprocess.run(
        [sys.executable, str(ROOT / "examples/freecad/polepatch_post.py"), "mikron-ucp710", rel, str(out)],
        cwd=ROOT, capture_output=True, text=True, check=False,
    )
    assert r.returncode == 0, r.stderr
    data = read(rel)
    try:
        data.decode("utf-8")
        raise AssertionError(f"{rel} was meant to hold non-UTF-8 bytes")
    except UnicodeDecodeError:
        pass
    assert out.read_bytes() == polepatch.patch_nc(data, "mikron-ucp710")[0]


def test_the_notebook_runs_and_draws(tmp_path: Path) -> None:
    if importlib.util.find_spec("matplotlib") is None:
        pytest.skip("matplotlib is not installed (pip install 'crates/python[examples]')")
    fig = tmp_path / "feed.png"
    r = subprocess.run(
        [sys.executable, str(ROOT / "examples/notebook.py"), "--out", str(fig)],
        cwd=tmp_path, capture_output=True, text=True, check=False,
    )
    assert r.returncode == 0, r.stderr
    assert "reached (joint), C ratio 0.104 → 1.000" in r.stdout, r.stdout
    assert fig.stat().st_size > 10_000
