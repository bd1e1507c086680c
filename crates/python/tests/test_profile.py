"""feed_profile: the samples behind analyze_nc's figures."""

from __future__ import annotations

import numpy as np
import pytest

import polepatch
from conftest import MACHINES, posted_for, read

PROGRAMS = [
    "fixtures/c17/SING.I",
    "fixtures/dialects/fanuc.nc",
    "fixtures/dialects/sinumerik.mpf",
    "fixtures/generated/heidenhain-bc-flip-d0.I",
]


@pytest.mark.parametrize("machine", MACHINES)
@pytest.mark.parametrize("rel", PROGRAMS)
def test_the_profile_has_the_analysis_minima(machine: str, rel: str) -> None:
    data = read(rel)
    if machine not in posted_for(data):
        # Posted for the other machine: both calls refuse it the same way (issue 29).
        with pytest.raises(polepatch.InputError, match="is not an axis of machine") as a:
            polepatch.analyze_nc(data, machine)
        with pytest.raises(polepatch.InputError) as p:
            polepatch.feed_profile(data, machine)
        assert str(a.value) == str(p.value)
        return
    report = polepatch.analyze_nc(data, machine)
    profile = polepatch.feed_profile(data, machine)
    assert len(profile) == len(report["runs"]) > 0
    assert profile[0]["axes"] == ["X", "Y", "Z", report["primary"], "C"]
    for p, r in zip(profile, report["runs"]):
        assert (p["run"], p["lines"], p["feed_mm_min"]) == (r["run"], r["lines"], r["feed_mm_min"])
        if "error" in r:
            assert p["error"] == r["error"] and p["s_mm"].size == 0
            continue
        s, ratio, axis = p["s_mm"], p["ratio"], p["axis_ratio"]
        assert p["error"] is None and s.shape == ratio.shape and axis.shape == (s.size, 5)
        assert np.all(np.diff(s) >= 0) and s[0] == 0.0
        assert abs(s[-1] - r["length_mm"]) < 1e-9 * max(1.0, r["length_mm"])
        assert np.all((ratio > 0) & (ratio <= 1.0))
        # Samples at every CL point (the spline's knots), which carry their file lines.
        points = p["point_s_mm"]
        assert points.size == r["points"] == len(p["point_lines"])
        assert np.isin(points, s).all()
        assert [p["point_lines"][0], p["point_lines"][-1]] == r["lines"]
        assert ratio.min() == r["min_ratio"]
        assert s[int(np.argmin(ratio))] == r["min_at_s_mm"]
        for k, letter in enumerate(p["axes"]):
            assert axis[:, k].min() == r["axis_min_ratio"][letter], letter


def test_patching_lifts_the_profile_to_the_feed() -> None:
    data = read("fixtures/c17/SING.I")
    patched, report = polepatch.patch_nc(data, "mikron-ucp710")
    (zone,) = report["zones"]
    run = zone["run"] - 1
    before = polepatch.feed_profile(data, "mikron-ucp710")[run]
    after = polepatch.feed_profile(patched, "mikron-ucp710")[run]
    # X Y Z are unchanged under TCPM: the CL points sit at the same s (the samples between
    # them follow the analysis of each span, which the patch changes).
    assert np.array_equal(before["point_s_mm"], after["point_s_mm"])
    c = before["axes"].index("C")
    assert before["axis_ratio"][:, c].min() == zone["before"]["c_ratio"] < 0.2
    assert after["axis_ratio"][:, c].min() == 1.0  # C reaches feed where it crawled
    assert after["ratio"].min() > before["ratio"].min()
