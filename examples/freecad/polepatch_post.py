"""polepatch_post.py: a FreeCAD CAM post-processor that hands another post's program to
polepatch before it is written, so the rotary axes reach the programmed feed near the pole.

FreeCAD (0.19 and later) lists the files named ``*_post.py`` in its macro folder as post
processors. To use this one:

1. Install the polepatch package into the Python FreeCAD runs (Help → About shows it), e.g.
   ``<that python> -m pip install /path/to/polepatch/crates/python`` (needs Rust).
2. Copy this file into the macro folder (Preferences → Python → Macro → Macro path).
3. Set ``BASE_POST`` and ``MACHINE`` below, or pass ``--polepatch-machine NAME_OR_TOML``,
   ``--polepatch-base POST`` and ``--polepatch-only-c`` in the job's post-processor
   arguments (the other arguments go to the base post unchanged).
4. Choose ``polepatch`` as the job's post-processor.

The program the base post writes is patched by :func:`polepatch.patch_nc`: byte for byte the
same except the rotary words that must change near the pole, with the report printed to
FreeCAD's report view. Bad input (a syntax error with its line and column) stops the post
with nothing written.

Any other Python post does the same in one line before it writes its output::

    gcode = patch_program(gcode, machine="mikron-ucp710", name=filename)

Run outside FreeCAD, this file patches NC files the same way:
``python polepatch_post.py MACHINE INPUT OUTPUT``.
"""

from __future__ import annotations

import importlib
import shlex
import sys
from types import ModuleType
from typing import Any, List, Optional, Tuple

import polepatch

TOOLTIP = """polepatch: the base post's program, patched so that the rotary axes
reach the programmed feed near the kinematic pole (table-table 5-axis machines)."""

#: The FreeCAD post whose program is patched (its file is ``<BASE_POST>_post.py``).
BASE_POST = "linuxcnc"
#: The machine: a built-in name (``polepatch.Machine.builtin_names()``) or a TOML file.
MACHINE = "mikron-ucp710"

TOOLTIP_ARGS = """
--polepatch-machine NAME_OR_TOML  machine (default: MACHINE in this file)
--polepatch-base POST             base post (default: BASE_POST in this file)
--polepatch-only-c                change C only (G16's method)
(every other argument goes to the base post)"""


def machine_of(name_or_toml: str) -> polepatch.Machine:
    """A built-in machine by name, else a machine TOML file."""
    if name_or_toml in polepatch.Machine.builtin_names():
        return polepatch.Machine.builtin(name_or_toml)
    return polepatch.Machine.from_file(name_or_toml)


def patch_program(
    gcode: str, machine: Any = MACHINE, name: Optional[str] = None, only_c: bool = False
) -> str:
    """The program ``gcode`` with its pole zones patched for ``machine`` (a
    ``polepatch.Machine``, a built-in name or a TOML file); prints one line per zone."""
    if isinstance(machine, str):
        machine = machine_of(machine)
    # Bytes that are not UTF-8 (a Latin-1 comment) pass through as surrogates and back.
    data = gcode.encode("utf-8", "surrogateescape")
    out, report = polepatch.patch_nc(data, machine, only_c=only_c, name=name)
    for z in report["zones"]:
        print(
            f"polepatch: {report['file']}: run {z['run']}, lines {z['lines'][0]}–{z['lines'][1]}: "
            f"{z['outcome']}, C feed ratio {z['before']['c_ratio']:.3f} → {z['after']['c_ratio']:.3f}, "
            f"max orientation change {z['max_deviation_deg']:.3f}°"
        )
    for u in report["untouched_runs"]:
        print(f"polepatch: {report['file']}: run {u['run']} left as it is: {u['message']}")
    for w in report["warnings"]:
        print(f"polepatch: warning: {w}")
    return out.decode("utf-8", "surrogateescape")


def base_post(name: str) -> ModuleType:
    """FreeCAD's post module ``<name>_post`` (FreeCAD ≥ 0.21/1.0: ``Path.Post.scripts``;
    0.19–0.20: ``PathScripts.post``; else a module on the macro path)."""
    for module in (
        f"Path.Post.scripts.{name}_post",
        f"PathScripts.post.{name}_post",
        f"{name}_post",
    ):
        try:
            return importlib.import_module(module)
        except ImportError:
            continue
    raise ImportError(f"no FreeCAD post named '{name}' ({name}_post.py)")


def split_arguments(argstring: Optional[str]) -> Tuple[str, str, bool, str]:
    """(machine, base post, only C, the base post's arguments) from the job's arguments."""
    machine, base, only_c = MACHINE, BASE_POST, False
    rest: List[str] = []
    words = shlex.split(argstring or "")
    i = 0
    while i < len(words):
        w = words[i]
        if w == "--polepatch-only-c":
            only_c = True
        elif w in ("--polepatch-machine", "--polepatch-base") and i + 1 < len(words):
            if w == "--polepatch-machine":
                machine = words[i + 1]
            else:
                base = words[i + 1]
            i += 1
        else:
            rest.append(w)
        i += 1
    return machine, base, only_c, " ".join(shlex.quote(w) for w in rest)


def export(objectslist: Any, filename: str, argstring: Optional[str]) -> str:
    """FreeCAD's entry point: the base post's program for ``objectslist``, patched, written
    to ``filename`` (not written when ``filename`` is ``"-"``) and returned."""
    machine, base, only_c, base_args = split_arguments(argstring)
    # "-": the base post returns its program without writing it.
    gcode: str = base_post(base).export(objectslist, "-", base_args)
    if not gcode:
        return gcode
    patched = patch_program(gcode, machine, name=filename, only_c=only_c)
    if filename != "-":
        with open(filename, "w", encoding="utf-8", errors="surrogateescape", newline="") as f:
            f.write(patched)
    return patched


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit("usage: python polepatch_post.py MACHINE INPUT OUTPUT")
    machine_name, input_path, output_path = sys.argv[1:]
    with open(input_path, encoding="utf-8", errors="surrogateescape", newline="") as f:
        text = f.read()
    with open(output_path, "w", encoding="utf-8", errors="surrogateescape", newline="") as f:
        f.write(patch_program(text, machine_name, name=input_path))
