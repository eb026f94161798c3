"""Vertex normals: the ones the file stored, completed with computed ones where unusable."""

from __future__ import annotations

import numpy as np
import trimesh

from ...scene.mesh import vertex_normals


def file_normals(geometry: trimesh.Trimesh) -> np.ndarray | None:
    """The vertex normals the file stored, or None when it stored none.

    trimesh computes normals lazily; normals read from a file are the ones already in the
    mesh's cache right after loading (trimesh offers no public way to ask).
    """
    shape = (len(geometry.vertices), 3)
    # the cache's own dict: indexing the cache first hashes the whole mesh (a transient copy
    # of its vertices), and nothing changed them since loading (process=False)
    stored = geometry._cache.cache.get("vertex_normals")  # noqa: SLF001 - see docstring
    if stored is None or np.shape(stored) != shape:
        return None
    return np.array(stored, dtype=np.float64)


def usable_normals(from_file: np.ndarray | None, positions: np.ndarray,
                   faces: np.ndarray) -> np.ndarray:
    """Unit file normals where finite and non-zero, normals computed from faces elsewhere
    (everywhere for None)."""
    if from_file is None:
        return vertex_normals(positions, faces)
    with np.errstate(all="ignore"):
        length = np.linalg.norm(from_file, axis=1, keepdims=True)
        unit = from_file / length
    usable = np.isfinite(length) & (length > 1e-12) & np.isfinite(unit).all(axis=1, keepdims=True)
    if usable.all():
        return unit.astype(np.float32)
    return np.where(usable, unit, vertex_normals(positions, faces)).astype(np.float32)
