"""The API as declared: keyword defaults are the library's, the stubs name what the
native module has, Machine's properties."""

from __future__ import annotations

import ast
import inspect
from pathlib import Path

import polepatch
from polepatch import _polepatch as native


def test_keyword_defaults_are_the_librarys() -> None:
    d = native.defaults()
    groups = {
        polepatch.patch_nc: ["patch", "file", "tool"],
        polepatch.post_cl: ["patch", "file", "tool", "post"],
        polepatch.patch_joints: ["patch"],
        polepatch.analyze_nc: ["analyze", "file"],
        polepatch.feed_profile: ["analyze", "file"],
    }
    for fn, names in groups.items():
        params = inspect.signature(fn).parameters
        expected = {k: v for g in names for k, v in d[g].items()}
        for k, v in expected.items():
            assert k in params, (fn.__name__, k)
            assert params[k].default == v, (fn.__name__, k, params[k].default, v)
    # Every keyword of those calls is one the native module reads (none is ignored).
    for fn, names in groups.items():
        known = {k for g in names for k in d[g]}
        for name, p in inspect.signature(fn).parameters.items():
            if p.kind is inspect.Parameter.KEYWORD_ONLY:
                assert name in known, (fn.__name__, name)
    assert inspect.signature(polepatch.reorient).parameters["cone_deg"].default == d["analyze"]["cone_deg"]


def test_the_stub_names_what_the_native_module_has() -> None:
    stub = Path(polepatch.__file__).with_name("_polepatch.pyi")
    tree = ast.parse(stub.read_text())
    declared = set()
    methods = set()
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            declared.add(node.name)
        elif isinstance(node, ast.ClassDef):
            declared.add(node.name)
            methods |= {n.name for n in node.body if isinstance(n, ast.FunctionDef)}
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            declared.add(node.target.id)
    have = {n for n in dir(native) if not n.startswith("__") or n == "__version__"}
    assert declared == have, (declared ^ have)
    have_methods = {n for n in dir(native.NativeMachine) if not n.startswith("__")}
    assert methods == have_methods, (methods ^ have_methods)
    assert (Path(polepatch.__file__).with_name("py.typed")).exists()


def test_machine_properties_in_their_units() -> None:
    m = polepatch.Machine.builtin("mikron-ucp710")
    assert (m.name, m.primary, m.tcy_ms) == ("mikron-ucp710", "A", 1.0)
    v, a, j = m.limits["C"]
    # 20 rpm, 0.83 rev/s², 50 rev/s³ (SPEC §1) in °/s, °/s², °/s³.
    assert (v, a, j) == (120.0, 0.83 * 360, 50 * 360)
    assert abs(m.limits["X"][0] - 30 * 1000 / 60) < 1e-12  # 30 m/min in mm/s
    # G16 eq. 1 on the UCP710: i = sin C sin A, j = −cos C sin A, k = cos A.
    i, jj, k = m.tool_axis(30.0, 90.0)
    assert abs(i - 0.5) < 1e-12 and abs(jj) < 1e-12 and abs(k - 3**0.5 / 2) < 1e-12
    assert polepatch.Machine.builtin_names() == ["mikron-ucp710", "mikron-hsm600"]
    b = polepatch.Machine.builtin("mikron-hsm600")
    assert b.primary == "B" and "B" in b.limits and "A" not in b.limits
    assert repr(m).startswith("Machine('mikron-ucp710'")
