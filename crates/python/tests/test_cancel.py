"""Ctrl-C during a long `patch_nc` (issue 26 item 4): KeyboardInterrupt arrives while the
native call works, not when it returns."""

from __future__ import annotations

import os
import signal
import threading
import time

import pytest

import polepatch
from conftest import read


def many_zones(copies: int) -> bytes:
    """`copies` passes near the pole, each its own run (a rapid between them): one
    stretch each, so the patch can stop between any two."""
    body = read("fixtures/generated/fanuc-ac-swing-d1.nc").decode().splitlines()
    moves = [l for l in body if l.startswith("X") or l.startswith("G1 ")]
    out = ["%", "O1000", "G90 G21 G94", "G43.4 H1"]
    for _ in range(copies):
        out.append("G0 Z50")
        out.extend(moves)
    out += ["G49", "M30", "%"]
    return ("\n".join(out) + "\n").encode()


@pytest.mark.skipif(not hasattr(signal, "SIGINT") or os.name != "posix", reason="needs POSIX signals")
def test_ctrl_c_stops_a_long_patch_before_it_ends() -> None:
    data = many_zones(300)
    t0 = time.perf_counter()
    out, report = polepatch.patch_nc(data, "mikron-ucp710")
    full = time.perf_counter() - t0
    assert len(report["zones"]) >= 300, len(report["zones"])
    assert full > 0.5, f"the whole patch takes {full:.2f} s: too short to interrupt"
    delay = min(0.2, full / 5)
    timer = threading.Timer(delay, lambda: os.kill(os.getpid(), signal.SIGINT))
    t0 = time.perf_counter()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        polepatch.patch_nc(data, "mikron-ucp710")
    stopped = time.perf_counter() - t0
    timer.join()
    # Seen within a poll (50 ms) and a stretch of the signal, far before the end.
    assert stopped < delay + 0.5 * (full - delay), f"stopped after {stopped:.2f} s of {full:.2f} s"
    # The package still works after an interrupted call.
    assert polepatch.patch_nc(read("fixtures/c17/SING.I"), "mikron-ucp710")[1]["zones"]

