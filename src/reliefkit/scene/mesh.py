"""`RenderMesh`: the triangle mesh every renderer and baker consumes, validated on creation.

Loading from files (`load_mesh`) lives in :mod:`reliefkit.scene.loader`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import MeshError


@dataclass(frozen=True, eq=False)
class RenderMesh:
    """An indexed triangle mesh in its file's own world coordinates.

    Attributes
    ----------
    positions : (V, 3) float32 world-space vertex positions.
    indices : (F, 3) uint32 triangle corners (counter-clockwise is the front face).
    normals : (V, 3) float32 unit vertex normals.
    colors : (V, 4) float32 linear RGBA base colour per vertex, in [0, 1].
    uvs : (V, 2) float32 texture coordinates (GL convention, v up) or None.
    texture : (h, w, 4) uint8 sRGB-encoded base-colour texture, row 0 at v = 0, or None.
    name : a label for pictures and messages.
    """

    positions: np.ndarray
    indices: np.ndarray
    normals: np.ndarray
    colors: np.ndarray
    uvs: np.ndarray | None = None
    texture: np.ndarray | None = None
    name: str = "mesh"
    extra: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "positions", _array(self.positions, np.float32, 3, "positions", self.name))
        set_(self, "indices", _indices(self.indices, len(self.positions), self.name))
        set_(self, "normals", _array(self.normals, np.float32, 3, "normals", self.name))
        set_(self, "colors", _array(self.colors, np.float32, 4, "colors", self.name))
        v = len(self.positions)
        for label, arr in (("normals", self.normals), ("colors", self.colors)):
            if len(arr) != v:
                raise MeshError(f"{self.name}: {label} has {len(arr)} rows, expected {v}")
        if self.uvs is not None:
            set_(self, "uvs", _array(self.uvs, np.float32, 2, "uvs", self.name))
            if len(self.uvs) != v:
                raise MeshError(f"{self.name}: uvs has {len(self.uvs)} rows, expected {v}")
        if self.texture is not None:
            tex = np.ascontiguousarray(self.texture)
            if tex.dtype != np.uint8 or tex.ndim != 3 or tex.shape[2] != 4 or tex.size == 0:
                raise MeshError(f"{self.name}: texture must be a non-empty (h, w, 4) uint8 array")
            if self.uvs is None:
                raise MeshError(f"{self.name}: a texture needs texture coordinates (uvs)")
            set_(self, "texture", tex)

    @property
    def bounds(self) -> np.ndarray:
        """(2, 3) array: minimum and maximum corner of the axis-aligned bounding box."""
        return np.stack([self.positions.min(axis=0), self.positions.max(axis=0)])

    @property
    def center(self) -> np.ndarray:
        """Centre of the bounding box."""
        return self.bounds.mean(axis=0)

    @property
    def radius(self) -> float:
        """Radius of the bounding sphere around `center` (never zero)."""
        r = float(np.linalg.norm(self.positions - self.center, axis=1).max())
        return r if r > 0 else 1.0

    @property
    def triangle_count(self) -> int:
        return len(self.indices)


def _array(a, dtype, cols: int, label: str, name: str) -> np.ndarray:
    try:
        arr = np.ascontiguousarray(a, dtype=dtype)
    except (TypeError, ValueError) as exc:
        raise MeshError(f"{name}: {label} is not a numeric array ({exc})") from None
    if arr.ndim != 2 or arr.shape[1] != cols:
        raise MeshError(f"{name}: {label} must have shape (N, {cols}), got {arr.shape}")
    if not np.isfinite(arr).all():
        bad = int((~np.isfinite(arr)).any(axis=1).sum())
        raise MeshError(f"{name}: {label} has {bad} rows with NaN or Inf values")
    return arr


def _indices(a, vertex_count: int, name: str) -> np.ndarray:
    arr = np.asarray(a)
    if arr.size == 0 or vertex_count == 0:
        raise MeshError(f"{name}: the mesh is empty (no triangles)")
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise MeshError(f"{name}: indices must have shape (F, 3), got {arr.shape}")
    if not np.issubdtype(arr.dtype, np.integer) and (
            not np.all(np.isfinite(arr)) or not np.all(arr == np.round(arr))):
        raise MeshError(f"{name}: indices must be integers")
    lo, hi = int(arr.min()), int(arr.max())
    if lo < 0:
        raise MeshError(f"{name}: a triangle index is negative ({lo})")
    if hi >= vertex_count:
        raise MeshError(
            f"{name}: a triangle index ({hi}) is out of range for {vertex_count} vertices"
        )
    return np.ascontiguousarray(arr, dtype=np.uint32)


def vertex_normals(positions: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """Area-weighted vertex normals; vertices on no triangle get +y."""
    p = np.asarray(positions, dtype=np.float64)
    tri = p[np.asarray(indices, dtype=np.int64)]
    face = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    idx = np.asarray(indices, dtype=np.int64).ravel()
    n = np.stack([np.bincount(idx, weights=np.repeat(face[:, c], 3), minlength=len(p))
                  for c in range(3)], axis=1)
    length = np.linalg.norm(n, axis=1, keepdims=True)
    out = np.where(length > 0, n / np.maximum(length, 1e-300), [0.0, 1.0, 0.0])
    return out.astype(np.float32)
