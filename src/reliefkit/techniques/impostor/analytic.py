"""An impostor of a sphere computed without a GL: every frame is the same disc. The contract
tests' sample and the reference scene of the tests (a ray meets a sphere exactly)."""

from __future__ import annotations

import numpy as np

from ...colorspace import to_rgba8
from . import octahedral
from .representation import OctahedralImpostor


def sphere_impostor(center, sphere_radius: float, *, grid: int = 4, frame: int = 16,
                    padding: int = 2, hemi: bool = False, rgb=(0.8, 0.3, 0.1),
                    bounding_radius: float | None = None) -> OctahedralImpostor:
    """A sphere of ``sphere_radius`` at ``center`` in linear colour ``rgb``, as ``grid`` x
    ``grid`` frames of ``frame`` texels whose bounding sphere has ``bounding_radius``
    (default: the sphere's own). Texel centres inside the disc are covered; each stores the
    exact front height and normal there."""
    center = np.asarray(center, np.float64)
    radius = float(bounding_radius or sphere_radius)
    frame_radius = radius * frame / (frame - 2 * padding)
    coords = ((np.arange(frame) + 0.5) / frame * 2.0 - 1.0) * frame_radius
    s, t = np.meshgrid(coords, coords)  # row j is t (row 0 at the bottom)
    inside = s * s + t * t < sphere_radius ** 2
    h = np.sqrt(np.maximum(sphere_radius ** 2 - s * s - t * t, 0.0))
    depth_cell = np.round(((np.where(inside, h, 0.0) / radius) + 1.0) * 127.5).astype(np.uint8)
    side = grid * frame
    color = np.zeros((side, side, 4), np.uint8)
    normal = np.zeros((side, side, 3), np.uint8)
    depth = np.zeros((side, side), np.uint8)
    rgba = np.zeros((frame, frame, 4))
    rgba[...] = (*rgb, 1.0)
    rgba[~inside, 3] = 0.0
    directions = octahedral.frame_directions(grid, hemi)
    for j in range(grid):
        for i in range(grid):
            d = directions[j, i]
            right, up = octahedral.frame_basis(d)
            n = (s[..., None] * right + t[..., None] * up + h[..., None] * d) / sphere_radius
            n = np.where(inside[..., None], n, d)
            cell = (slice(j * frame, (j + 1) * frame), slice(i * frame, (i + 1) * frame))
            color[cell] = to_rgba8(rgba)
            normal[cell] = np.round((n + 1.0) * 127.5).astype(np.uint8)
            depth[cell] = depth_cell
    bounds = np.stack([center - sphere_radius, center + sphere_radius])
    return OctahedralImpostor(grid, hemi, center, radius, padding, color, normal, depth,
                              source_bounds=bounds, params={"source": "analytic sphere"})
