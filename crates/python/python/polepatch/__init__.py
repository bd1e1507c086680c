"""polepatch: find and patch the places where the rotary axes slow a table-table 5-axis
machine near the kinematic pole.

The Rust library itself, called in-process: :func:`patch_nc` gives the same bytes and the
same report as ``polepatch patch --report``, :func:`analyze_nc` the report of
``polepatch analyze --json``, :func:`post_cl` the program of ``polepatch post``,
:func:`reorient` that of ``polepatch reorient``; :func:`feed_profile` samples Equation 6
along every run (for plots). :func:`cl_to_joints` and :func:`patch_joints` work on numpy
arrays of CL points and joint values.

Units everywhere: lengths mm, angles degrees, feeds mm/min, times as their names say
(``tcy_ms`` in ms; report fields end in ``_s``, ``_ms``, ``_mm``, ``_deg``). Reports are
the library's JSON documents as dicts (``json.loads``), so their keys and units are those
of the CLI's reports (docs/user-guide.md).

Errors: bad input raises :class:`InputError` (a ``ValueError``) with ``.path``, ``.line``,
``.column``; an unknown or invalid machine :class:`MachineError` (a ``ValueError``); a bad
option ``ValueError`` naming it. A zone that cannot reach feed is not an error: it is a
status in the report. Every call releases the GIL while it works, so threads run calls
in parallel; a Rust panic arrives as :class:`InternalError`, never as a crash.
"""

from __future__ import annotations

import json
import os
from typing import TYPE_CHECKING, Any, Dict, List, Optional, Tuple, Union

from . import _polepatch as _native
from ._errors import InputError, InternalError, MachineError, VerificationError

if TYPE_CHECKING:  # numpy is imported by the array calls only
    import os

    import numpy as np
    import numpy.typing as npt

__version__: str = _native.__version__

__all__ = [
    "Machine",
    "patch_nc",
    "analyze_nc",
    "feed_profile",
    "post_cl",
    "reorient",
    "cl_to_joints",
    "patch_joints",
    "InputError",
    "MachineError",
    "InternalError",
    "VerificationError",
]


class Machine:
    """A table-table 5-axis machine: axes, senses, ranges, the V/A/J limits of every axis
    and the interpolation cycle time. Immutable; share it between threads freely.

    Make one with :meth:`builtin`, :meth:`from_toml` or :meth:`from_file`. Every
    ``machine=`` argument of this package takes a ``Machine`` or a built-in name.
    """

    __slots__ = ("_native",)

    def __init__(self, native: _native.NativeMachine) -> None:
        """Use :meth:`builtin`, :meth:`from_toml` or :meth:`from_file`."""
        if not isinstance(native, _native.NativeMachine):
            raise TypeError(
                "make a Machine with Machine.builtin(name), Machine.from_toml(text) or "
                "Machine.from_file(path)"
            )
        self._native = native

    @classmethod
    def builtin(cls, name: str) -> Machine:
        """A built-in machine by name (:meth:`builtin_names`: ``"mikron-ucp710"``,
        ``"mikron-hsm600"``, the machines of G16's Tables 2 and 3).

        Raises :class:`MachineError` for an unknown name (the message lists the names).
        """
        return cls(_native.NativeMachine.builtin(name))

    @classmethod
    def from_toml(cls, text: str, origin: str = "machine TOML") -> Machine:
        """A machine from the text of a machine TOML file (the format of the README:
        limits in m/min, m/s², m/s³ and rpm, rev/s², rev/s³; ``tcy_ms``; ranges in
        degrees; an optional ``[chain]``). ``origin`` names the text in error messages.

        Raises :class:`MachineError` naming the field that is missing or invalid.
        """
        return cls(_native.NativeMachine.from_toml(text, origin))

    @classmethod
    def from_file(cls, path: Union[str, os.PathLike[str]]) -> Machine:
        """A machine from a machine TOML file (UTF-8), as :meth:`from_toml`. At most
        1 MiB is read: a longer file, or a device such as ``/dev/zero``, raises
        :class:`MachineError`."""
        return cls(_native.NativeMachine.from_file(os.fspath(path)))

    @staticmethod
    def builtin_names() -> List[str]:
        """Names of the built-in machines."""
        return list(_native.NativeMachine.builtin_names())

    @property
    def name(self) -> str:
        """The machine's name (``name`` in its TOML)."""
        return self._native.name

    @property
    def primary(self) -> str:
        """Letter of the primary (tilting) rotary axis: ``"A"`` (about X) or ``"B"``
        (about Y)."""
        return self._native.primary

    @property
    def tcy_ms(self) -> float:
        """Interpolation cycle time Tcy, ms."""
        return self._native.tcy_ms

    @property
    def primary_range_deg(self) -> Tuple[float, float]:
        """Travel of the primary axis, degrees (min, max)."""
        return self._native.primary_range_deg

    @property
    def c_range_deg(self) -> Optional[Tuple[float, float]]:
        """Travel of C, degrees (min, max); ``None`` for an endless C axis."""
        return self._native.c_range_deg

    @property
    def limits(self) -> Dict[str, Tuple[float, float, float]]:
        """``{letter: (v, a, j)}`` for X, Y, Z, the primary axis and C: velocity,
        acceleration and jerk limits in mm/s, mm/s², mm/s³ (X Y Z) and °/s, °/s², °/s³
        (rotary axes) — the units of Equation 6, converted from the TOML's once."""
        return self._native.limits

    def tool_axis(self, p_deg: float, c_deg: float) -> Tuple[float, float, float]:
        """Forward kinematics: the unit tool axis (i, j, k) in the part frame with the
        primary axis at ``p_deg`` and C at ``c_deg`` (degrees, the machine's senses)."""
        return self._native.tool_axis(p_deg, c_deg)

    def __repr__(self) -> str:
        return f"Machine({self.name!r}, primary={self.primary!r}, tcy_ms={self.tcy_ms})"


