"""Flattening a trimesh scene into `Part`s: every instance of every triangle geometry, placed.

Scene-graph transforms are applied in the file's own world coordinates (never rescaled or
recentred). Coordinates are checked against `MAX_COORDINATE` in float64, before anything
casts them to float32 (where 3e38 and more overflow).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
import trimesh

from ...core.transforms import MAX_COORDINATE
from ...scene.mesh import Material
from .badfile import BadFile, check_range
from .materials import SurfaceReader, decode_colors, is_face_colored
from .normals import file_normals

#: The largest coordinate magnitude the loader accepts, in the file's units, before and after
#: the scene-graph transforms. Far beyond any real mesh, yet small enough that the squared
#: distances the renderer computes in float32 (limit 3.4e38) never overflow.

# A triangle is visible when its doubled area exceeds (_VISIBLE * extent)**2, the extent being
# the diagonal of the whole mesh's bounds: thinner than float32 resolves at that scale, it
# draws nothing.
_VISIBLE = 2.0**-23

_BLOCK = 1 << 16  # triangles per block where a whole-mesh temporary would be large


@dataclass(frozen=True)
class Part:
    """One triangle geometry as it will enter the merged mesh."""

    positions: np.ndarray  # (V, 3) float64
    faces: np.ndarray  # (F, 3) int64, indices into this part
    normals: np.ndarray | None  # (V, 3) float64 from the file (NaN rows: none); None: no row
    colors: np.ndarray  # (V, 4) float64 linear RGBA vertex colours (a broadcast view if uniform)
    uvs: np.ndarray | None = None  # (V, 2) float64
    material: Material = field(default_factory=Material)


def scene_parts(scene: trimesh.Scene, srgb: bool,
                uv_transforms: dict[str, np.ndarray] | None = None) -> list[Part]:
    """Every instance of every triangle geometry, placed in world space.

    ``uv_transforms`` gives the texture transform of geometries (by name) whose material has
    one that trimesh does not read.
    """
    local: dict[str, Part | None] = {}
    parts = []
    several = len(scene.geometry) > 1
    surfaces = SurfaceReader(srgb)
    for node in scene.graph.nodes_geometry:
        with np.errstate(all="ignore"):  # trimesh multiplies the matrices lazily, here
            matrix, geometry_name = scene.graph[node]
        if geometry_name not in local:
            geometry = scene.geometry[geometry_name]
            where = f" in mesh '{geometry_name}'" if several else ""
            part = _local_part(geometry, surfaces, where)
            transform = (uv_transforms or {}).get(geometry_name)
            if part is not None and transform is not None:
                part = replace(part, material=replace(part.material, uv_transform=transform))
            local[geometry_name] = part
        part = local[geometry_name]
        if part is not None:
            parts.append(_placed(part, np.asarray(matrix, dtype=np.float64)))
    return parts


def _local_part(geometry, surfaces: SurfaceReader, where: str) -> Part | None:
    """A trimesh geometry as a `Part`; None for points, lines and meshes without faces."""
    if not isinstance(geometry, trimesh.Trimesh) or len(geometry.faces) == 0:
        return None
    positions = np.asarray(geometry.vertices, dtype=np.float64)
    faces = np.asarray(geometry.faces, dtype=np.int64)
    check_range(faces, len(positions), where)
    bad = int((~np.isfinite(positions)).any(axis=1).sum())
    if bad:
        raise BadFile(f"{_vertices_have(bad)} NaN or Inf coordinates{where}")
    _check_magnitude(positions, where)
    surface = surfaces.surface(geometry.visual, len(positions))
    part = Part(positions, faces, file_normals(geometry), *surface)
    if is_face_colored(geometry.visual):
        face_colors = decode_colors(geometry.visual.face_colors, surfaces.srgb)
        part = _unshared(part, np.repeat(face_colors, 3, axis=0))
    return part


def _check_magnitude(positions: np.ndarray, where: str) -> None:
    """Refuse coordinates beyond `MAX_COORDINATE` (finite ones; NaN/Inf are refused before)."""
    if positions.size == 0:
        return
    big = max(float(positions.max()), -float(positions.min()))  # no (V, 3) temporary
    if big > MAX_COORDINATE:
        count = int((np.abs(positions) > MAX_COORDINATE).any(axis=1).sum())
        raise BadFile(
            f"{_vertices_have(count)} coordinates beyond {MAX_COORDINATE:g} "
            f"(largest {big:.3g}){where}, more than reliefkit can render; is it corrupt, or "
            "in the wrong units?")


def check_visible(parts: list[Part]) -> None:
    """Refuse a mesh none of whose triangles has a visible area.

    Zero-area faces (collinear or coincident corners, a node scaled to 0) and slivers thinner
    than float32 can resolve at the mesh's size draw nothing; a mesh made only of those
    would render an empty picture. Meshes with at least one visible triangle are kept as
    they are, zero-area faces included.
    """
    with np.errstate(all="ignore"):
        low = np.min([p.positions.min(axis=0) for p in parts], axis=0)
        high = np.max([p.positions.max(axis=0) for p in parts], axis=0)
        threshold = (_VISIBLE * float(np.linalg.norm(high - low))) ** 2
        for part in parts:
            for start in range(0, len(part.faces), _BLOCK):  # a few MB of temporaries each
                a, b, c = (part.positions[part.faces[start:start + _BLOCK, k]] for k in range(3))
                doubled = np.linalg.norm(np.cross(b - a, c - a), axis=1)
                if (doubled > threshold).any():
                    return
    raise BadFile(
        "has no triangle with a visible area (every face has zero area: collinear or "
        "coincident corners, or a scale of 0); nothing visible would be drawn")


def _vertices_have(count: int) -> str:
    return "1 vertex has" if count == 1 else f"{count} vertices have"


def _unshared(part: Part, corner_colors: np.ndarray) -> Part:
    """The same triangles with three vertices of their own each, coloured per corner (for
    per-face colours)."""
    corners = part.faces.reshape(-1)
    return Part(
        positions=part.positions[corners],
        faces=np.arange(len(corners), dtype=np.int64).reshape(-1, 3),
        normals=None if part.normals is None else part.normals[corners],
        colors=corner_colors,
        uvs=None if part.uvs is None else part.uvs[corners],
        material=part.material,
    )


def _placed(part: Part, matrix: np.ndarray) -> Part:
    """`part` moved by a 4x4 scene-graph matrix; a mirroring matrix reverses the winding."""
    if np.array_equal(matrix, np.eye(4)):
        return part
    if not np.isfinite(matrix).all():
        raise BadFile("has a scene-graph transform with NaN or Inf values")
    linear = matrix[:3, :3]
    det = np.linalg.det(linear)
    with np.errstate(all="ignore"):
        positions = part.positions @ linear.T + matrix[:3, 3]
        normals = (None if part.normals is None
                   else part.normals @ (np.sign(det) * _cofactor(linear)).T)
    bad = int((~np.isfinite(positions)).any(axis=1).sum())
    if bad:
        raise BadFile(f"{_vertices_have(bad)} NaN or Inf coordinates after the scene transforms")
    _check_magnitude(positions, " after the scene transforms")
    faces = part.faces[:, ::-1] if det < 0 else part.faces
    return replace(part, positions=positions, faces=np.ascontiguousarray(faces), normals=normals)


def _cofactor(linear: np.ndarray) -> np.ndarray:
    """det * inverse-transpose of a 3x3 matrix, defined for singular matrices too.

    It maps a triangle's normal to the normal of the transformed triangle (times sign(det), to
    the side the transformed winding faces). Its columns are the cross products of the
    matrix's columns: column i is linear[:, i+1] x linear[:, i+2].
    """
    return np.cross(linear[:, [1, 2, 0]].T, linear[:, [2, 0, 1]].T).T
