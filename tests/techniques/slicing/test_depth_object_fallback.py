"""The fallback mesh of depth objects and visual hulls (what a glTF viewer without reliefkit
shows): the carved volume at a triangle budget, against the source mesh and the exact CPU
carving."""

from __future__ import annotations

import numpy as np
import pytest

import reliefkit as rk
from reliefkit.errors import UsageError
from reliefkit.io.inputs import load_input
from reliefkit.metrics import mask_iou
from reliefkit.scene.views import orbit_bounds
from reliefkit.techniques.slicing.depth_images import DepthImages, cube_of, face_boxes
from reliefkit.techniques.slicing.reference import inside

VIEWS = ((30.0, 20.0), (150.0, -10.0), (270.0, 60.0))


def winding_numbers(mesh, points: np.ndarray) -> np.ndarray:
    """(P,) generalized winding number of a closed mesh at ``points`` (Van Oosterom &
    Strackee's solid angles): 1 inside, 0 outside."""
    corners = mesh.world_positions[mesh.indices]
    out = np.empty(len(points))
    for s in range(0, len(points), 256):
        a, b, c = (corners[None, :, k] - points[s:s + 256, None] for k in range(3))
        la, lb, lc = (np.linalg.norm(x, axis=-1) for x in (a, b, c))
        det = np.einsum("...i,...i", a, np.cross(b, c))
        dot = lambda x, y: np.einsum("...i,...i", x, y)  # noqa: E731
        den = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb
        out[s:s + 256] = np.arctan2(det, den).sum(axis=1) / (2 * np.pi)
    return out


@pytest.fixture(scope="module")
def vehicle():
    return load_input("demo:vehicle")


@pytest.mark.parametrize("kind", ["depth-object", "visual-hull"])
def test_the_fallback_looks_like_the_mesh_from_three_views(gl, vehicle, kind):
    rep = rk.bake(vehicle, kind, res=128)  # a depth object decimated, a hull not
    fallback = rep.fallback_mesh()
    assert fallback.triangle_count <= 20_000
    for azimuth, elevation in VIEWS:
        camera = orbit_bounds(vehicle.bounds, azimuth, elevation, size=(128, 128))
        want, got = rk.render(vehicle, camera, ctx=gl), rk.render(fallback, camera, ctx=gl)
        assert mask_iou(got, want) >= 0.9, (azimuth, elevation)
        mean = [f.color[..., :3][f.mask].mean(axis=0) for f in (got, want)]
        np.testing.assert_allclose(mean[0], mean[1], atol=0.015,
                                   err_msg=f"view {azimuth}, {elevation}")


def test_the_budget_is_honoured_and_used(gl):
    rep = rk.bake(load_input("demo:blob"), "depth-object", res=48)
    counts = [rep.fallback_mesh(t).triangle_count for t in (100, 1000, 10_000)]
    assert all(c <= t for c, t in zip(counts, (100, 1000, 10_000), strict=True))
    assert counts[0] > 50 and counts[1] > 500 and counts[2] > 5000


@pytest.mark.parametrize("kind, res", [("depth-object", 32), ("visual-hull", 32),
                                       ("depth-object", 64)])  # 64: decimated
def test_the_mesh_encloses_the_exactly_carved_volume(gl, kind, res):
    """Points more than a grid cell inside the nearest-texel object (the CPU reference's
    `inside` at every point of a lattice around them) are inside the mesh; points as far
    outside are outside."""
    rep = rk.bake(load_input("demo:blob"), kind, res=res)
    fallback = rep.fallback_mesh()
    lo, hi = rep.bounds
    margin = 1.5 * rep.images.texel  # the grid is never finer than a texel; here it is one
    points = lo + np.random.default_rng(1).random((4000, 3)) * (hi - lo)
    steps = np.linspace(-margin, margin, 5)  # 0.75 texel apart
    offsets = np.stack(np.meshgrid(steps, steps, steps), axis=-1).reshape(-1, 3)
    around = np.stack([inside(rep.images, points + o) for o in offsets])
    deep_in, deep_out = around.all(axis=0), ~around.any(axis=0)
    assert deep_in.sum() > 80 and deep_out.sum() > 80
    assert (winding_numbers(fallback, points[deep_in]) > 0.5).all()
    assert (winding_numbers(fallback, points[deep_out][:400]) < 0.5).all()


def test_a_budget_below_the_smallest_is_refused(gl):
    rep = rk.bake(load_input("demo:blob"), "visual-hull", res=16)
    for bad in (0, 99, 2.5, True):
        with pytest.raises(UsageError, match="at least 100 triangles"):
            rep.fallback_mesh(bad)


def test_an_empty_object_has_no_fallback():
    n = 8  # six images that see nothing
    cube = cube_of(load_input("demo:blob"))
    empty = DepthImages(np.ones((6, n, n)), np.zeros((6, n, n), bool), np.zeros((6, n, n, 4)),
                        np.zeros((6, n, n, 3)), face_boxes(cube), cube)
    with pytest.raises(UsageError, match="carve nothing"):
        rk.DepthObject(empty).fallback_mesh()