#: A machine argument: a :class:`Machine` or a built-in name.
MachineLike = Union[Machine, str]


def _machine(machine: MachineLike) -> _native.NativeMachine:
    if isinstance(machine, Machine):
        return machine._native
    if isinstance(machine, str):
        return _native.NativeMachine.builtin(machine)
    raise TypeError(
        f"machine must be a polepatch.Machine or a built-in name, got {type(machine).__name__}"
    )


def _bytes(data: Any, what: str) -> bytes:
    if isinstance(data, bytes):
        return data
    if isinstance(data, (bytearray, memoryview)):
        return bytes(data)
    raise TypeError(
        f"{what} must be bytes (read the file with open(path, 'rb')), got {type(data).__name__}"
    )


def _report(text: str) -> Dict[str, Any]:
    """A report as a dict: the library's JSON document, read once."""
    report: Dict[str, Any] = json.loads(text)
    return report


def _options(arguments: Dict[str, Any], *positional: str) -> Dict[str, Any]:
    """A call's keyword options (its ``locals()`` less its positional arguments): the
    native module reads them by name."""
    return {k: v for k, v in arguments.items() if k not in positional}


def patch_nc(
    data: bytes,
    machine: MachineLike,
    *,
    only_c: bool = False,
    cone_deg: float = 5.0,
    max_deviation_deg: Optional[float] = None,
    tcy_ms: Optional[float] = None,
    margin: float = 0.02,
    max_decimals: int = 6,
    max_patch_length_mm: Optional[float] = None,
    jerk_continuity: bool = True,
    allow_c_offset: bool = False,
    feed_fallback_mm_min: Optional[float] = None,
    work_offset_mm: Optional[Tuple[float, float, float]] = None,
    name: Optional[str] = None,
    tool: Optional[str] = None,
    tool_point: Optional[str] = None,
    surface_tolerance_mm: float = 0.005,
) -> Tuple[bytes, Dict[str, Any]]:
    """Patch an NC program: the rewritten bytes and the report.

    The output is ``data`` byte for byte except the rotary words that had to change, and
    X Y Z where a ball-end mill programmed at its tip keeps its centre (the bytes
    ``polepatch patch`` writes). The report is the document of
    ``polepatch patch --report`` for one file: per zone the lines, kind, feed ratios
    before/after, times (s), orientation deviation (degrees), points changed, QP status
    and solve time (``solve_time_ms``, measured); ``output`` is ``None`` (no file is
    written here).

    Args:
        data: the program's bytes (any encoding; non-UTF-8 bytes pass through).
        machine: a :class:`Machine` or a built-in name.
        only_c: change C only (G16's method); default both rotary axes may change.
        cone_deg: singular cone, degrees: a stretch where C is below feed with a point
            with |primary| ≤ this is a zone; out to the pole reach (10°) beyond it, a
            stretch is a zone where the pole dominates its slowdown (docs/method.md).
        max_deviation_deg: largest change of tool orientation allowed, degrees
            (``None``: no limit; the deviation is minimised anyway).
        tcy_ms: interpolation cycle time, ms (``None``: the machine's). Accepted for
            compatibility: Equation 6 is bounded exactly over every span, so it changes no
            figure (the CLI has no such option for `patch`).
        margin: safety margin on the V/A/J limits, a fraction in [0, 0.5).
        max_decimals: most decimals written for a rotary value when the file's are not
            enough to hold Equation 6 (at most 9).
        max_patch_length_mm: longest patch, mm (``None``: up to the whole run).
        jerk_continuity: ask for third-derivative continuity at the joins.
        allow_c_offset: allow a 360° multiple offset of C after a zone.
        feed_fallback_mm_min: feed, mm/min, for runs with no F in force (``None``: such
            runs are reported and left as they are).
        work_offset_mm: work offset X, Y, Z, mm (machine coordinates of the program's
            zero), for a machine with a ``[chain]``; ``None``: the program's datum.
        name: the input's name in messages, errors (``InputError.path``) and the report
            (``file``); ``None``: ``"input"`` in messages and no ``path``.
        tool: the cutter for the whole program, as the CLI's ``--tool``: ``"ball:10"``,
            ``"flat:12"``, ``"bull:10,2"`` (diameter and corner radius, mm); ``None``:
            per run from the program (``TOOL DEF``, the CAM post's tool comments), else
            unknown (the report's ``tool`` is ``"unknown"`` and a warning says so). A ball
            programmed at its tip keeps its centre (X Y Z rewritten where the orientation
            changes); a flat or bull-nose cutter's orientation change is capped by
            ``surface_tolerance_mm`` (reason ``tool_limited``).
        tool_point: which point of the tool the program's X Y Z are, ``"tip"`` or
            ``"centre"`` (``--tool-point``); ``None``: the machine file's, else the TCPM
            code's (``M128`` and ``REFPNT CENTER-CENTER`` the centre, every other the tip).
        surface_tolerance_mm: how far a flat or bull-nose cutter's surface may move at a
            CL point, mm (``--surface-tolerance``).

    Raises:
        InputError: a syntax error (with ``line`` and ``column``), an unsupported form
            (with ``line``), an empty program or one without G1 motion or rotary words.
        MachineError: an unknown built-in name.
        ValueError: an option out of range (named).
        KeyboardInterrupt: Ctrl-C (SIGINT) during the call: the patch stops at its next
            stretch near the pole (it looks for signals every 50 ms), nothing is returned.
    """
    options = _options(locals(), "data", "machine")
    out, report = _native.patch_nc(_bytes(data, "data"), _machine(machine), options)
    return out, _report(report)


