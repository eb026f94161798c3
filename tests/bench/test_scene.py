"""`reliefkit bench scene`: the field's layout, equal error and the device-independent
counts of its timed frames."""

from __future__ import annotations

import numpy as np

from reliefkit.bench import scene
from reliefkit.metrics import ssim
from reliefkit.render import render
from reliefkit.scene.assets import make_asset
from reliefkit.scene.decimate import decimated, mesh_bytes
from reliefkit.scene.views import bounds_radius


def _sphere_pixels(layout, asset):
    """Every instance's bounding-sphere centre in pixels (x right, y up) and its diameter
    in pixels, from the camera's own matrices."""
    camera, p = layout["camera"], layout["placements"]
    centre = np.mean(asset.bounds, axis=0)
    c, s = np.cos(p[:, 4]), np.sin(p[:, 4])
    centres = p[:, :3] + p[:, 3:4] * np.column_stack(
        [c * centre[0] + s * centre[2], np.full(len(p), centre[1]), -s * centre[0] + c * centre[2]])
    clip = np.c_[centres, np.ones(len(p))] @ (camera.proj @ camera.view).T
    w, h = camera.size
    xy = (clip[:, :2] / clip[:, 3:] + 1) / 2 * [w, h]
    diameter = 2 * bounds_radius(asset.bounds) * camera.proj[1, 1] * h / 2
    return xy, diameter


def test_every_instance_is_the_stated_size_and_in_the_frame():
    asset = make_asset("tree")
    layout = scene.field(asset, 150, 16, 320)
    xy, diameter = _sphere_pixels(layout, asset)
    assert len(layout["placements"]) == 150
    np.testing.assert_allclose(diameter, 16, rtol=1e-9)
    w, h = layout["camera"].size
    assert w <= 320 + 16 and (xy >= 8 - 1e-6).all() and (xy <= [w - 8 + 1e-6, h - 8 + 1e-6]).all()


def test_the_decimated_mesh_is_at_least_as_good_as_the_representation(gl):
    asset = make_asset("tree")
    views = [scene.instance_camera(asset, az, 32) for az in scene.SSIM_AZIMUTHS]
    truth = render(asset, views)
    coarse = decimated(asset, mesh_bytes(asset) // 20)  # stands in for a representation
    row, mesh = scene.equal_error("coarse", coarse, asset, views, truth)
    measured = np.mean([ssim(f, t) for f, t in zip(render(mesh, views), truth, strict=True)])
    wanted = np.mean([ssim(f, t) for f, t in zip(render(coarse, views), truth, strict=True)])
    assert measured >= wanted and row["decimated_ssim"] == measured
    assert row["decimated_bytes"] == mesh_bytes(mesh) < mesh_bytes(asset)


def test_a_field_is_one_draw_call_per_plan_with_every_triangle(gl):
    asset = make_asset("tree")
    layout = scene.field(asset, 30, 16, 160)
    half = decimated(asset, mesh_bytes(asset) // 2)
    timed = scene.time_field(asset, {"half": half}, {"half": half}, layout, repeats=1)
    assert timed["instances"] == 30
    for name, mesh in (("full mesh", asset), ("half", half), ("half decimated", half)):
        assert timed["times"][name]["draw_calls"] == 1
        assert timed["times"][name]["primitives"] == 30 * mesh.triangle_count
        assert timed["times"][name]["samples_passed"] > 0
