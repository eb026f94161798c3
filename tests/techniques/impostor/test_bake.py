"""Baking impostors: the frames are the mesh seen from the grid's directions, the atlas
sizes follow the options, bad options fail in one line, and the .rk file round-trips."""

from __future__ import annotations

import json
import zipfile

import numpy as np
import pytest
from helpers import assert_one_line_error, run_cli

from reliefkit.bake import bake
from reliefkit.errors import FormatError, UsageError
from reliefkit.io import rk
from reliefkit.render import render
from reliefkit.scene.assets import make_asset
from reliefkit.scene.camera import Camera
from reliefkit.techniques.impostor import octahedral
from reliefkit.techniques.impostor.bake import frame_camera


@pytest.fixture(scope="module")
def blob_impostor(gl):
    return bake(make_asset("blob"), "octahedral-impostor", grid=5, atlas_res=160)


def test_each_frame_is_the_mesh_seen_from_its_direction(blob_impostor):
    """Frame (i, j)'s coverage is the mesh's mask from `frame_directions`[j, i] and its
    depth the mesh's surface height along that direction, to a step of the uint8 depth."""
    mesh, rep = make_asset("blob"), blob_impostor
    size = rep.frame
    assert rep.color.shape == (5 * size, 5 * size, 4) and size == 160 // 5
    directions = octahedral.frame_directions(5, False)
    for j, i in ((0, 0), (2, 3), (4, 1)):
        d = directions[j, i]
        seen = render(mesh, frame_camera(rep.center, rep.radius, rep.frame_radius, d, size))
        cell = (slice(j * size, (j + 1) * size), slice(i * size, (i + 1) * size))
        mask = seen.mask[::-1]
        np.testing.assert_array_equal(rep.color[cell][..., 3] > 0, mask)
        height = (seen.position[::-1][mask] - rep.center) @ d
        stored = (rep.depth[cell][mask] / 255.0 * 2.0 - 1.0) * rep.radius
        assert np.abs(stored - height).max() <= rep.radius / 255 + 1e-9
        # dilated: the empty texels hold a covered texel's normal, not zeros
        assert (rep.normal[cell][~mask].astype(int).sum(axis=-1) > 0).all()


def test_the_rk_file_round_trips(blob_impostor, tmp_path):
    rk.save(tmp_path / "imp.rk", blob_impostor)
    back = rk.load(tmp_path / "imp.rk")
    for name in ("color", "normal", "depth", "center", "source_bounds"):
        np.testing.assert_array_equal(getattr(back, name), getattr(blob_impostor, name))
    assert (back.grid, back.hemi, back.radius, back.padding) == \
        (blob_impostor.grid, blob_impostor.hemi, blob_impostor.radius, blob_impostor.padding)
    camera = Camera.orbit(blob_impostor.center, 40, 20, 3.0, size=(48, 48))
    np.testing.assert_array_equal(render(back, camera).color,
                                  render(blob_impostor, camera).color)


def test_a_grid_the_atlas_does_not_divide_is_refused_on_load(blob_impostor, tmp_path):
    path = tmp_path / "imp.rk"
    rk.save(path, blob_impostor)
    with zipfile.ZipFile(path) as z:
        members = {n: z.read(n) for n in z.namelist()}
    manifest = json.loads(members["manifest.json"])
    manifest["params"]["grid"] = 7  # 160 texels are not 7 frames
    forged = tmp_path / "forged.rk"
    with zipfile.ZipFile(forged, "w") as z:
        for name, data in members.items():
            z.writestr(name, json.dumps(manifest) if name == "manifest.json" else data)
    with pytest.raises(FormatError, match="multiple of the grid"):
        rk.load(forged)


@pytest.mark.parametrize("args,words", [
    (("--grid", "1"), ("--grid",)),
    (("--grid", "2"), ("--grid 3", "--hemi")),
    (("--grid", "12", "--atlas-res", "120"), ("--atlas-res", "--grid")),
])
def test_bad_options_fail_in_one_line(tmp_path, args, words):
    result = run_cli("bake", "demo:blob", "--as", "octahedral-impostor", *args,
                     "-o", tmp_path / "x.rk")
    assert_one_line_error(result, *words)
    assert not (tmp_path / "x.rk").exists()


def test_the_api_refuses_an_atlas_too_small_before_drawing():
    with pytest.raises(UsageError, match="--atlas-res 144 or more"):
        bake(make_asset("blob"), "octahedral-impostor", grid=12, atlas_res=100)
