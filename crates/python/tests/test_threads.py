"""Threads: calls run in parallel (the GIL is released while the library works) and give
the bytes a single thread gets."""

from __future__ import annotations

import re
import threading
import time
from concurrent.futures import ThreadPoolExecutor

import polepatch
from conftest import MACHINES, nc_fixtures, posted_for, read


def test_threads_calling_patch_nc_at_once_give_the_same_bytes() -> None:
    # The programs that pass the pole exactly (d0) and C17's two, on both machines in
    # turn, each twice: 36 calls on 8 threads.
    near = [rel for rel in nc_fixtures() if re.search(r"-d0\.[A-Za-z]+$", rel) or "c17" in rel]
    # Each on a machine it was posted for, the two machines in turn where both take it.
    unique = []
    for k, rel in enumerate(near):
        fit = posted_for(read(rel))
        unique.append((rel, fit[k % len(fit)]))
    assert len(unique) >= 10, unique
    serial = {job: polepatch.patch_nc(read(job[0]), job[1])[0] for job in unique}
    jobs = unique * 2
    machines = {name: polepatch.Machine.builtin(name) for name in MACHINES}  # shared objects
    with ThreadPoolExecutor(max_workers=8) as pool:
        got = list(pool.map(lambda j: polepatch.patch_nc(read(j[0]), machines[j[1]])[0], jobs))
    for (rel, machine), out in zip(jobs, got):
        assert out == serial[(rel, machine)], (rel, machine)


def test_the_gil_is_released_during_the_work() -> None:
    """A Python thread keeps running while another thread is inside a long call: with
    the GIL held for the call, no heartbeat could fall in its middle."""
    data = read("fixtures/c17/SING.I")
    span = {}

    def work() -> None:
        span["start"] = time.perf_counter()
        polepatch.reorient(data, "mikron-ucp710")  # the tilt search: a long call
        span["end"] = time.perf_counter()

    beats = []
    t = threading.Thread(target=work)
    t.start()
    while t.is_alive():
        beats.append(time.perf_counter())
        time.sleep(0.002)
    t.join()
    start, end = span["start"], span["end"]
    assert end - start > 0.2, f"the call took only {end - start:.3f} s: not a test of the GIL"
    # Away from both ends by more than the interpreter's switch interval (5 ms).
    middle = [b for b in beats if start + 0.05 < b < end - 0.05]
    assert len(middle) >= 5, (len(middle), end - start)
