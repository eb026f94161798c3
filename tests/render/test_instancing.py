"""Instanced drawing (render/instancing.py): N placements of an object in one draw call per
plan draw what the N placed objects, each drawn by itself and composited by depth, draw.

The reference draws the object as it is, with the existing (uninstanced) path, from the
camera moved into each instance's frame (view @ P, the light turned by R^T): that is what
the camera sees of the object placed by P, an independent route to the same picture; the
frames are then composited by depth and their positions and normals placed by P.
"""

from __future__ import annotations

import json
from dataclasses import dataclass

import numpy as np
import pytest
from helpers import sample, technique_samples

from reliefkit.render import render
from reliefkit.render.draw import Scene
from reliefkit.render.instancing import NotInstanceable, placements
from reliefkit.scene.assets import make_asset
from reliefkit.scene.camera import Camera
from reliefkit.scene.light import DirectionalLight

pytestmark = pytest.mark.usefixtures("toy_registered")

#: The kinds drawn instanced, and the mesh (the ground truth and the decimated mesh).
INSTANCEABLE = {("relief", "relief"), ("relief", "relief-object"),
                ("billboard", "billboard-cloud"), ("slicing", "depth-object"),
                ("slicing", "visual-hull"),  # the depth objects ray cast by default
                ("impostor", "octahedral-impostor")}
SIZE = (128, 128)
#: Three placements about the origin that overlap on screen (the depth test decides).
PLACED = placements([[-1.3, 0.0, 0.2], [1.1, 0.3, -0.6], [0.1, -0.5, 1.0]],
                    scales=[0.6, 0.8, 0.5], yaws=[0.5, -1.0, 2.5])



def _matrix(p) -> np.ndarray:
    """The 4x4 similarity of one placement [x, y, z, scale, yaw]."""
    c, s = np.cos(p[4]), np.sin(p[4])
    m = np.eye(4)
    m[:3, :3] = p[3] * np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    m[:3, 3] = p[:3]
    return m


@dataclass(frozen=True, eq=False)
class ObjectFrameCamera:
    """``camera`` in the object's own frame for placement matrix ``m``: drawing the object as
    it is from here gives what ``camera`` sees of the object placed by ``m``."""

    camera: Camera
    m: np.ndarray

    def _back(self, point) -> tuple:
        return tuple(np.linalg.solve(self.m, np.append(point, 1.0))[:3])

    @property
    def view(self):
        return self.camera.view @ self.m

    @property
    def eye(self):
        return self._back(self.camera.eye)

    @property
    def target(self):
        return self._back(self.camera.target)

    @property
    def origin(self):
        return np.asarray(self.target)

    def __getattr__(self, name):  # proj, size, near, far, fov_deg, orthographic, viewport
        return getattr(self.camera, name)


def _composited(obj, camera, light):
    """The object drawn by itself at each placement, nearest depth wins per pixel."""
    frames = []
    for p in PLACED:
        m = _matrix(p)
        rotation = m[:3, :3] / p[3]
        turned = DirectionalLight(direction=tuple(rotation.T @ light.unit_direction))
        frame = render(obj, ObjectFrameCamera(camera, m), light=turned)
        frame.position = frame.position @ m[:3, :3].T + m[:3, 3]
        frame.normal = frame.normal @ rotation.T
        frames.append(frame)
    nearest = np.argmin(np.stack([f.depth for f in frames]), axis=0)

    def pick(name):
        stack = np.stack([getattr(f, name) for f in frames])
        return np.take_along_axis(stack, nearest[None, ..., None] if stack.ndim == 4
                                  else nearest[None], axis=0)[0]

    return {name: pick(name) for name in ("color", "mask", "depth", "position", "normal")}


def _instanceable_objects():
    return [pytest.param(sample(*tk), id=f"{tk[0]}:{tk[1]}")
            for tk in technique_samples() if tk in INSTANCEABLE] + [
        pytest.param(make_asset("blob"), id="mesh")]


@pytest.mark.parametrize("obj", _instanceable_objects())
def test_instances_draw_the_placed_objects_composited_by_depth(gl, obj):
    camera = Camera.orbit((0.0, 0.0, 0.0), 30, 25, 5.0, size=SIZE, near=1.0, far=20.0)
    light = DirectionalLight()
    got = render(obj, camera, light=light, instances=PLACED)
    want = _composited(obj, camera, light)
    assert got.stats["instances"] == 3
    # The two routes round the placed geometry and rays differently (float32, about 1e-7
    # of the scene): a pixel whose centre is that close to an edge may fall on either side
    # of it, a silhouette (coverage, depth) or a crease (which face's normal and colour:
    # the rim of a relief box). Such pixels are a few along the edges; elsewhere the
    # pictures agree to float32 rounding, but for a few more on a relief box's side walls:
    # a hit there is on the wall only when it is exactly at the ray's entry (relief.glsl's
    # s_hit <= s0), which rounding may move a step inside (the top's normal then).
    differ = got.mask != want["mask"]
    assert want["mask"].sum() > 500 and differ.sum() <= 0.005 * want["mask"].sum()
    both = got.mask & want["mask"]
    same_surface = both & (np.abs(got.depth - want["depth"]) < 1e-4)
    assert same_surface.sum() >= 0.99 * both.sum()
    np.testing.assert_allclose(got.position[same_surface], want["position"][same_surface],
                               atol=1e-4)
    smooth = same_surface & ~_edges(want["mask"], want["normal"])
    assert smooth.sum() >= 0.5 * both.sum()  # small instances: many edge pixels
    for aov in ("color", "normal"):
        close = np.abs(getattr(got, aov) - want[aov]).max(-1) <= 2e-3
        assert (smooth & ~close).sum() <= 0.02 * smooth.sum(), aov


