"""The shared builders of the assets: `MeshBuilder`, `Geometry` and primitive solids.

Flat-shaded primitives (boxes, hulls, prisms, slabs) have their own vertices per face so
their normals stay crisp; a lathe is smooth around its axis.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ...errors import UsageError
from ..mesh import RenderMesh, vertex_normals


class Geometry(NamedTuple):
    """Positions (V, 3), triangles (F, 3) and unit normals (V, 3) of one part."""

    positions: np.ndarray
    indices: np.ndarray
    normals: np.ndarray


class MeshBuilder:
    """Collects coloured parts and concatenates them into one `RenderMesh`."""

    def __init__(self) -> None:
        self._chunks: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = []
        self._parts: list[dict] = []
        self._vertices = 0
        self._triangles = 0

    def add(self, name: str, geometry: Geometry, color, closed: bool = True) -> None:
        """Append a part.

        Parameters
        ----------
        name : str
            Part label recorded in ``extra["parts"]``.
        geometry : Geometry
            The part's positions, triangles and normals.
        color : array_like
            Linear RGB or RGBA, one colour for the part or one per vertex.
        closed : bool
            Whether the part bounds a solid (outward-facing, positive signed volume).
        """
        positions, indices, normals = geometry
        n = len(positions)
        rgba = np.asarray(color, dtype=np.float64)
        if rgba.shape[-1] == 3:
            rgba = np.concatenate([rgba, np.ones(rgba.shape[:-1] + (1,))], axis=-1)
        rgba = np.broadcast_to(rgba, (n, 4))
        self._chunks.append((positions, indices + self._vertices, normals, rgba))
        stop = self._triangles + len(indices)
        self._parts.append({"name": name, "triangles": (self._triangles, stop), "closed": closed})
        self._vertices += n
        self._triangles = stop

    def build(self, name: str) -> RenderMesh:
        """Concatenate every part into a validated `RenderMesh` named `name`."""
        if not self._chunks:
            raise UsageError(f"{name}: no parts to build a mesh from")
        columns = zip(*self._chunks, strict=True)
        positions, indices, normals, colors = (np.concatenate(c) for c in columns)
        return RenderMesh(
            positions=positions.astype(np.float32),
            indices=indices.astype(np.uint32),
            normals=_unit_normals(normals),
            colors=np.clip(colors, 0.0, 1.0).astype(np.float32),
            name=name,
            extra={"parts": self._parts},
        )


def normalize(v) -> np.ndarray:
    """Vectors along the last axis of `v` scaled to unit length (zero vectors stay zero)."""
    v = np.asarray(v, dtype=np.float64)
    length = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.where(length > 1e-12, length, np.inf)


def _unit_normals(normals: np.ndarray) -> np.ndarray:
    """(V, 3) float32 unit normals; a degenerate (zero) normal becomes +y."""
    unit = normalize(normals)
    unit[np.linalg.norm(unit, axis=1) < 0.5] = (0.0, 1.0, 0.0)
    return unit.astype(np.float32)


def quads_to_triangles(quads: np.ndarray) -> np.ndarray:
    """Split quads (Q, 4), corners counter-clockwise seen from the front, into triangles."""
    quads = np.asarray(quads)
    return np.concatenate([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])


def perpendicular_frame(axis: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit vectors ``e1, e2`` perpendicular to unit `axis` with ``cross(e1, e2) == axis``."""
    helper = np.array([1.0, 0.0, 0.0]) if abs(axis[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = normalize(np.cross(axis, helper))
    return e1, np.cross(axis, e1)


def box(center, half_size, axes=None) -> Geometry:
    """Flat-shaded box (24 vertices, 12 triangles).

    Parameters
    ----------
    center : array_like, (3,)
        Box centre.
    half_size : array_like, (3,)
        Half extents along the box's own axes.
    axes : array_like, (3, 3), optional
        Rotation whose columns are the box's axes in world space (default: identity).
    """
    center = np.asarray(center, dtype=np.float64)
    half = np.asarray(half_size, dtype=np.float64)
    axes = np.eye(3) if axes is None else np.asarray(axes, dtype=np.float64)
    square = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], dtype=np.float64)
    positions, normals = [], []
    for a in range(3):
        b, c = (a + 1) % 3, (a + 2) % 3  # cross(axes[:, b], axes[:, c]) == axes[:, a]
        for sign in (1.0, -1.0):
            corners = square if sign > 0 else square[::-1]
            face = (
                center
                + sign * half[a] * axes[:, a]
                + corners[:, :1] * half[b] * axes[:, b]
                + corners[:, 1:] * half[c] * axes[:, c]
            )
            positions.append(face)
            normals.append(np.tile(sign * axes[:, a], (4, 1)))
    quads = np.arange(24).reshape(6, 4)
    return Geometry(np.concatenate(positions), quads_to_triangles(quads), np.concatenate(normals))