def analyze_nc(
    data: bytes,
    machine: MachineLike,
    *,
    cone_deg: float = 5.0,
    tcy_ms: Optional[float] = None,
    feed_fallback_mm_min: Optional[float] = None,
    work_offset_mm: Optional[Tuple[float, float, float]] = None,
    name: Optional[str] = None,
) -> Dict[str, Any]:
    """Equation 6 along every G1 run: the report of ``polepatch analyze --json``.

    Per run: lines, points, length (mm), feed (mm/min), the lowest feed ratio and the
    axis and limit (V, A, J) that sets it, estimated and ideal times (s), peak speeds at
    the programmed feed (m/min for X Y Z, rpm for the rotary axes), the lowest ratio per
    axis, and the singular zones (lines, kind, min |primary| in degrees, C ratio).

    Options as :func:`patch_nc`'s of the same names.

    Raises:
        InputError, MachineError, ValueError: as :func:`patch_nc`.
    """
    options = _options(locals(), "data", "machine")
    report = _native.analyze_nc(_bytes(data, "data"), _machine(machine), options)
    return _report(report)


def feed_profile(
    data: bytes,
    machine: MachineLike,
    *,
    cone_deg: float = 5.0,
    tcy_ms: Optional[float] = None,
    feed_fallback_mm_min: Optional[float] = None,
    work_offset_mm: Optional[Tuple[float, float, float]] = None,
    name: Optional[str] = None,
) -> List[Dict[str, Any]]:
    """Equation 6 sampled along every G1 run: the curves behind :func:`analyze_nc`'s
    minima, for plots (``examples/notebook.py``).

    The samples are where the analysis evaluated Equation 6 on the analysis spline: every
    CL point, and inside a span below feed the points of its adaptive bisection (a span
    is bounded exactly by its largest derivatives, so no figure depends on Tcy). Options as :func:`analyze_nc`'s. The whole program is parsed at once
    (about ten times its size in memory).

    Returns:
        One dict per run, in file order: ``run`` (number from 1), ``lines`` (first and
        last file line), ``feed_mm_min``, ``s_mm`` (``(m,)`` array, mm along the run),
        ``ratio`` (``(m,)``: reachable feed / programmed feed, in (0, 1]),
        ``axis_ratio`` (``(m, 5)``: the same per axis, columns in ``axes`` order),
        ``axes`` (the five letters, e.g. ``["X", "Y", "Z", "A", "C"]``),
        ``point_s_mm`` (``(n,)``: s of each CL point of the run), ``point_lines`` (the
        file line of each CL point) and ``error`` (why the run was not analysed, e.g. no
        feed; then the sample arrays are empty).

    Raises:
        InputError, MachineError, ValueError: as :func:`analyze_nc`.
    """
    options = _options(locals(), "data", "machine")
    return _native.feed_profile(_bytes(data, "data"), _machine(machine), options)


