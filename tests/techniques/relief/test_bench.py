"""The relief bench: a tiny run with every method, whose rows and targets the report relies
on. No timing is asserted."""

from __future__ import annotations

from dataclasses import replace

import pytest

from reliefkit.techniques.relief import bench
from reliefkit.techniques.relief.render import METHODS


@pytest.fixture(scope="module")
def tiny(gl):
    cfg = replace(bench.BenchConfig.quick(), models=("terrain",), resolutions=(16, 32),
                  size=(64, 48), tolerances=(0.01,), tolerance_res=16, correctness_res=16,
                  correctness_views=((30, 45),), correctness_size=(48, 36))
    return bench.run(cfg, log=lambda message: None)


def test_every_method_is_measured(tiny):
    assert set(METHODS) >= {"binary", "exact", "robust", "maxmip"}
    for row in tiny["table1"]:
        for method in METHODS:
            assert row[f"{method}_ms"] > 0 and row[f"{method}_it_mean"] > 0
        assert row["pyramid_s"] >= 0 and row["safety_s"] >= 0
    assert {r["model"] for r in tiny["correctness"]} == {"terrain", "blob", "vehicle",
                                                         "vehicle frustum", "blob cube"}
    for corr in tiny["correctness"]:
        assert corr["maxmip"] <= 0.001 and corr["exact"] <= 0.001


def test_targets_name_each_method_and_render(tiny):
    names = " ".join(t["target"] for t in tiny["targets"])
    assert "maxmip" in names and "robust never slower than exact" in names
    text = bench.markdown(tiny)
    assert "maxmip ms" in text and "max pyramid s" in text and "scanned pieces" in text
    # a quick run times single draws: its frame-time ratios are shown, not judged
    timed = [t for t in tiny["targets"] if "slower than exact" in t["target"]]
    assert timed and all(t["met"] is None for t in timed)
    assert "not judged" in text
    judged = bench.check_targets({**tiny, "config": {**tiny["config"], "repeats": 5}})
    assert all(isinstance(t["met"], bool) for t in judged)


def test_safety_work_is_reported_per_texel(tiny):
    for row in tiny["table1"]:
        # at most one visit per direction-frame (264) and line through the texel (4 offsets
        # and the line entering at its column)
        assert 0 < row["safety_scans"] <= row["safety_visits"] <= 264 * 5
        assert row["safety_scanned_pieces"] >= row["safety_scans"]
