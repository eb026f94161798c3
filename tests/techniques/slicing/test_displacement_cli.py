"""`reliefkit bake --as displacement` from a heightmap, a projected mesh and a mesh base with
fur; `render` with each `--slicing`; typed fields of the .rk kind; one-line errors."""

from __future__ import annotations

import hashlib
import io
import json
import zipfile

import numpy as np
import pytest
from helpers import assert_one_line_error, run_cli

from reliefkit.errors import FormatError
from reliefkit.io import rk
from reliefkit.techniques.slicing.displacement import DisplacementMap


@pytest.fixture(scope="module")
def baked(tmp_path_factory):
    from PIL import Image

    folder = tmp_path_factory.mktemp("displacement")
    x, y = np.meshgrid(np.linspace(0, 1, 24), np.linspace(0, 1, 24))
    image = (255 * (0.5 + 0.5 * np.sin(6 * x) * np.cos(5 * y))).astype(np.uint8)
    Image.fromarray(image).save(folder / "hm.png")
    out = {}
    for name, args in {
        "heightmap": [folder / "hm.png", "--displacement-scale", "0.3"],
        "projected": ["demo:sphere", "--res", "32"],
        "fur": ["demo:torus", "--displacement", "fur", "--tile", "4,2", "--res", "24",
                "--displacement-scale", "0.05"],
        "file": ["demo:plane", "--displacement", folder / "hm.png"],
    }.items():
        path = folder / f"{name}.rk"
        result = run_cli("bake", *args, "--as", "displacement", "-o", path)
        assert result.returncode == 0, result.stderr
        assert "displacement map:" in result.stdout
        out[name] = path
    out["folder"] = folder
    return out


def test_bakes_hold_what_was_asked(baked):
    hm = rk.load(baked["heightmap"])
    assert isinstance(hm, DisplacementMap) and hm.triangle_count == 2
    assert hm.scale == pytest.approx(0.3) and hm.height.shape == (24, 24)
    assert hm.one_polygon_box() is not None and not hm.wrap
    proj = rk.load(baked["projected"])
    assert proj.triangle_count == 2 and proj.height.shape == (32, 32)
    # the unit sphere seen from above: the box is its bounding box, the top reaches h ~ 1
    assert proj.scale == pytest.approx(2.0, rel=0.01) and proj.height.max() > 0.98
    fur = rk.load(baked["fur"])
    assert fur.wrap and fur.tile == (4.0, 2.0) and fur.scale == pytest.approx(0.05)
    assert fur.triangle_count > 100 and fur.params["texture"] == "fur"
    on_plane = rk.load(baked["file"])
    assert on_plane.height.shape == (24, 24) and not on_plane.wrap
    np.testing.assert_allclose(on_plane.height, hm.height)  # the same PNG, the same heights


@pytest.mark.parametrize("slicing", ["surface", "orthogonal", "screen"])
def test_render_each_slicing(baked, slicing, tmp_path):
    stats = tmp_path / "s.json"
    result = run_cli("render", baked["fur"], "--size", "48x48", "--slicing", slicing,
                     "--slices", "10", "-o", tmp_path / "a.png", "--stats", stats)
    assert result.returncode == 0, result.stderr
    s = json.loads(stats.read_text())
    assert s["slicing"] == slicing and s["slices"] == 10 and s["slice_polygons"] > 0
    assert s["covered"] > 100


def test_render_heightmap_with_automatic_slices(baked, tmp_path):
    stats = tmp_path / "s.json"
    result = run_cli("render", baked["heightmap"], "--size", "48x48", "--slicing", "surface",
                     "--alpha-test", "bound", "-o", tmp_path / "a.png", "--stats", stats)
    assert result.returncode == 0, result.stderr
    s = json.loads(stats.read_text())
    assert 2 <= s["slices"] <= 512 and s["alpha_test"] == "bound"


def test_bad_input_is_a_one_line_error(baked, tmp_path):
    obj = tmp_path / "bare.obj"
    obj.write_text("v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nf 1 3 2\nf 1 4 3\n")
    out = tmp_path / "x.rk"
    assert_one_line_error(run_cli("bake", obj, "--as", "displacement", "--displacement",
                                  "fur", "-o", out), "uvs")
    assert_one_line_error(run_cli("bake", "demo:torus", "--as", "displacement",
                                  "--displacement-scale", "-1", "-o", out), "displacement-scale")
    assert_one_line_error(run_cli("bake", "demo:torus", "--as", "displacement",
                                  "--displacement", "nosuch", "-o", out), "nosuch")
    assert_one_line_error(run_cli("bake", "demo:sphere", "--as", "displacement", "--tile",
                                  "2,2", "-o", out), "--tile")
    assert_one_line_error(run_cli("render", baked["fur"], "--slicing", "diagonal", "-o",
                                  tmp_path / "a.png"), "slicing")
    assert not out.exists()


def _edit(path, edit_manifest, members=None) -> None:
    """Rewrite the .rk zip with its manifest edited and members replaced."""
    with zipfile.ZipFile(path) as zf:
        content = {info.filename: zf.read(info) for info in zf.infolist()}
    manifest = json.loads(content["manifest.json"])
    edit_manifest(manifest)
    content["manifest.json"] = json.dumps(manifest).encode()
    content |= members or {}
    with zipfile.ZipFile(path, "w") as zf:
        for name, data in content.items():
            zf.writestr(name, data)


def _npy(arr) -> bytes:
    bio = io.BytesIO()
    np.lib.format.write_array(bio, arr, allow_pickle=False)
    return bio.getvalue()