def post_cl(
    cl: Union[str, bytes],
    machine: MachineLike,
    dialect: str = "heidenhain",
    *,
    branch: str = "nearest",
    patch: bool = True,
    rotary_decimals: int = 3,
    linear_decimals: int = 3,
    only_c: bool = False,
    cone_deg: float = 5.0,
    max_deviation_deg: Optional[float] = None,
    tcy_ms: Optional[float] = None,
    margin: float = 0.02,
    max_decimals: int = 6,
    max_patch_length_mm: Optional[float] = None,
    jerk_continuity: bool = True,
    allow_c_offset: bool = False,
    feed_fallback_mm_min: Optional[float] = None,
    work_offset_mm: Optional[Tuple[float, float, float]] = None,
    name: Optional[str] = None,
    tool: Optional[str] = None,
    tool_point: Optional[str] = None,
    surface_tolerance_mm: float = 0.005,
) -> bytes:
    """Post a CL file as a TCPM program for ``machine``, with pole handling: the bytes
    of ``polepatch post``.

    The CL points (APT CLDATA ``GOTO/x,y,z,i,j,k`` with ``FEDRAT``, or CSV
    ``x,y,z,i,j,k[,f]``; mm and mm/min) get their joints from the machine's inverse
    kinematics, are written in ``dialect``, and (unless ``patch=False``) the program is
    patched by :func:`patch_nc` with the patch options given here — so
    ``patch_nc(post_cl(cl, m, patch=False), m)[0] == post_cl(cl, m)``; call it that way
    for the report.

    Args:
        cl: the CL file's text (``str``) or bytes (UTF-8).
        machine: a :class:`Machine` or a built-in name.
        dialect: ``"heidenhain"`` (ISO), ``"sinumerik"`` or ``"fanuc"``.
        branch: IK branch rule: ``"nearest"`` (continuous), ``"domain"`` (G16 Table 1:
            P flips sign near the pole), ``"positive"`` (P ≥ 0), ``"negative"`` (P ≤ 0).
        patch: patch the posted program (``False``: the joints as the IK gives them).
        rotary_decimals: decimals of the rotary words (at most 9).
        linear_decimals: decimals of X Y Z (at most 9).
        feed_fallback_mm_min: feed, mm/min, for points without one.
        name: the CL file's name in messages, errors and the program's comment.
        only_c, cone_deg, …: the patch options of :func:`patch_nc`.
        tool, tool_point, surface_tolerance_mm: as :func:`patch_nc`'s; ``None`` here:
            the CL file's ``CUTTER/`` (or ``TLDATA/MILL``) and the tool tip (APT's
            ``GOTO/`` states the tip), as ``polepatch post`` does.

    Raises:
        InputError: a bad CL record (with ``line`` and ``column``), a point that needs
            the primary axis outside its range or has no feed (with ``line``).
        MachineError, ValueError: as :func:`patch_nc`.
    """
    if isinstance(cl, str):
        cl = cl.encode("utf-8")
    options = _options(locals(), "cl", "machine")
    return _native.post_cl(_bytes(cl, "cl"), _machine(machine), options)


