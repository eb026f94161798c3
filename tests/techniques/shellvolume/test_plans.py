"""The shell as draw plans: each of its ways to draw (opaque composite, the sorted
transparent pass with and without the half-opacity search, depth peeling, shadows) gives
from a list of cameras the Frames of one render per camera, and its plans survive JSON and
draw the same Frame after the round trip."""

from __future__ import annotations

import json

import numpy as np
import pytest
from shell_scenes import grid_mesh, sphere_mesh

from reliefkit import render
from reliefkit.gl.targets import draw_passes
from reliefkit.render.executor import Executor
from reliefkit.render.frame import frame_from_passes
from reliefkit.render.plan import from_json, to_json
from reliefkit.scene.camera import Camera
from reliefkit.scene.light import DirectionalLight
from reliefkit.scene.mesh import RenderMesh
from reliefkit.techniques.shellvolume import textures
from reliefkit.techniques.shellvolume.render import ShellRenderOptions, TexturedShellDrawable
from reliefkit.techniques.shellvolume.representation import TexturedShell

#: Each way the drawable draws: its options, and the multi-pass kind that draws it.
WAYS = {
    "opaque": ({"composite": "opaque"}, None),
    "opaque, shadows": ({"composite": "opaque", "shadows": True}, "shadow-map"),
    "sorted": ({}, "half-opacity-search"),
    "sorted, no search": ({"half_opacity": False}, "opaque-depth"),
    "centroid, vertex exits": ({"sort": "centroid", "exit": "vertex"}, "half-opacity-search"),
    "peeled": ({"sort": "peel"}, "depth-peel"),
    "sorted, shadows, animated": ({"shadows": True, "time": 0.25}, "half-opacity-search"),
}
ARRAYS = ("color", "mask", "depth", "position", "normal")
LIGHT = DirectionalLight(direction=(0.4, 0.8, 0.3))


@pytest.fixture(scope="module")
def shell():
    return TexturedShell(sphere_mesh(1), 0.25, textures.make_ellipsoids(size=(8, 8, 4)))


@pytest.fixture(scope="module")
def backdrop():
    """An opaque wall behind the shell, which its segments stop at."""
    wall = grid_mesh(2)
    return RenderMesh(wall.world_positions * (3, 3, 1) - (0, 0, 0.9), wall.indices,
                      wall.normals, np.tile((0.8, 0.8, 0.8, 1.0), (len(wall.normals), 1)))


def cameras():
    return [Camera.orbit((0.0, 0.0, 0.0), az, el, 3.5, fov_deg=40.0, size=(40, 32))
            for az, el in ((20.0, 15.0), (150.0, -30.0))]


def same_frames(a, b) -> None:
    for name in ARRAYS:
        assert np.array_equal(getattr(a, name), getattr(b, name), equal_nan=True), name
    untimed = [{k: v for k, v in f.stats.items() if "seconds" not in k} for f in (a, b)]
    assert untimed[0] == untimed[1]
    assert a.warnings == b.warnings


@pytest.mark.parametrize("way", WAYS)
def test_a_list_of_cameras_gives_the_frames_of_single_renders(gl, shell, backdrop, way):
    """Uploaded once, drawn twice: the view hook sorts again for the second camera, the
    shadow map is kept for the same light, and nothing of the first frame shows."""
    options, kind = WAYS[way]
    plans = TexturedShellDrawable(shell, ShellRenderOptions(**options)).plans
    assert [p.multipass.kind if p.multipass else None for p in plans] == [kind]
    both = render([backdrop, shell], cameras(), ctx=gl, light=LIGHT, samples=4, **options)
    for camera, frame in zip(cameras(), both, strict=True):
        alone = render([backdrop, shell], camera, ctx=gl, light=LIGHT, samples=4, **options)
        assert alone.stats["covered"] > 100
        same_frames(frame, alone)


def frame_of_plans(ctx, plans, camera):
    """A Frame of ``plans`` alone, drawn by an executor of their own."""
    executor = Executor(ctx)
    try:
        executor.upload(plans)

        def draw(render_pass):
            return lambda: [executor.draw(p, camera, LIGHT) for p in plans
                            if p.render_pass == render_pass]

        transparent = any(p.render_pass == "transparent" for p in plans)
        images = draw_passes(ctx, camera.size, draw("opaque"),
                             [draw("transparent")] if transparent else [])
        return frame_from_passes(camera, images)
    finally:
        executor.release()


@pytest.mark.parametrize("way", WAYS)
def test_plans_survive_json_and_draw_the_same_frame(gl, shell, way):
    """The plans are plain data (the view hook's too: the visibility order's cells), and
    the plans read back draw the Frame `render` draws."""
    options, _ = WAYS[way]
    plans = TexturedShellDrawable(shell, ShellRenderOptions(samples=4, **options)).plans
    doc, arrays = to_json(plans)
    doc = json.loads(json.dumps(doc))
    assert all(isinstance(a, np.ndarray) for a in arrays.values())
    back = from_json(doc, {k: a.copy() for k, a in arrays.items()})
    camera = cameras()[0]
    frame = frame_of_plans(gl, back, camera)
    expected = render(shell, camera, ctx=gl, light=LIGHT, samples=4, **options)
    assert expected.stats["covered"] > 100
    for name in ARRAYS:
        assert np.array_equal(getattr(frame, name), getattr(expected, name),
                              equal_nan=True), name
