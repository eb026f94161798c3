"""The slicing bench: a tiny run whose results have the structure and the invariants the
report relies on; targets decided from the numbers. No timing is asserted."""

from __future__ import annotations

import json
from dataclasses import replace

import pytest

from reliefkit.techniques.slicing import bench


def tiny_config() -> bench.BenchConfig:
    return replace(bench.BenchConfig.quick_config(), res=24, size=48, assets=("cup",),
                   slice_counts=(16,), convergence_counts=(16, 64),
                   coverages=(24,), fig12_slices=(8,), fixed_slices=8, fixed_coverage=24,
                   carve_sizes=(8,), terrain_res=16, displacement_slices=(8,))


@pytest.fixture(scope="module")
def tiny(gl, tmp_path_factory):
    out = tmp_path_factory.mktemp("slicing-bench")
    results = bench.run(tiny_config(), log=lambda message: None)
    paths = bench.write_report(out, "slicing-bench", results, bench.markdown)
    return results, paths


def test_tiny_run_structure(tiny):
    results, paths = tiny
    assert {"machine", "config", "quality", "convergence", "texturing", "fig12", "passes",
            "peer", "displacement", "targets"} <= set(results)
    variants = {(r["object"], r["variant"]) for r in results["quality"]}
    assert ("depth object", "ray cast") in variants and ("visual hull", "ray cast") in variants
    assert json.loads(paths[0].read_text())["config"]["res"] == 24
    assert "#### Targets" in paths[1].read_text()


def test_ray_casting_rows_are_exact_and_the_hull_fails_the_cup(tiny):
    results, _ = tiny
    rows = {(r["object"], r["variant"]): r for r in results["quality"]}
    ray = rows[("depth object", "ray cast")]
    assert ray["reference_wrong"] < 0.01 and ray["reference_iou"] > 0.99
    hull = rows[("visual hull", "ray cast")]
    # the hull fills the cup: farther from the mesh than the depth object
    assert hull["mesh_position_rms_texels"] > 1.4 * ray["mesh_position_rms_texels"]


def test_stencil_rows_match_the_single_pass(tiny):
    results, _ = tiny
    for row in results["passes"]:
        assert row["same_mask"] and row["max_color_difference"] < 1e-6
        assert row["draws_stencil"] > row["draws_single"] == 1


def test_targets_follow_the_numbers(tiny):
    results, _ = tiny
    for t in results["targets"]:
        assert isinstance(t["met"], bool) and t["value"]
    conv = {r["mode"]: r for r in results["convergence"]}
    slab = conv["orthogonal, slab test"]
    assert slab["reached_at"] == slab["steps"][0]["slices"]
    peer = results["peer"]
    assert peer["available"] or peer["reason"]