def reorient(
    data: bytes,
    machine: MachineLike,
    theta_x: Optional[float] = None,
    theta_z: Optional[float] = None,
    *,
    pivot_mm: Optional[Tuple[float, float, float]] = None,
    cone_deg: float = 5.0,
    name: Optional[str] = None,
) -> Tuple[bytes, Dict[str, Any]]:
    """Tilt the workpiece on a jig (C17's avoidance): the program rewritten for the
    tilted part, and the report of ``polepatch reorient --json``.

    With ``theta_x`` and ``theta_z`` (degrees; R = Rx(θx)·Rz(θz), θz applied first) the
    program is reoriented by that tilt; with neither, the smallest tilt that makes the
    program reach feed on both rotary axes is searched for (the report lists the
    candidates). Tool-tip positions turn about ``pivot_mm`` (X, Y, Z in mm; default the
    program's origin). Only the changed words differ from ``data``.

    Raises:
        InputError: bad input, or no tilt found by the search (with the largest tried).
        ValueError: only one of ``theta_x``, ``theta_z`` given, or a value not finite.
        MachineError: as :func:`patch_nc`.
    """
    out, report = _native.reorient(
        _bytes(data, "data"), _machine(machine), theta_x, theta_z, pivot_mm, cone_deg, name
    )
    return out, _report(report)


def _rows(a: Any, n_cols: int, what: str) -> np.ndarray:
    import numpy as np

    arr = np.asarray(a, dtype=np.float64)
    if arr.ndim != 2 or arr.shape[1] != n_cols:
        raise ValueError(f"{what} must have shape (n, {n_cols}), got {arr.shape}")
    return arr


def cl_to_joints(
    xyzijk: npt.ArrayLike, machine: MachineLike, *, branch: str = "nearest"
) -> np.ndarray:
    """Joints for CL points: the machine's inverse kinematics on an ``(n, 6)`` array.

    Args:
        xyzijk: rows ``x, y, z, i, j, k``: tool tip in the part frame (mm) and tool axis
            (any length but zero; normalised here).
        machine: a :class:`Machine` or a built-in name.
        branch: IK branch rule, as :func:`post_cl`'s.

    Returns:
        An ``(n, 5)`` float64 array of rows ``x, y, z, p, c``: x y z as given, the
        primary axis and C in degrees (C continuous along the rows). It owns its memory
        (no copy was made to return it).

    Raises:
        InputError: a value that is not finite, a zero tool axis, or a joint value
            outside the machine's range on the branch picked (e.g. A = 180° where A ends
            at 120°) (``index``: the row).
        ValueError: a wrong shape or branch name.
    """
    arr = _rows(xyzijk, 6, "xyzijk")
    return _native.cl_to_joints(arr, _machine(machine), branch)


def patch_joints(
    xyzpc: npt.ArrayLike,
    machine: MachineLike,
    feed_mm_min: float,
    *,
    only_c: bool = False,
    cone_deg: float = 5.0,
    max_deviation_deg: Optional[float] = None,
    tcy_ms: Optional[float] = None,
    margin: float = 0.02,
    max_decimals: int = 6,
    max_patch_length_mm: Optional[float] = None,
    jerk_continuity: bool = True,
    allow_c_offset: bool = False,
) -> Tuple[np.ndarray, List[Dict[str, Any]]]:
    """Patch one run of joint values held in memory (a CAM plugin's toolpath).

    Args:
        xyzpc: ``(n, 5)`` rows ``x, y, z, p, c``: tool tip in the part frame (mm, as
            under TCPM) and the primary axis and C (degrees), moved through in order.
        machine: a :class:`Machine` or a built-in name.
        feed_mm_min: the programmed feed, mm/min.
        only_c, cone_deg, …: as :func:`patch_nc`'s. ``max_decimals`` is also the
            precision the new values are verified and rounded at.

    Returns:
        ``(xyzpc, zones)``: an ``(n, 5)`` float64 array with the new p and c (x y z
        unchanged; the first and last rows keep their values), and one dict per singular
        zone — the patcher's zone report: ``first``/``last`` row, ``kind``,
        ``min_abs_primary_deg``, ``before``/``after`` figures (feed ratios, limiting axis
        and limit, ``time_s``), ``ideal_time_s``, ``max_deviation_deg``,
        ``points_modified``, ``outcome`` (``reached``, ``improved``, ``unchanged``),
        ``method``, ``qp`` (status, iterations, solves, ``solve_time_s``), decimals.

    Raises:
        InputError: fewer than two rows, two consecutive rows with the same tool tip
            (``index``: the second), a value not finite, a feed not positive.
        ValueError: a wrong shape or an option out of range.
    """
    options = _options(locals(), "xyzpc", "machine", "feed_mm_min")
    arr = _rows(xyzpc, 5, "xyzpc")
    out, zones = _native.patch_joints(arr, _machine(machine), float(feed_mm_min), options)
    zone_reports: List[Dict[str, Any]] = json.loads(zones)
    return out, zone_reports