@pytest.mark.parametrize("field, value, words", [
    ("scale", -0.5, "scale"), ("scale", "big", "scale"), ("tile", [1.0], "tile"),
    ("tile", [0.0, 1.0], "tile"), ("wrap", 1, "wrap"),
    ("surface_box", [0, 0, 1, 1], "come with 'surface'"),
])
def test_forged_typed_fields_are_refused(baked, tmp_path, field, value, words):
    path = tmp_path / "f.rk"
    path.write_bytes(baked["heightmap"].read_bytes())

    def forge(manifest):
        manifest["params"][field] = value

    _edit(path, forge)
    with pytest.raises(FormatError) as info:
        rk.load(path)
    assert words in str(info.value) and "\n" not in str(info.value)


def test_forged_heights_out_of_range_are_refused(baked, tmp_path):
    path = tmp_path / "f.rk"
    path.write_bytes(baked["heightmap"].read_bytes())
    data = _npy(np.full((24, 24), 2.0, np.float32))

    def forge(manifest):
        manifest["arrays"]["height"]["sha256"] = hashlib.sha256(data).hexdigest()

    _edit(path, forge, {"height.npy": data})
    with pytest.raises(FormatError, match=r"\[0, 1\]"):
        rk.load(path)


def test_a_projected_mesh_covers_what_the_mesh_covers_from_above(gl, baked):
    from reliefkit.render import render
    from reliefkit.scene.assets import make_asset
    from reliefkit.scene.views import orbit_bounds

    rep = rk.load(baked["projected"])
    sphere = make_asset("sphere")
    cam = orbit_bounds(sphere.bounds, 10.0, 75.0, 3.0, size=(64, 64))
    got = render(rep, cam, slicing="screen", slices=48)
    want = render(sphere, cam)
    iou = (got.mask & want.mask).sum() / (got.mask | want.mask).sum()
    assert iou > 0.95, iou
    # the top of the sphere (y = 1) is where the displacement puts it
    top = got.mask & want.mask
    assert np.nanmax(got.position[top][:, 1]) == pytest.approx(1.0, abs=0.05)


def test_an_rgba_displacement_texture_keeps_its_colours_and_alpha_heights(tmp_path):
    """The paper's displacement texture: colour in RGB, displacement in alpha. Left half
    alpha 0 (no displacement: the blue base itself), right half alpha 1 in red."""
    from PIL import Image

    rgba = np.zeros((16, 16, 4), np.uint8)
    rgba[:, :8] = (0, 0, 255, 0)
    rgba[:, 8:] = (255, 0, 0, 255)
    Image.fromarray(rgba, "RGBA").save(tmp_path / "tex.png")
    path = tmp_path / "tex.rk"
    out = run_cli("bake", "demo:plane", "--as", "displacement", "--displacement",
                  tmp_path / "tex.png", "--displacement-scale", "0.2", "-o", path)
    assert out.returncode == 0, out.stderr
    rep = rk.load(path)
    assert rep.height[:, :8].max() == 0 and rep.height[:, 8:].min() == 1
    assert np.allclose(rep.color[0, 12, :3], (1, 0, 0), atol=1e-6)
    out = run_cli("render", path, "--size", "48x48", "--view", "0,89.9,2.5", "--unlit",
                  "--slicing", "orthogonal", "--slices", "16", "-o", tmp_path / "t.png",
                  "--aovs", tmp_path / "t.npz")
    assert out.returncode == 0, out.stderr
    aovs = np.load(tmp_path / "t.npz")
    mask, pos, color = aovs["mask"], aovs["position"], aovs["color"]
    right = mask & (pos[..., 0] > 0.15)
    left = mask & (pos[..., 0] < -0.15)
    assert right.sum() > 200 and left.sum() > 200
    # the top (the highest slice, h = 15.5 / 16), bar the bilinear ramp at the step
    assert (np.abs(pos[right][:, 1] - 0.2) < 0.02).mean() > 0.85
    assert pos[mask][:, 1].max() <= 0.2 + 1e-4
    assert (np.abs(color[right][:, :3] - (1, 0, 0)).max(axis=1) < 0.02).mean() > 0.85
    # left of the step (u < 0.5), the base at height 0 in the texture's blue
    np.testing.assert_allclose(pos[left][:, 1], 0.0, atol=1e-5)
    assert (np.abs(color[left][:, :3] - (0, 0, 1)).max(axis=1) < 0.02).mean() > 0.85


def test_a_bad_rgba_npy_texture_is_a_one_line_error(tmp_path):
    np.save(tmp_path / "bad.npy", np.zeros((8, 8, 3), np.float32))
    out = run_cli("bake", "demo:plane", "--as", "displacement", "--displacement",
                  tmp_path / "bad.npy", "-o", tmp_path / "x.rk")
    assert_one_line_error(out, "(H, W, 4)")
    assert not (tmp_path / "x.rk").exists()


@pytest.mark.parametrize("kind", ["fifo", "truncated"])
def test_an_unreadable_displacement_file_is_a_one_line_error(tmp_path, kind):
    """A FIFO is refused before it is opened (reading it would block); an .npy texture whose
    body is shorter than its header says is a format error, not an internal one."""
    import os

    if kind == "fifo":
        path = tmp_path / "pipe.png"
        os.mkfifo(path)
    else:
        path = tmp_path / "short.npy"
        np.save(path, np.full((16, 16, 4), 0.5, np.float32))
        path.write_bytes(path.read_bytes()[:600])
    out = run_cli("bake", "demo:plane", "--as", "displacement", "--displacement", path,
                  "-o", tmp_path / "x.rk")
    assert_one_line_error(out, str(path), "not a file" if kind == "fifo" else "not a readable")
    assert not (tmp_path / "x.rk").exists()
