"""Octahedral maps of view directions: the grid of frames an impostor bakes and the three
frames (and their barycentric weights) a view between them blends.

A direction d (unit, from the object towards the viewer; +y up) maps to a point of the
square [-1, 1]^2 (u along x, v along z). The full map (Praun and Hoppe's octahedral
parameterization) projects d onto the octahedron |x| + |y| + |z| = 1 and unfolds the lower
half over the corners: +y is the centre, -y the four corners. The hemi map keeps the upper
half only and turns its diamond by 45 degrees to fill the square: views from below are
clamped to the horizon. Frame (i, j) of an N x N grid sits at u = 2i / (N - 1) - 1,
v = 2j / (N - 1) - 1, so the square's border holds frames too (on the full map, opposite
border frames mirror each other, as the map folds there).

shaders/impostor.glsl holds the same functions in GLSL; tests hold the two to the same
frames and weights.
"""

from __future__ import annotations

import numpy as np

#: |d.y| above this picks -z as a frame's reference up vector (the poles).
POLE = 0.999


def _sign(x: np.ndarray) -> np.ndarray:
    """+1 or -1 (0 counts as positive: the fold needs a side for every point)."""
    return np.where(x >= 0.0, 1.0, -1.0)


def encode(direction, hemi: bool) -> np.ndarray:
    """(..., 3) directions -> (..., 2) points of the map in [-1, 1]^2."""
    d = np.asarray(direction, dtype=np.float64)
    if hemi:
        d = np.concatenate([d[..., :1], np.maximum(d[..., 1:2], 0.0), d[..., 2:]], axis=-1)
    d = d / np.maximum(np.sum(np.abs(d), axis=-1, keepdims=True), 1e-12)
    x, y, z = d[..., 0], d[..., 1], d[..., 2]
    if hemi:
        return np.stack([x + z, z - x], axis=-1)
    folded_x = (1.0 - np.abs(z)) * _sign(x)
    folded_z = (1.0 - np.abs(x)) * _sign(z)
    return np.stack([np.where(y < 0.0, folded_x, x), np.where(y < 0.0, folded_z, z)], axis=-1)


def decode(point, hemi: bool) -> np.ndarray:
    """(..., 2) points of the map -> (..., 3) unit directions (`encode`'s inverse)."""
    p = np.asarray(point, dtype=np.float64)
    u, v = p[..., 0], p[..., 1]
    if hemi:
        x, z = 0.5 * (u - v), 0.5 * (u + v)
        d = np.stack([x, 1.0 - np.abs(x) - np.abs(z), z], axis=-1)
    else:
        y = 1.0 - np.abs(u) - np.abs(v)
        x = np.where(y < 0.0, (1.0 - np.abs(v)) * _sign(u), u)
        z = np.where(y < 0.0, (1.0 - np.abs(u)) * _sign(v), v)
        d = np.stack([x, y, z], axis=-1)
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def frame_point(i, j, grid: int) -> np.ndarray:
    """The map point of frame (i, j) of a ``grid`` x ``grid`` grid."""
    return np.stack([2.0 * np.asarray(i, np.float64) / (grid - 1) - 1.0,
                     2.0 * np.asarray(j, np.float64) / (grid - 1) - 1.0], axis=-1)


def frame_directions(grid: int, hemi: bool) -> np.ndarray:
    """(grid, grid, 3) directions of the frames, indexed [j, i] (row j of the atlas)."""
    i, j = np.meshgrid(np.arange(grid), np.arange(grid))
    return decode(frame_point(i, j, grid), hemi)


def frame_basis(direction) -> tuple[np.ndarray, np.ndarray]:
    """The (right, up) axes of the orthographic frame seen along -``direction``: right =
    normalize(ref x d), up = d x right, with ref = +y (-z at the poles)."""
    d = np.asarray(direction, dtype=np.float64)
    ref = np.where(np.abs(d[..., 1:2]) > POLE, [0.0, 0.0, -1.0], [0.0, 1.0, 0.0])
    right = np.cross(ref, d)
    right /= np.linalg.norm(right, axis=-1, keepdims=True)
    return right, np.cross(d, right)


def blend_frames(direction, grid: int, hemi: bool) -> tuple[np.ndarray, np.ndarray]:
    """The three frames around ``direction`` on the map and their barycentric weights:
    ((..., 3, 2) int (i, j), (..., 3) float summing to 1). A direction exactly on a frame
    gives that frame weight 1.

    The map point's grid cell is split along its (1, 0)-(0, 1) diagonal; the point's
    triangle gives the three frames.
    """
    g = (encode(direction, hemi) + 1.0) * 0.5 * (grid - 1)
    cell = np.clip(np.floor(g), 0, grid - 2)
    f = np.clip(g - cell, 0.0, 1.0)
    fx, fy = f[..., 0], f[..., 1]
    lower = (fx + fy <= 1.0)[..., None, None]
    offsets = np.where(lower, np.array([[0, 0], [1, 0], [0, 1]]),
                       np.array([[1, 1], [0, 1], [1, 0]]))
    weights = np.where(lower[..., 0], np.stack([1.0 - fx - fy, fx, fy], axis=-1),
                       np.stack([fx + fy - 1.0, 1.0 - fx, 1.0 - fy], axis=-1))
    return (cell[..., None, :] + offsets).astype(np.int64), weights
