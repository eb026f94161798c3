"""``reliefkit bench NAME --mesh FILE``: the suites that take a mesh measure that file (its
triangles, its bytes), the others refuse the flag by name."""

from __future__ import annotations

import json
from dataclasses import replace

import trimesh
from helpers import assert_one_line_error, run_cli


def _write_box(folder):
    path = folder / "two boxes.obj"
    boxes = [trimesh.creation.box(extents=(1.0, 0.4, 0.6)),
             trimesh.creation.box(extents=(0.3, 0.3, 0.3))]
    boxes[1].apply_translation((0.0, 0.35, 0.0))
    trimesh.util.concatenate(boxes).export(path)
    return path


def test_loading_measures_the_given_file(tmp_path):
    mesh = _write_box(tmp_path)
    out = run_cli("bench", "loading", "--mesh", mesh, "--out", tmp_path / "bench")
    assert out.returncode == 0, out.stderr
    rows = json.loads((tmp_path / "bench" / "loading-bench.json").read_text())["rows"]
    assert len(rows) == 1
    assert rows[0]["format"] == "obj" and rows[0]["triangles"] == 24
    assert rows[0]["file_bytes"] == mesh.stat().st_size


def test_relief_runs_on_the_given_mesh(gl, tmp_path):
    from reliefkit.techniques.relief.bench import BenchConfig, run

    mesh = _write_box(tmp_path)
    cfg = replace(BenchConfig.quick().on_mesh(str(mesh)), resolutions=(16,), size=(48, 36),
                  tolerances=(0.01,), tolerance_res=16, correctness_res=16,
                  correctness_views=((30, 45),), correctness_size=(48, 36))
    results = run(cfg, log=lambda line: None)
    assert [(r["model"], r["triangles"]) for r in results["table1"]] == [(mesh.name, 24)]
    assert {r["model"] for r in results["correctness"]} == {
        mesh.name, f"{mesh.name} frustum", f"{mesh.name} cube"}
    assert results["tolerance"]


def test_mesh_is_refused_where_a_suite_has_only_its_own_assets(tmp_path):
    mesh = _write_box(tmp_path)
    assert_one_line_error(run_cli("bench", "billboard", "--mesh", mesh, "--out", tmp_path),
                          "--mesh applies to", "loading", "relief", code=2)
    assert_one_line_error(run_cli("bench", "loading", "--mesh", tmp_path / "nope.obj", "--out",
                                  tmp_path), "nope.obj: no such file", code=1)
