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


def unit_cube_corners() -> np.ndarray:
    """(8, 3) corners of [0, 1]^3, index = x + 2y + 4z."""
    return np.array([[i & 1, (i >> 1) & 1, (i >> 2) & 1] for i in range(8)], dtype=np.float64)
