"""The toy technique (tests/toy_technique) through every generic entry point: one new module
and no edit to the core gives it bake, render options, .rk files, compare, bench and demo."""

from __future__ import annotations

import json

import numpy as np
import pytest
from helpers import make_relief, toy_technique

from reliefkit import cli
from reliefkit.bake import bake
from reliefkit.compare import compare
from reliefkit.demo import demo_tiles
from reliefkit.errors import UsageError
from reliefkit.io import rk
from reliefkit.render import render
from reliefkit.scene.assets import make_asset
from reliefkit.scene.camera import Camera


@pytest.fixture(scope="module")
def toy():
    with toy_technique() as module:
        yield module


def test_bake_save_load_render(gl, toy, tmp_path):
    quad = bake(make_asset("blob"), "toy-quad", opacity=1.0)
    rk.save(tmp_path / "q.rk", quad)
    back = rk.load(tmp_path / "q.rk")
    camera = Camera(eye=(0, 0, 4), target=(0, 0, 0), size=(32, 32))
    frame = render(back, camera, method="checker")
    assert frame.mask.sum() > 100 and frame.stats["toy_quads"] == 1
    flat = render(back, camera, method="flat")
    assert not np.array_equal(frame.color, flat.color)


def test_options_with_one_name_are_checked_by_each_owner(gl, toy):
    quad = toy.TECHNIQUE.samples()["toy-quad"]
    relief = make_relief(np.full((16, 16), 0.5, np.float32))
    camera = Camera(eye=(0, 2, 4), target=(0, 0, 0), size=(16, 16))
    with pytest.raises(UsageError, match="toy render option: method must be one of flat"):
        render([relief, quad], camera, method="exact")
    with pytest.raises(UsageError, match="relief render option: method must be one of"):
        render([relief, quad], camera, method="checker")
    with pytest.raises(UsageError, match="unknown render option.*shine"):
        render(quad, camera, shine=True)
    assert render([relief, quad], camera, shadows=True).mask.any()  # relief's own option


def test_compare_uses_the_toys_variants_and_metric(gl, toy):
    mesh = make_asset("blob")
    quad = bake(mesh, "toy-quad")
    camera = Camera(eye=(0, 0, 4), target=tuple(mesh.center), size=(32, 32))
    result = compare(mesh, quad, camera)
    assert set(result["metrics"]) == {"flat", "checker"}
    assert result["metrics"]["flat"]["mean_alpha"] == pytest.approx(1.0)
    assert "mean_alpha" in result["columns"]
    # memory as stored: 4 x 3 float64 corners and 4 float32 colour channels
    assert result["bytes"]["representation"] == 4 * 3 * 8 + 4 * 4
    assert result["bytes"]["mesh"] >= mesh.positions.nbytes + mesh.indices.nbytes


def test_demo_lists_the_toys_tile(toy):
    assert "toy-quad" in [tile.slug for tile in demo_tiles()]


def test_cli_derives_everything_from_the_registry(gl, toy, tmp_path, capsys):
    out = tmp_path / "q.rk"
    assert cli.main(["bake", "demo:blob", "--as", "toy-quad", "--opacity", "0.5", "-o",
                     str(out)]) == 0
    assert rk.read_manifest(out)["kind"] == "toy-quad"
    assert cli.main(["render", str(out), "--method", "checker", "--size", "24x24",
                     "-o", str(tmp_path / "q.png"), "--stats", str(tmp_path / "s.json")]) == 0
    stats = json.loads((tmp_path / "s.json").read_text())
    assert stats["covered"] > 0 and stats["toy_quads"] == 1
    assert cli.main(["render", str(out), "--method", "exact", "-o",
                     str(tmp_path / "bad.png")]) == 2  # a usage error
    assert "method must be one of flat, checker" in capsys.readouterr().err
    assert cli.main(["bake", "demo:blob", "--as", "toy-quad", "--spread", "20", "-o",
                     str(tmp_path / "x.rk")]) == 2
    assert "--spread does not apply to --as toy-quad" in capsys.readouterr().err
    assert cli.main(["bench", "toy", "--out", str(tmp_path / "bench")]) == 0
    assert "toy bench" in capsys.readouterr().out
