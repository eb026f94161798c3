"""Vertex normals: the ones the file stored, completed with computed ones where unusable."""

from __future__ import annotations

import numpy as np
import trimesh

from ..mesh import vertex_normals


def file_normals(geometry: trimesh.Trimesh) -> np.ndarray:
    """The vertex normals the file stored, NaN rows for none.

    trimesh computes normals lazily; normals read from a file are the ones already in the
    mesh's cache right after loading (trimesh offers no public way to ask).
    """
    shape = (len(geometry.vertices), 3)
    stored = geometry._cache["vertex_normals"]  # noqa: SLF001 - see docstring
    if stored is None or np.shape(stored) != shape:
        return np.full(shape, np.nan)
    return np.array(stored, dtype=np.float64)


def usable_normals(from_file: np.ndarray, positions: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Unit file normals where finite and non-zero, normals computed from faces elsewhere."""
    with np.errstate(all="ignore"):
        length = np.linalg.norm(from_file, axis=1, keepdims=True)
        unit = from_file / length
    usable = np.isfinite(length) & (length > 1e-12) & np.isfinite(unit).all(axis=1, keepdims=True)
    if usable.all():
        return unit.astype(np.float32)
    return np.where(usable, unit, vertex_normals(positions, faces)).astype(np.float32)
