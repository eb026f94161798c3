"""The shellvolume bench: a tiny run (one base, two views, small images) whose results have
the structure and the invariants the report relies on; targets decided from the numbers.
No timing is asserted."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest

from reliefkit.techniques.shellvolume import bench


def tiny_config() -> bench.BenchConfig:
    return replace(bench.BenchConfig.quick_config(), size=48, samples=(4,),
                   texture_size=(16, 16, 8), repeats=1, scenes=("sphere",),
                   large_spheres=((12, 6),), sort_repeats=1, order_shapes=("torus",),
                   views=2, rays=32, peel_scenes=("vase",), peel_samples=4,
                   reference_size=32, reference_samples=(2,), halving=(8, 16))


@pytest.fixture(scope="module")
def tiny(gl, tmp_path_factory):
    out = tmp_path_factory.mktemp("shellvolume-bench")
    results = bench.run(tiny_config(), log=lambda message: None)
    return results, bench.write(results, out)


def test_tiny_run_structure(tiny):
    results, _ = tiny
    assert {"machine", "config", "table1", "sorting", "ordering", "peeling", "reference",
            "filtering", "targets"} <= set(results)
    assert results["machine"]["cpus"] and results["machine"]["renderer"]
    (row,) = results["table1"]
    assert row["scene"] == "sphere" and row["texture"].startswith("clouds 16x16x8")
    assert row["triangles_sent"] == 4 * row["tetrahedra"] == 2 * row["front_faces"]
    assert row["tetrahedra"] == 3 * row["base_triangles"]
    assert not row["opaque"] and row["frame_aov_ms"] is not None
    assert row["sort_ms"] is not None and row["ratio_to_mesh"] > 0
    (sort,) = results["sorting"]
    assert sort["tetrahedra"] > 0 and sort["sxmpvo_tets_per_s"] > 0
    assert sort["centroid_tets_per_s"] > 0 and sort["cycles"] >= 0


def test_sxmpvo_has_no_violations_on_its_rays(tiny):
    results, _ = tiny
    rows = {(r["shell"], r["method"]): r for r in results["ordering"]}
    assert set(rows) == {(s, m) for s in bench.ORDER_SHELLS
                         for m in ("sxmpvo", "centroid", "vtk")}
    sx = rows["as built", "sxmpvo"]
    assert sx["pairs"] > 0 and sx["violations"] == 0 and sx["bad_rays"] == 0
    assert rows["as built", "centroid"]["pairs"] == sx["pairs"]  # the same rays checked
    vtk = rows["as built", "vtk"]
    assert vtk["available"] or vtk["reason"]  # unavailable: a reason, not a missing row


def test_peeling_gives_the_sorted_picture(tiny):
    results, _ = tiny
    (peel,) = results["peeling"]
    assert peel["scene"] == "vase" and peel["peeled_layers"] > 1 and not peel["capped"]
    assert peel["max_diff"] < 1e-3


def test_reference_and_filtering_figures(tiny):
    results, _ = tiny
    ref = results["reference"]
    assert {r["projection"] for r in ref["rows"]} == {"perspective", "orthographic"}
    assert all(np.isfinite(r["rmse"]) and r["rmse"] >= 0 for r in ref["rows"])
    assert 0 <= ref["halving"]["max_alpha_change"] <= 1
    mip = [r for r in results["filtering"] if r["pyramid"] == "mip"]
    naive = [r for r in results["filtering"] if r["pyramid"] == "naive"]
    assert len(mip) == len(naive) == 2
    assert all(len(r["transmittance"]) == 4 for r in mip + naive)
    assert max(r["drift"] for r in mip) <= bench.DRIFT_TARGET < max(r["drift"] for r in naive)


def test_written_files_and_markdown(tiny):
    results, paths = tiny
    names = [p.name for p in paths]
    assert names == ["shellvolume-bench.json", "shellvolume-bench.md",
                     "shellvolume-bench.png"]
    data = json.loads(paths[0].read_text())
    assert data["targets"] == results["targets"] and "_tiles" not in data
    text = paths[1].read_text()
    assert text == bench.markdown(data)
    assert len(results["targets"]) == 7
    for target in results["targets"]:
        assert target["target"] in text and isinstance(target["met"], bool)
    for section in ("Table 1", "Sorting throughput", "Ordering violations", "Depth peeling",
                    "CPU reference", "Filtering", "Targets"):
        assert section in text
    assert paths[2].stat().st_size > 0


def test_targets_follow_the_numbers():
    def results(sx_bad=0, ce_bad=5, rate=2e6, peel_diff=0.0, speedup=10.0, rmse=1e-3,
                halving=1e-3, mip=0.0, naive=0.3):
        order = [{"shape": "t", "shell": s, "method": m, "views": 2, "cycles": 0,
                  "bad_rays": 0, "violations": {"sxmpvo": sx_bad, "centroid": ce_bad}[m]}
                 for s in bench.ORDER_SHELLS for m in ("sxmpvo", "centroid")]
        return {"sorting": [{"tetrahedra": 1000, "sxmpvo_tets_per_s": rate,
                             "sxmpvo_default_tets_per_s": rate, "sxmpvo_ms": 1.0,
                             "resolution": 64, "default_resolution": 256, "cycles": 0}],
                "ordering": order,
                "peeling": [{"scene": "v", "max_diff": peel_diff, "pixels_over_1e-3": 0,
                             "capped": False, "speedup": speedup, "peel_ms": 10.0,
                             "sxmpvo_ms": 1.0, "peeled_layers": 4}],
                "reference": {"rows": [{"rmse": rmse, "projection": "p", "samples": 2}],
                              "halving": {"max_alpha_change": 0.05, "samples": [32, 64],
                                          "mean_alpha_change": halving,
                                          "fraction_over": halving / 10}},
                "filtering": [{"texture": "x", "pyramid": "mip", "drift": mip},
                              {"texture": "x", "pyramid": "naive", "drift": naive}]}

    def met(**kw):
        return [t["met"] for t in bench.check_targets(results(**kw))]

    assert met() == [True] * 7
    assert met(rate=5e5) == [False] + [True] * 6
    assert met(sx_bad=1) == [True, False] + [True] * 5
    assert met(ce_bad=0) == [True, False] + [True] * 5
    assert met(peel_diff=0.01) == [True] * 2 + [False] + [True] * 4
    assert met(speedup=0.5) == [True] * 3 + [False] + [True] * 3
    assert met(rmse=0.01) == [True] * 4 + [False] + [True] * 2
    assert met(halving=0.01) == [True] * 5 + [False, True]
    assert met(mip=0.03) == [True] * 6 + [False]
    assert met(naive=0.0) == [True] * 6 + [False]