def box_between(lo, hi) -> Geometry:
    """Axis-aligned flat-shaded box spanning corners `lo` and `hi`."""
    lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    return box((lo + hi) / 2.0, np.abs(hi - lo) / 2.0)


def lathe(base, axis, profile, segments: int) -> Geometry:
    """Closed surface of revolution: smooth around the axis, crisp between profile bands.

    Parameters
    ----------
    base : array_like, (3,)
        Point on the axis where the profile's distance 0 lies.
    axis : array_like, (3,)
        Direction of the axis (normalised here).
    profile : array_like, (K, 2)
        ``(radius, distance along axis)`` pairs, K >= 2, radii > 0, distances non-decreasing.
        Flat caps close both ends.
    segments : int
        Number of vertices around the axis.
    """
    base = np.asarray(base, dtype=np.float64)
    axis = normalize(np.asarray(axis, dtype=np.float64))
    profile = np.asarray(profile, dtype=np.float64)
    e1, e2 = perpendicular_frame(axis)
    theta = 2.0 * np.pi * np.arange(segments) / segments
    radial = np.cos(theta)[:, None] * e1 + np.sin(theta)[:, None] * e2
    ring = np.arange(segments)
    nxt = (ring + 1) % segments

    positions, normals, triangles = [], [], []
    count = 0

    def emit(points: np.ndarray, normal: np.ndarray, tris: np.ndarray) -> None:
        nonlocal count
        positions.append(points)
        normals.append(np.broadcast_to(normal, points.shape))
        triangles.append(tris + count)
        count += len(points)

    for (r0, t0), (r1, t1) in zip(profile[:-1], profile[1:], strict=True):
        lower = base + t0 * axis + r0 * radial
        upper = base + t1 * axis + r1 * radial
        normal = normalize(radial * (t1 - t0) - axis * (r1 - r0))
        quads = np.stack([ring, nxt, nxt + segments, ring + segments], axis=1)
        emit(
            np.concatenate([lower, upper]),
            np.concatenate([normal, normal]),
            quads_to_triangles(quads),
        )
    for (r, t), sign in ((profile[0], -1.0), (profile[-1], 1.0)):
        center = base + t * axis
        fan = np.stack([np.zeros(segments, int), ring + 1, nxt + 1], axis=1)
        if sign < 0:
            fan = fan[:, [0, 2, 1]]
        emit(np.concatenate([center[None], center + r * radial]), sign * axis, fan)
    return Geometry(np.concatenate(positions), np.concatenate(triangles), np.concatenate(normals))


