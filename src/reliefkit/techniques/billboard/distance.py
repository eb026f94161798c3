"""The occupancy a box's stored maps imply and its distance texture (§3.4.1).

The distance texture is derived data: the bake computes it from the maps it stores, and the
.rk reader computes it again rather than trust a file's (a stored step longer than the true
distance makes the sphere march jump over surfaces).

* Occupancy: volumetric, the voxels whose colour alpha is >= 128; the shells, the cells of a
  covered texel's column that overlap its interval in w (the shell's displacement
  +- thickness / 2, within [0, 1]; the thick shell's two displacements) by more than the
  encoding's rounding.
* Distance: per voxel centre, the Euclidean distance to the nearest occupied voxel centre,
  measured in units of the smallest of the three voxel sides, rounded down (a stored step
  never exceeds the true one) and clamped at `MAX_DISTANCE` (all of it where nothing is
  occupied).
"""

from __future__ import annotations

import numpy as np

from .boxes import MAX_DISTANCE, BillboardBox

#: Displacements are stored as w * DISP_SCALE in uint16.
DISP_SCALE = 65535


def occupancy(variant: str, color: np.ndarray, displacement: np.ndarray | None, depth: int,
              thickness: float | None = None) -> np.ndarray:
    """(D, H, W) bool: the cells a box of ``variant`` with these maps occupies."""
    covered = color[..., 3] >= 128
    if variant == "volumetric":
        return covered
    if variant == "shell":
        w = displacement[..., 0] / DISP_SCALE
        interval = np.stack([np.clip(w - thickness / 2, 0, 1),
                             np.clip(w + thickness / 2, 0, 1)], axis=-1)
    else:
        interval = displacement / DISP_SCALE
    lo, hi = interval[..., 0], interval[..., 1]
    tol = 1.0 / DISP_SCALE
    k = np.arange(depth, dtype=np.float64)[:, None, None]
    return covered[None] & (k / depth < hi[None] - tol) & ((k + 1) / depth > lo[None] + tol)


def distance_texture(occupied: np.ndarray, box_to_world: np.ndarray) -> np.ndarray:
    """(D, H, W) uint8 distance from each voxel centre to the nearest occupied one (module)."""
    from scipy.ndimage import distance_transform_edt

    if not occupied.any():
        return np.full(occupied.shape, MAX_DISTANCE, np.uint8)
    sides = voxel_sides(box_to_world, occupied.shape)
    distance = distance_transform_edt(~occupied, sampling=sides / sides.min())
    return np.minimum(np.floor(distance + 1e-6), MAX_DISTANCE).astype(np.uint8)


def box_distance(box: BillboardBox, variant: str, thickness: float | None) -> np.ndarray:
    """The distance texture ``box``'s own maps imply."""
    cells = occupancy(variant, box.color, box.displacement, box.resolution[2], thickness)
    return distance_texture(cells, box.box_to_world)


def voxel_sides(box_to_world: np.ndarray, shape: tuple[int, int, int]) -> np.ndarray:
    """World lengths of a (D, H, W) grid's voxel sides, in array order (w, v, u)."""
    lengths = np.linalg.norm(np.asarray(box_to_world)[:3, :3], axis=0)
    d, h, w = shape
    return np.array([lengths[2] / d, lengths[1] / h, lengths[0] / w])
