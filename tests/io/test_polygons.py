"""Ear clipping against each polygon's own area: every point inside is covered exactly once.

The reference is independent of the triangulation: an even-odd point-in-polygon test at many
random points, and the shoelace area.
"""

from __future__ import annotations

import numpy as np
import pytest
from helpers import inside_polygon, shoelace, triangles_covering
from scipy.spatial.transform import Rotation

from reliefkit.io.meshes.polygons import triangulate_polygon


def keyhole(n_arc: int = 24) -> np.ndarray:
    """A keyhole, counter-clockwise: a circle of radius 1 on top of a slot 0.6 wide."""
    start, stop = np.radians(-72.5), np.radians(252.5)  # where the slot meets the circle
    angles = np.linspace(start, stop, n_arc)
    arc = np.column_stack([np.cos(angles), np.sin(angles)])
    slot = [[-0.3, -2.0], [0.3, -2.0]]
    return np.vstack([arc, slot])


def star(points: int = 7) -> np.ndarray:
    angles = np.arange(2 * points) * np.pi / points
    radii = np.where(np.arange(2 * points) % 2 == 0, 1.0, 0.35)
    return np.column_stack([radii * np.cos(angles), radii * np.sin(angles)])


def comb_polygon() -> np.ndarray:
    """A comb, counter-clockwise: a base 12 x 1 with four 3-unit teeth, and collinear points
    along the base."""
    outline = [[0, 0], [3, 0], [6, 0], [9, 0], [12, 0], [12, 1]]
    for k in range(3, -1, -1):
        outline += [[3 * k + 2, 1], [3 * k + 2, 4], [3 * k + 1, 4], [3 * k + 1, 1]]
    outline += [[0, 1]]
    return np.array(outline, float)


def framed_hole() -> np.ndarray:
    """A 4 x 4 square with a 2 x 2 hole, joined by a zero-width cut (the classic keyhole
    polygon): the cut's two ends appear twice in the outline."""
    outer = [[0, 0], [4, 0], [4, 4], [0, 4], [0, 0]]
    inner = [[1, 1], [1, 3], [3, 3], [3, 1], [1, 1]]  # clockwise: the hole
    return np.array(outer + inner, float)


def assert_tiles(xy: np.ndarray, triangles: np.ndarray) -> None:
    """The triangles tile the polygon: n - 2 of them, same winding, each inside point once."""
    assert triangles.shape == (len(xy) - 2, 3)
    assert sorted(set(triangles.ravel())) == list(range(len(xy)))
    areas = [shoelace(xy[t]) for t in triangles]
    assert min(areas) >= -1e-12  # none flipped (zero-area ones may remove collinear points)
    np.testing.assert_allclose(sum(areas), shoelace(xy), rtol=1e-9)
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    points = np.random.default_rng(0).uniform(lo, hi, (4000, 2))
    np.testing.assert_array_equal(triangles_covering(xy[triangles], points),
                                  inside_polygon(xy, points).astype(int))


POLYGONS = {"keyhole": keyhole(), "star": star(), "comb": comb_polygon(),
            "framed_hole": framed_hole()}


@pytest.mark.parametrize("name", POLYGONS)
def test_concave_polygons_are_tiled(name):
    xy = POLYGONS[name]
    assert shoelace(xy) > 0
    flat = np.column_stack([xy, np.zeros(len(xy))])
    assert_tiles(xy, triangulate_polygon(flat))


@pytest.mark.parametrize("name", POLYGONS)
def test_clockwise_polygons_keep_their_winding(name):
    xy = POLYGONS[name][::-1]
    flat = np.column_stack([xy, np.zeros(len(xy))])
    triangles = triangulate_polygon(flat)
    assert_tiles(xy[:, ::-1], triangles)  # mirrored, the clockwise outline is anticlockwise


@pytest.mark.parametrize("start", range(4))
def test_concave_quad_uses_its_inner_diagonal(start):
    dart = np.array([[0, 0], [2, 1], [0, 2], [0.6, 1.0]])  # reflex at the last corner
    xy = np.roll(dart, start, axis=0)
    flat = np.column_stack([xy, np.zeros(4)])
    assert_tiles(xy, triangulate_polygon(flat))


def test_polygon_in_a_tilted_plane_with_noise():
    xy = keyhole()
    rng = np.random.default_rng(1)
    local = np.column_stack([xy, 1e-4 * rng.normal(size=len(xy))])
    rotation = Rotation.from_rotvec([0.7, -1.1, 0.4])
    placed = rotation.apply(local) + [5.0, -2.0, 30.0]
    assert_tiles(xy, triangulate_polygon(placed))


def test_repeated_and_collinear_vertices():
    square = np.array([[0, 0], [1, 0], [1, 0], [2, 0], [2, 1], [2, 2], [1, 2], [0, 2], [0, 1]],
                      float)
    flat = np.column_stack([square, np.zeros(len(square))])
    triangles = triangulate_polygon(flat)
    assert triangles.shape == (len(square) - 2, 3)
    areas = [shoelace(square[t]) for t in triangles]
    assert min(areas) >= 0
    np.testing.assert_allclose(sum(areas), 4.0)


def test_degenerate_polygon_still_gives_triangles():
    line = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0], [4, 0, 0.0]])
    assert triangulate_polygon(line).shape == (3, 3)


@pytest.mark.parametrize("seed", range(5))
def test_random_star_shaped_polygons(seed):
    rng = np.random.default_rng(seed)
    angles = np.sort(rng.uniform(0, 2 * np.pi, 60))
    radii = rng.uniform(0.2, 1.0, 60)
    xy = np.column_stack([radii * np.cos(angles), radii * np.sin(angles)])
    assert_tiles(xy, triangulate_polygon(np.column_stack([xy, np.zeros(60)])))
