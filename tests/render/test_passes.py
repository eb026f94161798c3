"""Render passes on an analytic scene: transparent quads of known opacity over an opaque mesh.

Colour is composited front to back (straight alpha in the Frame); depth, position and normal
belong to the point where the accumulated opacity first reaches 0.5 (docs/architecture.md,
"Frame").
The expected values come from the quads' analytic colours and the mesh rendered alone.
"""

from __future__ import annotations

import numpy as np
import pytest
from helpers import toy_technique

from reliefkit.errors import UsageError
from reliefkit.render import render
from reliefkit.render.executor import Executor
from reliefkit.render.frame import window_depth
from reliefkit.scene.camera import Camera
from reliefkit.scene.mesh import RenderMesh

CAMERA = Camera(eye=(0.0, 0.0, 3.0), target=(0.0, 0.0, 0.0), size=(48, 40))
BACKDROP = RenderMesh(  # an opaque quad at z = -1, facing the camera
    positions=[[-3, -3, -1], [3, -3, -1], [3, 3, -1], [-3, 3, -1]],
    indices=[[0, 1, 2], [0, 2, 3]], normals=[[0, 0, 1]] * 4, colors=[[0.1, 0.6, 0.3, 1]] * 4)


@pytest.fixture(scope="module")
def toy():
    with toy_technique() as module:
        yield module


def quad(toy, z, half, rgb, opacity, x0=0.0):
    corners = [[x0 - half, -half, z], [x0 + half, -half, z], [x0 + half, half, z],
               [x0 - half, half, z]]
    return toy.ToyQuad(corners, [*rgb, opacity])


def inside(z, half, x0=0.0, margin=0.05):
    """Pixels whose ray meets the plane z inside the square (away from its edges)."""
    origins, dirs = CAMERA.pixel_rays()
    t = (z - origins[..., 2]) / dirs[..., 2]
    p = origins + t[..., None] * dirs
    return (np.abs(p[..., 0] - x0) < half - margin) & (np.abs(p[..., 1]) < half - margin)


def plane_points(z):
    origins, dirs = CAMERA.pixel_rays()
    t = (z - origins[..., 2]) / dirs[..., 2]
    return origins + t[..., None] * dirs


@pytest.mark.parametrize("opacity", [0.7, 0.3])
def test_one_transparent_quad_over_a_mesh(gl, toy, opacity):
    rgb = np.array([0.9, 0.2, 0.1])
    backdrop = render(BACKDROP, CAMERA)
    frame = render([quad(toy, 0.0, 0.5, rgb, opacity), BACKDROP], CAMERA)
    region = inside(0.0, 0.5)
    expected = opacity * rgb + (1 - opacity) * backdrop.color[region][:, :3]
    np.testing.assert_allclose(frame.color[region][:, :3], expected, atol=2e-6)
    np.testing.assert_allclose(frame.color[region][:, 3], 1.0, atol=1e-6)
    outside = ~inside(0.0, 0.5, margin=-0.1)
    np.testing.assert_array_equal(frame.color[outside], backdrop.color[outside])
    if opacity >= 0.5:  # the quad is where the opacity reaches 0.5
        np.testing.assert_allclose(frame.position[region], plane_points(0.0)[region], atol=1e-5)
        np.testing.assert_allclose(frame.normal[region], [[0, 0, 1]] * region.sum(), atol=1e-6)
    else:  # it reaches 0.5 only at the mesh behind
        np.testing.assert_array_equal(frame.position[region], backdrop.position[region])
    expected_depth = window_depth(frame.position, CAMERA.view, CAMERA.proj, frame.depth)
    np.testing.assert_allclose(frame.depth[region], expected_depth[region], atol=1e-6)


def test_transparent_quad_alone_keeps_its_opacity_and_never_reaches_half(gl, toy):
    rgb = np.array([0.2, 0.3, 0.9])
    frame = render(quad(toy, 0.0, 0.5, rgb, 0.4), CAMERA)
    region = inside(0.0, 0.5)
    np.testing.assert_allclose(frame.color[region], [[*rgb, 0.4]] * region.sum(), atol=2e-6)
    assert frame.mask[region].all() and not frame.mask[~inside(0.0, 0.5, margin=-0.1)].any()
    assert np.isnan(frame.position[region]).all() and (frame.depth[region] == 1).all()


@pytest.mark.parametrize("order", ["front first", "back first"])
def test_two_layers_reach_half_at_the_second(gl, toy, order):
    front_rgb, back_rgb = np.array([0.9, 0.9, 0.1]), np.array([0.1, 0.2, 0.9])
    front, back = quad(toy, 0.5, 0.4, front_rgb, 0.4), quad(toy, 0.0, 0.6, back_rgb, 0.4)
    frame = render([front, back] if order == "front first" else [back, front], CAMERA)
    both = inside(0.5, 0.4) & inside(0.0, 0.6)
    alpha = 0.4 + 0.6 * 0.4
    premultiplied = 0.4 * front_rgb + 0.6 * 0.4 * back_rgb
    np.testing.assert_allclose(frame.color[both][:, 3], alpha, atol=1e-6)
    np.testing.assert_allclose(frame.color[both][:, :3], [premultiplied / alpha] * both.sum(),
                               atol=2e-6)
    # 0.4 after the front layer, 0.64 after the back one: the AOVs are the back layer's
    np.testing.assert_allclose(frame.position[both], plane_points(0.0)[both], atol=1e-5)


def test_opaque_drawables_hide_transparent_ones_behind_them(gl, toy):
    hidden = quad(toy, -1.5, 0.5, (1.0, 0.0, 0.0), 0.9)
    backdrop = render(BACKDROP, CAMERA)
    frame = render([hidden, BACKDROP], CAMERA)
    np.testing.assert_array_equal(frame.color, backdrop.color)
    np.testing.assert_array_equal(frame.position, backdrop.position)


def test_gpu_objects_are_released_when_a_draw_fails(gl, toy, monkeypatch):
    made = []
    real_release = Executor.release

    def failing_draw(self, *args, **kwargs):
        raise UsageError("draw failed on purpose")

    def recorded_release(self):
        made.extend(self._made)
        real_release(self)

    monkeypatch.setattr(Executor, "draw_viewed", failing_draw)
    monkeypatch.setattr(Executor, "release", recorded_release)
    with pytest.raises(UsageError, match="on purpose"):
        render([quad(toy, 0.0, 0.5, (1, 1, 1), 0.5), BACKDROP], CAMERA)
    assert made, "the plans were uploaded before the draw failed"
    assert all(type(obj.mglo).__name__ == "InvalidObject" for obj in made)
    monkeypatch.undo()
    assert render(BACKDROP, CAMERA).mask.any()  # the context still works
    assert gl.error == "GL_NO_ERROR"


def test_any_iterable_of_cameras_gives_a_list_of_frames(gl):
    frames = render(BACKDROP, iter([CAMERA, CAMERA]))
    assert len(frames) == 2
    np.testing.assert_array_equal(frames[0].color, frames[1].color)
    for bad in ([], 5, [CAMERA, "camera"]):
        with pytest.raises(UsageError, match="a camera or"):
            render(BACKDROP, bad)