def _edges(mask: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """Pixels next to a silhouette or a crease: a 4-neighbour uncovered or whose normal
    turns by more than 45 degrees."""
    n = np.where(mask[..., None], normal, 0.0)
    edge = np.zeros(mask.shape, bool)
    for axis in (0, 1):
        for shift in (1, -1):
            cos = (n * np.roll(n, shift, axis)).sum(-1)
            edge |= np.roll(~mask, shift, axis) | (cos < np.cos(np.radians(45)))
    return edge


def _refused():
    return [pytest.param(*tk, id=f"{tk[0]}:{tk[1]}")
            for tk in technique_samples() if tk not in INSTANCEABLE]


@pytest.mark.parametrize("technique, kind", _refused())
def test_other_kinds_are_refused_with_the_reason(gl, technique, kind):
    camera = Camera.orbit((0.0, 0.0, 0.0), 30, 25, 7.0, size=(32, 32))
    with pytest.raises(NotInstanceable) as info:
        render(sample(technique, kind), camera, instances=PLACED)
    message = str(info.value)
    assert "cannot be drawn instanced: " in message and "\n" not in message


def test_the_mesh_with_shadows_is_refused(gl):
    camera = Camera.orbit((0.0, 0.0, 0.0), 30, 25, 7.0, size=(32, 32))
    with pytest.raises(NotInstanceable, match="shadow-map"):
        render(make_asset("tree"), camera, instances=PLACED, shadows=True)


@pytest.mark.parametrize("obj", _instanceable_objects())
def test_one_draw_call_per_plan_whatever_the_count(gl, obj):
    camera = Camera.orbit((0.0, 0.0, 0.0), 30, 25, 30.0, size=(64, 64))
    grid = np.stack(np.meshgrid(np.arange(20.0), [0.0], np.arange(20.0)), -1).reshape(-1, 3)
    for count in (1, 3, 400):
        with Scene(obj, instances=placements(3 * grid[:count] - 30)) as scene:
            scene.frame(camera)
            assert scene.executor.draw_calls == len(scene.drawables[0].plans)


@pytest.mark.parametrize("bad, words", [
    (np.zeros((0, 5)), "0 instances"),
    (np.array([[0, 0, 0, 0.0, 0]]), "positive scales"),
    (np.array([[0, np.nan, 0, 1.0, 0]]), "finite"),
    (np.zeros((3, 4)), "(N, 5)")])
def test_bad_placements_are_one_line_errors(gl, bad, words):
    camera = Camera.orbit((0.0, 0.0, 0.0), 30, 25, 7.0, size=(32, 32))
    with pytest.raises(Exception) as info:
        render(make_asset("tree"), camera, instances=bad)
    assert words in str(info.value) and "\n" not in str(info.value)


def test_a_depth_object_drawn_by_slices_is_refused(gl):
    camera = Camera.orbit((0.0, 0.0, 0.0), 30, 25, 7.0, size=(32, 32))
    with pytest.raises(NotInstanceable, match="view hook works per object .*slice stack"):
        render(sample("slicing", "depth-object"), camera, instances=PLACED,
               slicing="orthogonal")


@pytest.mark.parametrize("technique, kind, reason", [
    ("billboard", "dmbbc", "it flattens each box and hands it over to the billboard cloud by "
                           "the object's own distance from the camera"),
    ("slicing", "displacement", "it cuts new slice polygons through the object's own shell "
                                "for each camera")])
def test_a_per_object_view_hook_is_refused_with_a_reason_a_user_reads(gl, technique, kind,
                                                                      reason):
    """The hook's declared reason, not its docstring (no ``markup``, no cross-references)."""
    camera = Camera.orbit((0.0, 0.0, 0.0), 30, 25, 7.0, size=(32, 32))
    with pytest.raises(NotInstanceable) as info:
        render(sample(technique, kind), camera, instances=PLACED)
    assert str(info.value).endswith(f"cannot be drawn instanced: its view hook works per "
                                    f"object ({reason})")


def test_instanced_plans_round_trip_through_json(gl):
    from reliefkit.render.instancing import instanced
    from reliefkit.render.plan import from_json, to_json
    from reliefkit.render.registry import make_drawables

    plans = instanced(make_drawables([sample("relief", "relief-object")], {})[0].plans, PLACED)
    doc, arrays = to_json(plans)
    again = from_json(json.loads(json.dumps(doc)), arrays)
    assert [p.per_view.function for p in again] == [p.per_view.function for p in plans]
    for got, want in zip(again, plans, strict=True):
        assert got.geometry.instances == want.geometry.instances == len(PLACED)
        assert dict(got.program.defines) == dict(want.program.defines)
        for name in ("in_instance", "in_instance_yaw"):
            np.testing.assert_array_equal(got.geometry.attributes[name].array,
                                          want.geometry.attributes[name].array)
            assert got.geometry.attributes[name].per_instance
