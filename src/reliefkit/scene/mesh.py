"""`RenderMesh` and its `Material`s: what every renderer and baker consumes, validated.

Loading from files (`load_mesh`) lives in :mod:`reliefkit.io.meshes`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import MeshError

#: Most materials one mesh may have (per-triangle material indices are uint16).
MAX_MATERIALS = 1 << 16

#: A mesh whose bounding-box centre lies farther from the world origin than this many times
#: its extent keeps its positions relative to that centre (`RenderMesh.origin`): float32
#: resolves about 2^-24 of a coordinate's magnitude, so beyond this ratio it would blur the
#: mesh's own detail (georeferenced scans sit 1e6..1e8 units away).
FAR_RATIO = 256.0

#: How a material's alpha (vertex colour x factor x texture) is used, as glTF's alphaMode.
ALPHA_MODES = ("OPAQUE", "MASK", "BLEND")


@dataclass(frozen=True, eq=False)
class Material:
    """One surface's base colour: ``color`` times ``texture`` (times the vertex colours).

    Materials compare equal by value, so a loader can merge the same material met twice.

    Attributes
    ----------
    name : the file's material name ("" when it has none).
    color : (4,) float32 linear RGBA factor, in [0, 1].
    texture : (h, w, 4) uint8 sRGB-encoded base-colour image, row 0 at v = 0, or None.
    uv_transform : (3, 3) float32 affine map of (u, v, 1) applied before the lookup (glTF's
        KHR_texture_transform, in this mesh's UV convention), or None for the identity.
    alpha_mode : "OPAQUE" (the default, as in glTF: alpha is ignored and drawn as 1), "MASK"
        (fragments whose alpha is below `alpha_cutoff` are discarded, the rest drawn with
        alpha 1) or "BLEND" (alpha kept as coverage/opacity).
    alpha_cutoff : float in [0, 1], the MASK threshold (glTF's alphaCutoff, default 0.5);
        kept but unused in the other modes.
    double_sided : glTF's doubleSided: whether viewers draw the back faces too. reliefkit's
        renderer draws both sides of every triangle whatever it says; it is kept so a glTF
        export (a billboard's quads) says what a viewer must do.
    """

    name: str = ""
    color: np.ndarray = (1.0, 1.0, 1.0, 1.0)
    texture: np.ndarray | None = None
    uv_transform: np.ndarray | None = None
    alpha_mode: str = "OPAQUE"
    alpha_cutoff: float = 0.5
    double_sided: bool = False

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        where = f"material '{self.name}'"
        if not isinstance(self.name, str):
            raise MeshError(f"a material name must be a string, got {type(self.name).__name__}")
        color = _array(np.atleast_2d(self.color), np.float32, 4, "color", where)
        if len(color) != 1 or color.min() < 0 or color.max() > 1:
            raise MeshError(f"{where}: color must be 4 values in [0, 1], got {color.tolist()}")
        set_(self, "color", color[0])
        if self.texture is not None:
            tex = np.ascontiguousarray(self.texture)
            if tex.dtype != np.uint8 or tex.ndim != 3 or tex.shape[2] != 4 or tex.size == 0:
                raise MeshError(f"{where}: texture must be a non-empty (h, w, 4) uint8 array")
            set_(self, "texture", tex)
        if self.uv_transform is not None:
            matrix = _array(self.uv_transform, np.float32, 3, "uv_transform", where)
            if matrix.shape != (3, 3) or not np.array_equal(matrix[2], [0, 0, 1]):
                raise MeshError(f"{where}: uv_transform must be a 3x3 affine matrix "
                                "(last row 0, 0, 1)")
            set_(self, "uv_transform", None if np.array_equal(matrix, np.eye(3)) else matrix)
        if not isinstance(self.alpha_mode, str) or self.alpha_mode not in ALPHA_MODES:
            raise MeshError(f"{where}: alpha_mode must be one of {', '.join(ALPHA_MODES)}, "
                            f"got {self.alpha_mode!r}")
        try:
            cutoff = float(self.alpha_cutoff)
        except (TypeError, ValueError):
            cutoff = float("nan")
        if isinstance(self.alpha_cutoff, bool) or not 0.0 <= cutoff <= 1.0:
            raise MeshError(f"{where}: alpha_cutoff must be a number in [0, 1], "
                            f"got {self.alpha_cutoff!r}")
        set_(self, "alpha_cutoff", float(np.float32(cutoff)))  # as stored in .rk files
        if not isinstance(self.double_sided, (bool, np.bool_)):
            raise MeshError(f"{where}: double_sided must be True or False, "
                            f"got {self.double_sided!r}")
        set_(self, "double_sided", bool(self.double_sided))

    def __eq__(self, other) -> bool:
        if not isinstance(other, Material):
            return NotImplemented
        return (self.name == other.name and np.array_equal(self.color, other.color)
                and _same_or_none(self.texture, other.texture)
                and _same_or_none(self.uv_transform, other.uv_transform)
                and self.alpha_mode == other.alpha_mode
                and self.alpha_cutoff == other.alpha_cutoff
                and self.double_sided == other.double_sided)

    __hash__ = None


@dataclass(frozen=True, eq=False, init=False)
class RenderMesh:
    """An indexed triangle mesh in its file's own world coordinates, with its materials.

    A triangle's base colour is its vertex colour times its material's colour and texture.
    Every material keeps its own texture; the renderer draws each material's triangles with
    it (`material_groups`).

    Attributes
    ----------
    positions : (V, 3) float32 vertex positions relative to `origin`.
    origin : (3,) float64 world point the positions are relative to: the zero vector unless
        the mesh lies far from the world origin (`FAR_RATIO`), then its bounding-box centre;
        `world_positions`, `bounds` and `center` are in the file's own world coordinates.
    indices : (F, 3) uint32 triangle corners (counter-clockwise is the front face).
    normals : (V, 3) float32 unit vertex normals.
    colors : (V, 4) float32 linear RGBA base colour per vertex, in [0, 1]; one colour for all
        vertices may be a read-only broadcast view (stride 0), which takes no memory per
        vertex (loaders give uncoloured meshes so).
    uvs : (V, 2) float32 texture coordinates (GL convention, v up) or None; shared by all
        materials, required when one has a texture.
    materials : tuple of at least one `Material`.
    material : (F,) uint16 index into `materials` per triangle.
    name : a label for pictures and messages.
    extra : free-form provenance (source path, asset parts), never stored in .rk files.

    The constructor also takes the single-texture form of older callers:
    ``RenderMesh(positions, indices, normals, colors, uvs, texture)`` is one material with
    that texture (and a white colour); ``materials=`` with ``material=`` gives several.
    """

    positions: np.ndarray
    indices: np.ndarray
    normals: np.ndarray
    colors: np.ndarray
    uvs: np.ndarray | None
    materials: tuple[Material, ...]
    material: np.ndarray
    name: str
    extra: dict

    def __init__(self, positions, indices, normals, colors, uvs=None, texture=None,
                 name: str = "mesh", extra: dict | None = None, *, materials=None,
                 material=None, origin=None) -> None:
        set_ = object.__setattr__
        set_(self, "name", name)
        set_(self, "extra", {} if extra is None else extra)
        relative, origin = _relative_positions(positions, origin, name)
        set_(self, "positions", relative)
        set_(self, "origin", origin)
        set_(self, "indices", _indices(indices, len(self.positions), name))
        set_(self, "normals", _array(normals, np.float32, 3, "normals", name))
        set_(self, "colors", _colors(colors, name))
        v = len(self.positions)
        for label, arr in (("normals", self.normals), ("colors", self.colors)):
            if len(arr) != v:
                raise MeshError(f"{name}: {label} has {len(arr)} rows, expected {v}")
        if uvs is not None:
            uvs = _array(uvs, np.float32, 2, "uvs", name)
            if len(uvs) != v:
                raise MeshError(f"{name}: uvs has {len(uvs)} rows, expected {v}")
        set_(self, "uvs", uvs)
        set_(self, "materials", _materials(materials, texture, name))
        set_(self, "material", _material_indices(material, self, name))
        if self.textured and uvs is None:
            raise MeshError(f"{name}: a texture needs texture coordinates (uvs)")

    @property
    def texture(self) -> np.ndarray | None:
        """The texture of a one-material mesh (None with several materials, or none)."""
        return self.materials[0].texture if len(self.materials) == 1 else None

    @property
    def textured(self) -> bool:
        """Whether any material has a real image."""
        return any(m.texture is not None for m in self.materials)

    def material_groups(self) -> list[tuple[Material, np.ndarray]]:
        """(material, (G, 3) uint32 corners of its triangles) for each material that has some.

        The triangles of one material keep their order; one draw per group renders the mesh.
        """
        if len(self.materials) == 1:
            return [(self.materials[0], self.indices)]
        order = np.argsort(self.material, kind="stable")
        counts = np.bincount(self.material, minlength=len(self.materials))
        starts = np.concatenate([[0], np.cumsum(counts)])
        return [(m, self.indices[order[starts[k]:starts[k + 1]]])
                for k, m in enumerate(self.materials) if counts[k]]

    @property
    def world_positions(self) -> np.ndarray:
        """(V, 3) float64 vertex positions in world coordinates (`positions` + `origin`)."""
        return self.positions.astype(np.float64) + self.origin

    @property
    def bounds(self) -> np.ndarray:
        """(2, 3) float64 minimum and maximum world corner of the axis-aligned bounding box."""
        local = np.stack([self.positions.min(axis=0), self.positions.max(axis=0)])
        return local.astype(np.float64) + self.origin

    @property
    def center(self) -> np.ndarray:
        """Centre of the bounding box (world)."""
        return self.bounds.mean(axis=0)

    @property
    def radius(self) -> float:
        """Radius of the bounding sphere around `center` (never zero)."""
        local_center = self.center - self.origin
        r = float(np.linalg.norm(self.positions - local_center, axis=1).max())
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


def _relative_positions(positions, origin, name: str) -> tuple[np.ndarray, np.ndarray]:
    """float32 positions relative to a float64 origin: the given one, or the zero vector, or
    (for a mesh far from the world origin, see `FAR_RATIO`) its bounding-box centre."""
    dtype = getattr(positions, "dtype", None)
    wide = dtype if dtype in (np.float32, np.float64) else np.float64  # no float32 round trip
    points = _array(positions, wide, 3, "positions", name)
    if origin is not None:
        origin = np.asarray(origin, dtype=np.float64)
        if origin.shape != (3,) or not np.isfinite(origin).all():
            raise MeshError(f"{name}: origin must be 3 finite numbers")
        return np.ascontiguousarray(points, dtype=np.float32), origin
    origin = _far_origin(points)
    if not origin.any():
        return np.ascontiguousarray(points, dtype=np.float32), origin
    relative = np.empty(points.shape, np.float32)  # in blocks: no second float64 copy
    for start in range(0, len(points), _BLOCK):
        block = slice(start, start + _BLOCK)
        relative[block] = points[block] - origin
    return relative, origin


def _colors(colors, name: str) -> np.ndarray:
    """(V, 4) float32 colours; a broadcast of one row stays a view (checked once)."""
    if isinstance(colors, np.ndarray) and colors.ndim == 2 and colors.shape[1] == 4 \
            and colors.strides[0] == 0 and len(colors):
        row = _array(colors[:1], np.float32, 4, "colors", name)
        return np.broadcast_to(row[0], colors.shape)
    return _array(colors, np.float32, 4, "colors", name)


_BLOCK = 1 << 16  # rows per block of whole-mesh arithmetic


def _far_origin(points: np.ndarray) -> np.ndarray:
    """The bounding-box centre of points far from the world origin, else the zero vector."""
    if not len(points):
        return np.zeros(3)
    low = points.min(axis=0).astype(np.float64)
    high = points.max(axis=0).astype(np.float64)
    centre = (low + high) / 2
    if np.abs(centre).max() > FAR_RATIO * float((high - low).max()):
        return centre
    return np.zeros(3)


def _materials(materials, texture, name: str) -> tuple[Material, ...]:
    if materials is None:
        return (Material(texture=texture),) if texture is not None else (Material(),)
    if texture is not None:
        raise MeshError(f"{name}: give texture= (one material) or materials=, not both")
    materials = tuple(materials)
    if not materials or not all(isinstance(m, Material) for m in materials):
        raise MeshError(f"{name}: materials must be a non-empty sequence of Material")
    if len(materials) > MAX_MATERIALS:
        raise MeshError(f"{name}: {len(materials)} materials, more than {MAX_MATERIALS}")
    return materials


def _material_indices(material, mesh: RenderMesh, name: str) -> np.ndarray:
    """Per-triangle material indices, checked against the materials (all 0 for one)."""
    count, triangles = len(mesh.materials), len(mesh.indices)
    if material is None:
        if count > 1:
            raise MeshError(f"{name}: {count} materials need per-triangle material indices")
        return np.zeros(triangles, np.uint16)
    arr = np.asarray(material)
    if arr.shape != (triangles,) or not np.issubdtype(arr.dtype, np.integer):
        raise MeshError(f"{name}: material must be {triangles} integers (one per triangle), "
                        f"got {arr.dtype} {arr.shape}")
    if arr.size and (arr.min() < 0 or arr.max() >= count):
        bad = int(arr.min() if arr.min() < 0 else arr.max())
        raise MeshError(f"{name}: material index {bad} out of range for {count} materials")
    return np.ascontiguousarray(arr, dtype=np.uint16)


def _same_or_none(a: np.ndarray | None, b: np.ndarray | None) -> bool:
    if a is None or b is None:
        return a is b
    return a is b or (a.shape == b.shape and np.array_equal(a, b))


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
    """Area-weighted unit vertex normals, float32; vertices on no triangle get +y.

    Large meshes are why it works one coordinate and one block at a time: it holds no float64
    copy of every triangle's corners, only one (F,) and one (V, 3) float64 array.
    """
    positions, faces = np.asarray(positions), np.asarray(indices, dtype=np.int64)
    count = len(positions)
    summed = np.zeros((count, 3))
    for axis in range(3):
        face = _face_normal_coordinate(positions, faces, axis)
        for corner in range(3):
            summed[:, axis] += np.bincount(faces[:, corner], weights=face, minlength=count)
        del face
    unit = np.empty((count, 3), np.float32)
    for start in range(0, count, _BLOCK):
        block = summed[start:start + _BLOCK]
        length = np.linalg.norm(block, axis=1, keepdims=True)
        unit[start:start + _BLOCK] = np.where(length > 0, block / np.maximum(length, 1e-300),
                                              [0.0, 1.0, 0.0])
    return unit


def _face_normal_coordinate(positions: np.ndarray, faces: np.ndarray, axis: int) -> np.ndarray:
    """Coordinate `axis` of each triangle's (b - a) x (c - a), in float64."""
    i, j = (axis + 1) % 3, (axis + 2) % 3
    out = np.empty(len(faces))
    for start in range(0, len(faces), _BLOCK):
        a, b, c = (positions[faces[start:start + _BLOCK, k]].astype(np.float64)
                   for k in range(3))
        u, v = b - a, c - a
        out[start:start + _BLOCK] = u[:, i] * v[:, j] - u[:, j] * v[:, i]
    return out
