"""The scale of a surface's detail, for bakers that lay a textured layer over a mesh (a shell
volume, a displacement map): how thick the layer is and how often its texture repeats, when
the user does not say.

A fixed fraction of the bounding box turns a real mesh into a blob (a spider's legs are
thinner than 5% of its diagonal) and one tile stretched over a whole uv atlas smears the
texture; both follow the mesh's own detail instead:

- `layer_thickness`: `LAYER_PER_EDGE` of the median edge length (the median: a few long
  edges of a coarse part do not thicken the layer over the fine ones);
- `uv_tiling`: per uv axis, as many tiles as make one tile `TILE_PER_LAYER` layer
  thicknesses long on the surface (a texel density: a texture of N texels per tile has
  N / (TILE_PER_LAYER * thickness) texels per unit of length), from the world length of one
  unit of u and of v averaged over the uv map.
"""

from __future__ import annotations

import numpy as np

#: The default layer is this fraction of the mesh's median edge length thick.
LAYER_PER_EDGE = 0.5
#: A default tile spans this many layer thicknesses on the surface.
TILE_PER_LAYER = 5.0
#: Tile counts stay within the bakers' --tile range.
MAX_TILES = 4096


def median_edge_length(mesh) -> float:
    """The median length of the mesh's triangle edges, world units (0 for no triangles)."""
    faces = np.asarray(mesh.indices, np.int64)
    if len(faces) == 0:
        return 0.0
    p = np.asarray(mesh.world_positions, np.float64)
    edges = p[faces] - p[np.roll(faces, 1, axis=1)]
    return float(np.median(np.linalg.norm(edges, axis=-1)))


def layer_thickness(mesh) -> float:
    """A layer thickness following the mesh's detail: `LAYER_PER_EDGE` of its median edge
    (of its bounding-box diagonal when every edge has length 0)."""
    edge = median_edge_length(mesh)
    if edge > 0:
        return LAYER_PER_EDGE * edge
    lo, hi = (np.asarray(b, np.float64) for b in mesh.bounds)
    return LAYER_PER_EDGE * float(np.linalg.norm(hi - lo)) or 1.0


def uv_tiling(mesh, tile_length: float) -> tuple[int, int]:
    """(U, V) whole tile counts over the uvs such that one tile is about ``tile_length``
    world units long along u and along v (at least 1, at most `MAX_TILES`).

    Per triangle, the world length of one unit of u is |dp/du| of the affine map from uv to
    space; it is averaged over the triangles weighted by their uv area (the share of the
    texture they show). A mesh without uvs, or without a triangle of uv area, gets (1, 1).
    """
    if mesh.uvs is None or not tile_length > 0:
        return 1, 1
    faces = np.asarray(mesh.indices, np.int64)
    p = np.asarray(mesh.world_positions, np.float64)[faces]
    uv = np.asarray(mesh.uvs, np.float64)[faces]
    dp = np.stack([p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]], axis=-1)      # (F, 3, 2)
    duv = np.stack([uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0]], axis=-1)  # (F, 2, 2)
    det = duv[:, 0, 0] * duv[:, 1, 1] - duv[:, 0, 1] * duv[:, 1, 0]
    good = np.abs(det) > 1e-12 * max(float(np.abs(det).max(initial=0.0)), 1e-300)
    if not good.any():
        return 1, 1
    inverse = np.stack([np.stack([duv[good, 1, 1], -duv[good, 0, 1]], -1),
                        np.stack([-duv[good, 1, 0], duv[good, 0, 0]], -1)], -2)
    jacobian = dp[good] @ (inverse / det[good, None, None])              # dp/d(u, v)
    weight = np.abs(det[good])
    per_unit = (np.linalg.norm(jacobian, axis=1) * weight[:, None]).sum(0) / weight.sum()
    counts = np.clip(np.round(per_unit / tile_length), 1, MAX_TILES)
    return int(counts[0]), int(counts[1])
