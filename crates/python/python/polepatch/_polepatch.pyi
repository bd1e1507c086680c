"""Type stubs of the native module ``polepatch._polepatch`` (Rust, PyO3).

Private: use the ``polepatch`` package, whose functions check and document their
arguments and call these. Options cross as one dict keyed by the package's keyword names;
reports cross as the library's JSON text.
"""

from typing import Any, Dict, List, Mapping, Optional, Tuple

import numpy as np
import numpy.typing as npt

__version__: str

class NativeMachine:
    @staticmethod
    def builtin(name: str) -> NativeMachine: ...
    @staticmethod
    def from_toml(text: str, origin: str) -> NativeMachine: ...
    @staticmethod
    def builtin_names() -> List[str]: ...
    @property
    def name(self) -> str: ...
    @property
    def primary(self) -> str: ...
    @property
    def tcy_ms(self) -> float: ...
    @property
    def primary_range_deg(self) -> Tuple[float, float]: ...
    @property
    def c_range_deg(self) -> Optional[Tuple[float, float]]: ...
    @property
    def limits(self) -> Dict[str, Tuple[float, float, float]]: ...
    def tool_axis(self, p_deg: float, c_deg: float) -> Tuple[float, float, float]: ...

def patch_nc(
    data: bytes, machine: NativeMachine, options: Mapping[str, Any]
) -> Tuple[bytes, str]: ...
def analyze_nc(
    data: bytes,
    machine: NativeMachine,
    cone_deg: float,
    tcy_ms: Optional[float],
    options: Mapping[str, Any],
) -> str: ...
def feed_profile(
    data: bytes,
    machine: NativeMachine,
    cone_deg: float,
    tcy_ms: Optional[float],
    options: Mapping[str, Any],
) -> List[Dict[str, Any]]: ...
def post_cl(cl: bytes, machine: NativeMachine, options: Mapping[str, Any]) -> bytes: ...
def reorient(
    data: bytes,
    machine: NativeMachine,
    theta_x: Optional[float],
    theta_z: Optional[float],
    pivot_mm: Optional[Tuple[float, float, float]],
    cone_deg: float,
    name: Optional[str],
) -> Tuple[bytes, str]: ...
def cl_to_joints(
    xyzijk: npt.NDArray[np.float64], machine: NativeMachine, branch: str
) -> npt.NDArray[np.float64]: ...
def patch_joints(
    xyzpc: npt.NDArray[np.float64],
    machine: NativeMachine,
    feed_mm_min: float,
    options: Mapping[str, Any],
) -> Tuple[npt.NDArray[np.float64], str]: ...
def defaults() -> Dict[str, Dict[str, Any]]: ...
def _panic_for_test(message: str) -> None: ...
