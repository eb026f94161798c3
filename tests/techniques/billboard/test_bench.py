"""The billboard bench: targets decided from the measured numbers, and a tiny run that
writes valid json and markdown."""

from __future__ import annotations

import json

from reliefkit.bench import suite_names
from reliefkit.techniques.billboard import bench


def _results(vol_iou=0.9, bbc_iou=0.8, ratio=4.0, wrong=0.0, seconds=5.0, skipped=0,
             static=0.005, change=0.3, motion=0.295, full=True) -> dict:
    scores = {"volumetric": {"iou": vol_iou, "ssim": 0.7, "psnr": 30.0},
              "bbc": {"iou": bbc_iou, "ssim": 0.6, "psnr": 25.0}}
    return {"quality": [{"asset": "a", "distance": "near", "radii": 1.5, **scores}],
            "equal_error": [{"asset": "a", "variant": "volumetric", "ratio": ratio,
                             "uniform_samples": 4, "sphere_wrong": wrong}],
            "generation": [{"mesh": "m", "triangles": 100_000, "seconds": seconds,
                            "skipped": skipped, "cpus": 2, "full_run": full},
                           {"mesh": "curved", "triangles": 81_920, "seconds": 1.0,
                            "skipped": 0, "cpus": 2, "full_run": full}],
            "dolly": [{"asset": "a", "switch_radii": 30.0, "switch_change": change,
                       "switch_motion": motion, "switch_static": static}]}


def _met(results) -> list[bool]:
    return [t["met"] for t in bench.check_targets(results)]


def test_targets_follow_the_numbers():
    assert _met(_results()) == [True, True, True, True, True]
    assert _met(_results(vol_iou=0.7)) == [False, True, True, True, True]
    assert _met(_results(ratio=2.9, wrong=0.002)) == [True, False, False, True, True]
    assert _met(_results(seconds=11.0)) == [True, True, True, False, True]
    assert _met(_results(skipped=1)) == [True, True, True, False, True]
    assert _met(_results(full=False)) == [True, True, True, False, True]
    assert _met(_results(static=0.02)) == [True, True, True, True, False]
    assert _met(_results(change=0.4)) == [True, True, True, True, False]


def test_a_dolly_without_a_switch_is_reported():
    results = _results()
    results["dolly"][0]["switch_change"] = None
    targets = bench.check_targets(results)
    assert targets[-1]["met"] is False and "no switch" in targets[-1]["value"]


def test_the_suite_is_registered():
    assert "billboard" in suite_names()


def test_tiny_run_writes_json_and_markdown(tmp_path, monkeypatch):
    monkeypatch.delenv(bench.MESH_ENV, raising=False)
    cfg = bench.BenchConfig(assets=("vehicle",), texel_divisor=48, size=48,
                            azimuths=(30.0,), repeats=1, uniform_samples=(1, 4),
                            big_asset="vehicle", big_subdivisions=0, curved_subdivisions=2,
                            generation_tries=1, fig6_points=2, dolly_frames=12, quick=True)
    lines = []
    results = bench.run(cfg, log=lines.append)
    paths = bench.write(results, tmp_path)
    assert lines
    data = json.loads(paths[0].read_text())
    assert data["targets"] == bench.check_targets(data)
    q = data["quality"][0]
    assert data["targets"][0]["met"] == (q["volumetric"]["iou"] > q["bbc"]["iou"]
                                         and q["volumetric"]["ssim"] > q["bbc"]["ssim"])
    assert [g["full_run"] for g in data["generation"]] == [False, False]
    assert data["generation"][1]["triangles"] == 20 * 4 ** 2  # the bumpy sphere, curved
    assert any(bench.MESH_ENV in note for note in data["notes"])
    text = paths[1].read_text()
    assert "#### Table 1" in text and "#### Targets" in text and "vehicle" in text
