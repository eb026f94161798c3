"""Vertex normals: the ones the file stored, completed with computed ones where unusable."""

from __future__ import annotations

import numpy as np
import trimesh

_BLOCK = 1 << 16  # rows per block where a whole-mesh float64 temporary would be large


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


def vertex_normals(positions: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """`scene.mesh.vertex_normals`, the same values, in a fraction of its memory.

    That one holds float64 copies of every triangle's corners and several (V, 3) float64
    temporaries; here each face-normal coordinate is summed on its own (in the same order,
    so the sums are identical) and the normalization runs in blocks of vertices.
    """
    corners = np.asarray(faces, dtype=np.int64).ravel()
    summed = np.empty((len(positions), 3))
    for axis in range(3):
        face = _face_normal_coordinate(positions, faces, axis)
        summed[:, axis] = np.bincount(corners, weights=np.repeat(face, 3),
                                      minlength=len(positions))
        del face
    unit = np.empty((len(positions), 3), np.float32)
    for start in range(0, len(positions), _BLOCK):
        block = summed[start:start + _BLOCK]
        length = np.linalg.norm(block, axis=1, keepdims=True)
        unit[start:start + _BLOCK] = np.where(length > 0, block / np.maximum(length, 1e-300),
                                              [0.0, 1.0, 0.0])
    return unit


def _face_normal_coordinate(positions: np.ndarray, faces: np.ndarray, axis: int) -> np.ndarray:
    """Coordinate `axis` of each triangle's (b - a) x (c - a), as `np.cross` computes it."""
    i, j = (axis + 1) % 3, (axis + 2) % 3
    out = np.empty(len(faces))
    for start in range(0, len(faces), _BLOCK):
        a, b, c = (np.asarray(positions[faces[start:start + _BLOCK, k]], dtype=np.float64)
                   for k in range(3))
        u, v = b - a, c - a
        out[start:start + _BLOCK] = u[:, i] * v[:, j] - u[:, j] * v[:, i]
    return out
