"""The cup asset: a mug with a thick wall, a floor and a handle, the concave object the
visual hull cannot show (§5 of the slicing paper: "a cup cannot be rendered correctly")."""

from __future__ import annotations

import numpy as np

from .colors import mix, rgb, smoothstep
from .geometry import Geometry, MeshBuilder, isosurface
from .params import check_int

OUTER_RADIUS, INNER_RADIUS = 0.62, 0.52
BOTTOM, FLOOR, RIM = -0.8, -0.6, 0.8


def _cup_field(p: np.ndarray) -> np.ndarray:
    """Signed distance (approximate, negative inside) of the mug: a capped tube with a floor,
    and a torus handle on +x."""
    x, y, z = p[..., 0], p[..., 1], p[..., 2]
    r = np.hypot(x, z)
    outer = np.maximum(r - OUTER_RADIUS, np.maximum(BOTTOM - y, y - RIM))
    hole = np.maximum(r - INNER_RADIUS, FLOOR - y)
    body = np.maximum(outer, -hole)
    hx, hy = x - OUTER_RADIUS, y - 0.05
    ring = np.hypot(np.hypot(hx, hy) - 0.34, z) - 0.07
    handle = np.maximum(ring, OUTER_RADIUS - 0.02 - x)  # only the part outside the wall
    return np.minimum(body, handle)


def cup(subdivisions: int = 4):
    """A mug about 1.6 high: outer radius 0.62, a 0.1 wall, its inside open from the rim
    (y = 0.8) down to its floor (y = -0.6), and a round handle on +x.

    Parameters
    ----------
    subdivisions : int
        Level of detail in [1, 5]: the field is sampled on ``5 * 2**subdivisions`` points per
        axis over [-1.1, 1.1].
    """
    n = 5 * 2 ** check_int("subdivisions", subdivisions, 1, 5)
    axis = np.linspace(-1.1, 1.1, n)
    grid = np.stack(np.meshgrid(axis, axis, axis, indexing="ij"), axis=-1)
    positions, faces, normals = isosurface(_cup_field(grid), 1.1)
    inside = np.hypot(positions[:, 0], positions[:, 2]) < 0.5 * (INNER_RADIUS + OUTER_RADIUS)
    inside &= (positions[:, 1] > FLOOR - 0.03) & (positions[:, 1] < RIM - 0.01)
    color = mix(rgb(70, 110, 190), rgb(120, 170, 230),
                smoothstep(BOTTOM, RIM, positions[:, 1]))
    color = np.where(inside[:, None], rgb(236, 226, 200), color)
    builder = MeshBuilder()
    builder.add("cup", Geometry(positions, faces, normals), color)
    return builder.build("cup")
