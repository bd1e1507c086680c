"""The exceptions of polepatch (raised by the native module, exported by the package)."""

from __future__ import annotations

from typing import Optional

__all__ = ["InputError", "MachineError", "InternalError", "VerificationError"]


class InputError(ValueError):
    """The NC program, CL file or array cannot be used, and where.

    Attributes (``None`` where unknown or not applicable):

    - ``path``: the input's name, as given with ``name=`` (``None`` when no name was given);
    - ``line``: 1-based line of the fault in the NC program or CL file;
    - ``column``: 1-based byte column of the fault on that line;
    - ``index``: 0-based row of the fault in an array (``cl_to_joints``, ``patch_joints``).

    ``str(error)`` is the library's message, naming the value and where it is.
    """

    def __init__(
        self,
        message: str,
        *,
        path: Optional[str] = None,
        line: Optional[int] = None,
        column: Optional[int] = None,
        index: Optional[int] = None,
    ) -> None:
        super().__init__(message)
        self.path = path
        self.line = line
        self.column = column
        self.index = index


class MachineError(ValueError):
    """An unknown built-in machine name, or a machine TOML text that is invalid (the
    message names the field)."""


class InternalError(RuntimeError):
    """A bug in polepatch (a Rust panic, caught before it reached Python). Please report
    it with the input that caused it."""


class VerificationError(RuntimeError):
    """The patched program failed its check against the input (``polepatch verify``) even
    with every failing zone put back, so nothing is returned. ``str(error)`` names the lines
    and the checks; ``path`` is the input's name (``None`` when none was given) and
    ``line`` the first failing line (``None`` for the program as a whole)."""

    def __init__(self, message: str, *, path: Optional[str] = None, line: Optional[int] = None) -> None:
        super().__init__(message)
        self.path = path
        self.line = line
