"""Relief textures of a mesh far from the world origin match those of the mesh at the origin:
the same heightfield baked, the same picture drawn, hit positions in world coordinates."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from reliefkit.bake import bake
from reliefkit.render import render
from reliefkit.scene.camera import Camera
from reliefkit.scene.mesh import RenderMesh, vertex_normals


def blob(offset=0.0) -> RenderMesh:
    """A squashed unit sphere coloured by its normal, moved by ``offset`` on every axis."""
    sphere = trimesh.creation.icosphere(subdivisions=3)
    positions = np.asarray(sphere.vertices, np.float64) * [1.0, 0.6, 0.8]
    normals = vertex_normals(positions, sphere.faces)
    colors = np.c_[0.5 + 0.5 * normals, np.ones(len(normals))]
    return RenderMesh(positions + offset, sphere.faces, normals, colors, name="blob")


@pytest.mark.parametrize("kind, offset", [("relief", 1e4), ("relief", 1e6), ("relief", 1e8),
                                          ("relief-frustum", 1e8), ("relief-cube", 1e8)])
def test_a_far_relief_bakes_and_draws_like_the_one_at_the_origin(gl, kind, offset):
    near, far = (bake(blob(o), kind, depth_res=32, safety=False) for o in (0.0, offset))
    parts = lambda rep: getattr(rep, "parts", [rep])  # noqa: E731
    for a, b in zip(parts(near), parts(far), strict=True):
        assert np.abs(a.height - b.height).max() < 1e-4  # the same heightfield baked
        np.testing.assert_allclose(b.box_to_world[:3, 3] - a.box_to_world[:3, 3],
                                   offset * a.box_to_world[3, 3], rtol=1e-12)
    frames = [render(rep, Camera.orbit(np.full(3, o), 35.0, 25.0, 3.0, size=(72, 72)),
                     method="exact") for rep, o in ((near, 0.0), (far, offset))]
    reference, frame = frames
    assert reference.mask.sum() > 1000 and (reference.mask != frame.mask).sum() <= 4
    both = reference.mask & frame.mask
    # the cube's frusta meet at seams, where rounding picks one part or the other
    differ = np.abs(frame.color[both] - reference.color[both]).max(axis=-1) > 5e-3
    assert differ.sum() <= (0.005 * both.sum() if kind == "relief-cube" else 0)
    assert np.abs(frame.position[both] - offset - reference.position[both]).max() < 1e-3


def test_robust_walks_on_a_far_heightfield_agree_with_exact_ones(gl):
    rep = bake(blob(1e8), "relief", depth_res=32)
    camera = Camera.orbit(np.full(3, 1e8), 35.0, 25.0, 3.0, size=(72, 72))
    exact, robust = (render(rep, camera, method=m) for m in ("exact", "robust"))
    assert exact.mask.sum() > 1000 and (exact.mask != robust.mask).sum() <= 0.005 * exact.mask.sum()
