"""Homogeneous transforms of point arrays: the one place points meet 4x4 matrices."""

from __future__ import annotations

import numpy as np

MAX_COORDINATE = 1e18  # |coordinate| beyond this overflows float32 products on the GPU: refused


def homogeneous(points) -> np.ndarray:
    """(..., 3) points -> (..., 4) with w = 1 (float64)."""
    p = np.asarray(points, dtype=np.float64)
    return np.concatenate([p, np.ones(p.shape[:-1] + (1,))], axis=-1)


def transform_points(matrix, points) -> np.ndarray:
    """Apply a 4x4 (possibly projective) matrix to (..., 3) points, dividing by w."""
    hom = homogeneous(points) @ np.asarray(matrix, dtype=np.float64).T
    with np.errstate(divide="ignore", invalid="ignore"):
        return hom[..., :3] / hom[..., 3:4]


def translation(offset) -> np.ndarray:
    """4x4 matrix moving points by ``offset`` (3,)."""
    matrix = np.eye(4)
    matrix[:3, 3] = np.asarray(offset, dtype=np.float64)
    return matrix


def box_center(box_to_world) -> np.ndarray:
    """World point at the centre of a (possibly projective) box: box coordinates 0.5."""
    return transform_points(box_to_world, np.full(3, 0.5))


def invert_box(box_to_world) -> np.ndarray:
    """world_to_box of a box far from the world origin, as exact as near it.

    A plain inverse of a matrix holding a 1e8 translation (and a projective row) loses the
    box in rounding; inverting it relative to the box's centre does not.
    """
    centre = box_center(box_to_world)
    relative = translation(-centre) @ np.asarray(box_to_world, dtype=np.float64)
    return np.linalg.inv(relative) @ translation(-centre)


def unit_cube_corners() -> np.ndarray:
    """(8, 3) corners of [0, 1]^3, index = x + 2y + 4z."""
    return np.array([[i & 1, (i >> 1) & 1, (i >> 2) & 1] for i in range(8)], dtype=np.float64)