def _hull(points) -> Geometry:
    """Flat-shaded convex hull of `points`, outward-facing, one vertex per triangle corner."""
    from scipy.spatial import ConvexHull  # scipy: slow to import
    points = np.asarray(points, dtype=np.float64)
    hull = ConvexHull(points)
    tri = hull.simplices.copy()
    outward = hull.equations[:, :3]
    corners = points[tri]
    face = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    flip = np.einsum("ij,ij->i", face, outward) < 0
    tri[flip] = tri[flip][:, ::-1]
    keep = np.linalg.norm(face, axis=1) > 1e-12
    tri, outward = tri[keep], outward[keep]
    positions = points[tri].reshape(-1, 3)
    indices = np.arange(len(positions)).reshape(-1, 3)
    return Geometry(positions, indices, np.repeat(outward, 3, axis=0))


def _chamfer_polygon(polygon: np.ndarray, d: float) -> np.ndarray:
    """Cut every corner of a convex polygon (K, 2) by distance `d` along both edges."""
    prev = np.roll(polygon, 1, axis=0)
    nxt = np.roll(polygon, -1, axis=0)
    to_prev = normalize(prev - polygon) * d
    to_next = normalize(nxt - polygon) * d
    return np.stack([polygon + to_prev, polygon + to_next], axis=1).reshape(-1, 2)


def _inset_polygon(polygon: np.ndarray, d: float) -> np.ndarray:
    """Offset a convex counter-clockwise polygon (K, 2) inwards by distance `d`."""
    direction = normalize(np.roll(polygon, -1, axis=0) - polygon)  # edge k: vertex k -> k+1
    inward = np.stack([-direction[:, 1], direction[:, 0]], axis=1)
    start = polygon + d * inward
    out = []
    for k in range(len(polygon)):  # new vertex k: edge k-1 meets edge k
        p, q = start[k - 1], start[k]
        a, b = direction[k - 1], direction[k]
        s, _ = np.linalg.solve(np.stack([a, -b], axis=1), q - p)
        out.append(p + s * a)
    return np.array(out)


def chamfered_prism(profile, z_range, bevel: float) -> Geometry:
    """Convex prism of a counter-clockwise x-y `profile` over `z_range`, edges chamfered.

    Faces of the profile and the two end caps keep their exact planes; every edge and corner
    is cut by about `bevel`.
    """
    profile = np.asarray(profile, dtype=np.float64)
    z0, z1 = z_range
    outer = _chamfer_polygon(profile, bevel)
    inner = _chamfer_polygon(_inset_polygon(profile, bevel), bevel)

    def at(poly: np.ndarray, z: float) -> np.ndarray:
        return np.column_stack([poly, np.full(len(poly), z)])

    return _hull(
        np.concatenate([at(outer, z0 + bevel), at(outer, z1 - bevel), at(inner, z0), at(inner, z1)])
    )


def slab(polygon, z_range) -> Geometry:
    """Thin flat-shaded prism of a convex x-y `polygon` over `z_range` (a panel on a side)."""
    polygon = np.asarray(polygon, dtype=np.float64)
    layers = [np.column_stack([polygon, np.full(len(polygon), z)]) for z in z_range]
    return _hull(np.concatenate(layers))


def isosurface(field: np.ndarray, half_extent: float) -> Geometry:
    """The zero level set (negative inside) of ``field`` sampled on a regular grid over
    [-half_extent, half_extent]^3 ([i, j, k] = x, y, z), by marching cubes: a closed,
    outward-facing surface (the grid is padded with outside values) with smooth normals."""
    from skimage.measure import marching_cubes  # heavy import, only needed here

    n = field.shape[0]
    step = 2.0 * half_extent / (n - 1)
    padded = np.pad(field, 1, constant_values=1.0)  # closed at the border
    verts, faces, _, _ = marching_cubes(padded, level=0.0, spacing=(step, step, step))
    positions = verts - (half_extent + step)
    faces = faces.astype(np.int64)
    corners = positions[faces]
    volume = np.einsum("ij,ij->i", corners[:, 0], np.cross(corners[:, 1], corners[:, 2])).sum()
    if volume < 0:
        faces = faces[:, ::-1]
    return Geometry(positions, faces, vertex_normals(positions, faces).astype(np.float64))
