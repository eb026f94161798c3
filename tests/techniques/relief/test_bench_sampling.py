"""The sampling study (`reliefkit bench relief-sampling`): its rows tell samplings apart by
their work and by the checker's verdict, and its report holds every bake. No timing is
asserted."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.ndimage import gaussian_filter

from reliefkit.techniques.relief import bench_sampling


def test_a_coarse_sampling_does_less_work_and_fails_the_checker():
    noise = gaussian_filter(np.random.default_rng(2).random((24, 24)), 1.5)
    h = (noise - noise.min()) / np.ptp(noise)
    default, coarse = bench_sampling.study_field(h, ((64, 4, 0.25), (2, 1, 0.0)),
                                                 tolerance=0.01, rays=20000, seed=3)
    assert default["ratio"] == 1.0
    # 264 direction-frames x 4 offsets against 16 x 1 (plus the lines entering at a column)
    assert default["visits"] > 0.9 * 264 * 4 and coarse["visits"] < default["visits"] / 20
    assert coarse["violations"] > default["violations"] + 10
    for row in (default, coarse):
        assert row["per_million"] == pytest.approx(row["violations"] * 50)
        assert (row["excess"] > 0) == (row["violations"] > 0)


def test_verdict_is_the_cheapest_sampling_that_keeps_the_defaults_violations():
    def row(d, seconds, violations):
        return {"model": "m", "res": 8, "directions": d, "offsets": 4, "margin": 0.25,
                "seconds": seconds, "ratio": seconds / 4.0, "violations": violations}

    rows = [row(64, 4.0, 3), row(32, 2.0, 3), row(16, 1.0, 9), row(8, 3.0, 0)]
    (verdict,) = bench_sampling.verdicts(rows)
    assert verdict["sampling"] == (32, 4, 0.25) and verdict["ratio"] == 0.5
    assert verdict["default_violations"] == 3


def test_suite_reports_every_bake(gl, tmp_path):
    cfg = bench_sampling.SamplingConfig(
        fields=(("terrain", 16, bench_sampling.SAMPLINGS[:2]),), rays=2000)
    results = bench_sampling.run(cfg, log=lambda message: None)
    assert [(r["directions"], r["offsets"]) for r in results["rows"]] == [(64, 4), (32, 4)]
    paths = bench_sampling.write(results, tmp_path)
    assert all(p.stat().st_size > 0 for p in paths)
    text = paths[1].read_text()
    assert text.count("| terrain | 16² |") == 2 and "Cheapest sampling" in text
    assert json.loads(paths[0].read_text())["config"]["rays"] == 2000
