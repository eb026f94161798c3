"""`reliefkit bench viewer`: its quick run's report per input (the mesh and one kind, in
headless Chromium at a tiny size) with counts that match the GLB the page was given; without
a browser, one line saying what to install."""

from __future__ import annotations

import json

import numpy as np
import pytest
from browser import launch, playwright
from helpers import assert_one_line_error, run_cli

from reliefkit.bench import run_suite, viewer
from reliefkit.export.draw import read_plans
from reliefkit.io.gltf.glb import read_glb
from reliefkit.scene.light import DirectionalLight
from reliefkit.scene.views import orbit_bounds
from reliefkit.viewer.site import make_input

SIZE = (48, 48)


def plans_in(glb_bytes: bytes, folder):
    """The draw plans of an input's GLB, read back in Python."""
    path = folder / "input.glb"
    path.write_bytes(glb_bytes)
    glb = read_glb(path)
    (node,) = [n for n in glb.document["nodes"] if "extensions" in n]
    (extension,) = node["extensions"].values()
    return read_plans(glb, extension["draw"])


def uploaded_bytes(plans) -> int:
    """What the page uploads for the plans' textures, once each: the given levels or the
    array, float64 as float32 (WebGL has no float64 texture)."""
    textures = {id(t): t for p in plans for t in p.textures.values()}.values()
    assert not any(t.encoded for t in textures)  # an encoded one is decoded first: not here
    arrays = [a for t in textures for a in (t.levels or [t.array])]
    return sum(a.size * min(a.dtype.itemsize, 4) if a.dtype == np.float64 else a.nbytes
               for a in arrays)


@pytest.fixture(scope="module")
def chromium_here():
    """Skips where Playwright or Chromium is missing (a failure on CI)."""
    with playwright() as p:
        launch(p).close()


@pytest.fixture(scope="module")
def quick_run(chromium_here, tmp_path_factory):
    out = tmp_path_factory.mktemp("bench")
    markdown, paths = run_suite("viewer", quick=True, out=out, log=lambda line: None,
                                size=SIZE)
    return markdown, json.loads((out / "viewer.json").read_text()), paths


def test_the_quick_report_has_the_mesh_and_a_kind_with_frames_and_ratios(quick_run):
    markdown, data, paths = quick_run
    assert [p.name for p in paths] == ["viewer.json", "viewer.md"]
    assert data["size"] == list(SIZE) and len(data["azimuths"]) == viewer.QUICK_VIEWS
    assert "SwiftShader" in data["webgl_renderer"]
    mesh, kind = data["rows"]
    assert (mesh["asset"], mesh["kind"]) == ("vehicle", "mesh") and kind["kind"] != "mesh"
    for row in (mesh, kind):
        assert len(row["frame_ms"]) == viewer.QUICK_VIEWS
        assert 0 < row["fastest_ms"] <= row["median_ms"]
        assert row["fps"] == pytest.approx(1000.0 / row["median_ms"])
        assert row["meets_target"] == (row["fps"] >= viewer.TARGET_FPS)
        assert f"| {row['asset']} | {row['kind']} |" in markdown
    assert mesh["mesh_ratio"] == 1.0
    assert kind["mesh_ratio"] == pytest.approx(kind["median_ms"] / mesh["median_ms"])


def test_the_counts_are_the_plans_and_texture_bytes_of_the_glb(quick_run, tmp_path):
    """Plans drawn, draw calls and vertices of the last frame (one draw per single-pass plan
    its view hook leaves on, seen in Python from the orbit's last view, and the picture's
    presentation: a full-screen triangle) and texture bytes against the GLB each page was
    given, read in Python."""
    _, data, _ = quick_run
    inputs = list(viewer._inputs(True, lambda line: None))
    assert len(inputs) == len(data["rows"])
    for (_, kind, spec, obj), row in zip(inputs, data["rows"], strict=True):
        made = make_input(spec, obj)
        plans = plans_in(made.glb, tmp_path)
        assert row["plans"] == len(plans), kind
        assert not any(p.multipass for p in plans)  # one draw each
        camera = orbit_bounds(made.bounds, data["azimuths"][-1], data["elevation"], size=SIZE)
        viewed = [p.with_view(camera, DirectionalLight())[0] for p in plans]
        drawn = [p for p in viewed if p.count != 0]
        assert row["draw_calls"] == len(drawn) + 1, kind
        assert all(p.geometry.indices is not None for p in drawn)  # counted by their indices
        assert row["vertices"] == 3 + sum(
            (p.geometry.indices.size if p.count is None else p.count)
            * (p.geometry.instances or 1) for p in drawn), kind
        assert row["texture_bytes"] == uploaded_bytes(plans), kind
    assert data["rows"][1]["texture_bytes"] > 0  # the kind's textures are counted


def test_without_chromium_the_bench_says_what_to_install(tmp_path):
    result = run_cli("bench", "viewer", "--quick", "--out", tmp_path / "out",
                     env={"RELIEFKIT_CHROMIUM": str(tmp_path / "no-chromium")})
    assert_one_line_error(result, "RELIEFKIT_CHROMIUM", "no executable browser")
    assert not (tmp_path / "out").exists()


def test_a_frame_the_page_refuses_stops_the_bench_before_any_bake(chromium_here, tmp_path):
    """The baseline mesh comes first: its page's refusal (5000² of float targets, over its
    1 GiB) is the bench's one error line, after its progress line, with nothing written."""
    result = run_cli("bench", "viewer", "--quick", "--size", "5000x5000", "--out",
                     tmp_path / "out")
    assert result.returncode == 2 and "Traceback" not in result.stderr
    *progress, error = result.stderr.strip().splitlines()
    assert progress == ["bench viewer: demo:vehicle: mesh at 5000x5000, 2 views"]
    assert error.startswith("error: the viewer page: demo:vehicle: a 5000x5000 frame needs")
    assert not (tmp_path / "out").exists()


def test_size_and_browser_apply_to_the_viewer_bench_only(tmp_path):
    result = run_cli("bench", "export", "--size", "64x64", "--out", tmp_path)
    assert_one_line_error(result, "bench export takes no --size", "viewer")
    result = run_cli("bench", "viewer", "--size", "64y64", "--out", tmp_path)
    assert_one_line_error(result, "--size must be WxH")
