"""Procedural demo assets: a terrain, a closed blob, a tree and a van.

Every asset is deterministic for a given seed (``np.random.default_rng(seed)``), built with
numpy, scipy and scikit-image only (nothing is downloaded) and returned as a
:class:`~reliefkit.scene.mesh.RenderMesh` with linear RGBA vertex colours picked in sRGB.
Coordinates are right-handed with +y up and fit roughly in [-1, 1].

Each mesh lists its parts in ``mesh.extra["parts"]``: one dict per part with its ``name``,
its triangle range ``triangles`` (start, stop) and whether it is ``closed`` (a closed part
bounds a solid with counter-clockwise, outward-facing triangles, so its signed volume is
positive). Flat-shaded parts (boxes, hulls) have their own vertices per face so their normals
stay crisp; smooth parts (terrain, blob, round sides of cylinders) share vertices.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

import numpy as np
from scipy import ndimage
from scipy.spatial import ConvexHull

from ..errors import UsageError
from .mesh import RenderMesh, vertex_normals

__all__ = [
    "ASSET_NAMES",
    "all_assets",
    "blob",
    "make_asset",
    "srgb_to_linear",
    "terrain",
    "terrain_heights",
    "tree",
    "vehicle",
]

ASSET_NAMES = ("terrain", "blob", "tree", "vehicle")


# --------------------------------------------------------------------------- colours


def srgb_to_linear(srgb) -> np.ndarray:
    """Decode sRGB-encoded values in [0, 1] to linear values with the sRGB transfer function.

    Parameters
    ----------
    srgb : array_like
        Encoded values; anything outside [0, 1] is clipped first.

    Returns
    -------
    numpy.ndarray
        Linear values (float64), same shape.
    """
    c = np.clip(np.asarray(srgb, dtype=np.float64), 0.0, 1.0)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def _rgb(r: int, g: int, b: int) -> np.ndarray:
    """Linear RGB of an 8-bit sRGB colour."""
    return srgb_to_linear(np.array([r, g, b], dtype=np.float64) / 255.0)


def _mix(a, b, t) -> np.ndarray:
    """Linear interpolation ``a + (b - a) * t`` with `t` broadcast over colour channels."""
    t = np.asarray(t, dtype=np.float64)
    if t.ndim:
        t = t[..., None]
    return np.asarray(a) + (np.asarray(b) - np.asarray(a)) * t


def _smoothstep(edge0: float, edge1: float, x) -> np.ndarray:
    """Hermite step from 0 at `edge0` to 1 at `edge1` (``edge0 > edge1`` gives a falling step)."""
    t = np.clip((np.asarray(x, dtype=np.float64) - edge0) / (edge1 - edge0), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


# --------------------------------------------------------------------------- mesh assembly


class _Geometry(NamedTuple):
    """Positions (V, 3), triangles (F, 3) and unit normals (V, 3) of one part."""

    positions: np.ndarray
    indices: np.ndarray
    normals: np.ndarray


class _MeshBuilder:
    """Collects coloured parts and concatenates them into one `RenderMesh`."""

    def __init__(self) -> None:
        self._chunks: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = []
        self._parts: list[dict] = []
        self._vertices = 0
        self._triangles = 0

    def add(self, name: str, geometry: _Geometry, color, closed: bool = True) -> None:
        """Append a part.

        Parameters
        ----------
        name : str
            Part label recorded in ``extra["parts"]``.
        geometry : _Geometry
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


def _normalize(v) -> np.ndarray:
    """Vectors along the last axis of `v` scaled to unit length (zero vectors stay zero)."""
    v = np.asarray(v, dtype=np.float64)
    length = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.where(length > 1e-12, length, np.inf)


def _unit_normals(normals: np.ndarray) -> np.ndarray:
    """(V, 3) float32 unit normals; a degenerate (zero) normal becomes +y."""
    unit = _normalize(normals)
    unit[np.linalg.norm(unit, axis=1) < 0.5] = (0.0, 1.0, 0.0)
    return unit.astype(np.float32)


def _quads_to_triangles(quads: np.ndarray) -> np.ndarray:
    """Split quads (Q, 4), corners counter-clockwise seen from the front, into triangles."""
    quads = np.asarray(quads)
    return np.concatenate([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])


def _perpendicular_frame(axis: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit vectors ``e1, e2`` perpendicular to unit `axis` with ``cross(e1, e2) == axis``."""
    helper = np.array([1.0, 0.0, 0.0]) if abs(axis[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = _normalize(np.cross(axis, helper))
    return e1, np.cross(axis, e1)


# --------------------------------------------------------------------------- primitives


def _box(center, half_size, axes=None) -> _Geometry:
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
    return _Geometry(np.concatenate(positions), _quads_to_triangles(quads), np.concatenate(normals))


def _box_between(lo, hi) -> _Geometry:
    """Axis-aligned flat-shaded box spanning corners `lo` and `hi`."""
    lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    return _box((lo + hi) / 2.0, np.abs(hi - lo) / 2.0)


def _lathe(base, axis, profile, segments: int) -> _Geometry:
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
    axis = _normalize(np.asarray(axis, dtype=np.float64))
    profile = np.asarray(profile, dtype=np.float64)
    e1, e2 = _perpendicular_frame(axis)
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
        normal = _normalize(radial * (t1 - t0) - axis * (r1 - r0))
        quads = np.stack([ring, nxt, nxt + segments, ring + segments], axis=1)
        emit(
            np.concatenate([lower, upper]),
            np.concatenate([normal, normal]),
            _quads_to_triangles(quads),
        )
    for (r, t), sign in ((profile[0], -1.0), (profile[-1], 1.0)):
        center = base + t * axis
        fan = np.stack([np.zeros(segments, int), ring + 1, nxt + 1], axis=1)
        if sign < 0:
            fan = fan[:, [0, 2, 1]]
        emit(np.concatenate([center[None], center + r * radial]), sign * axis, fan)
    return _Geometry(np.concatenate(positions), np.concatenate(triangles), np.concatenate(normals))


def _hull(points) -> _Geometry:
    """Flat-shaded convex hull of `points`, outward-facing, one vertex per triangle corner."""
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
    return _Geometry(positions, indices, np.repeat(outward, 3, axis=0))


def _chamfer_polygon(polygon: np.ndarray, d: float) -> np.ndarray:
    """Cut every corner of a convex polygon (K, 2) by distance `d` along both edges."""
    prev = np.roll(polygon, 1, axis=0)
    nxt = np.roll(polygon, -1, axis=0)
    to_prev = _normalize(prev - polygon) * d
    to_next = _normalize(nxt - polygon) * d
    return np.stack([polygon + to_prev, polygon + to_next], axis=1).reshape(-1, 2)


def _inset_polygon(polygon: np.ndarray, d: float) -> np.ndarray:
    """Offset a convex counter-clockwise polygon (K, 2) inwards by distance `d`."""
    direction = _normalize(np.roll(polygon, -1, axis=0) - polygon)  # edge k: vertex k -> k+1
    inward = np.stack([-direction[:, 1], direction[:, 0]], axis=1)
    start = polygon + d * inward
    out = []
    for k in range(len(polygon)):  # new vertex k: edge k-1 meets edge k
        p, q = start[k - 1], start[k]
        a, b = direction[k - 1], direction[k]
        s, _ = np.linalg.solve(np.stack([a, -b], axis=1), q - p)
        out.append(p + s * a)
    return np.array(out)


def _chamfered_prism(profile, z_range, bevel: float) -> _Geometry:
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


def _slab(polygon, z_range) -> _Geometry:
    """Thin flat-shaded prism of a convex x-y `polygon` over `z_range` (a panel on a side)."""
    polygon = np.asarray(polygon, dtype=np.float64)
    layers = [np.column_stack([polygon, np.full(len(polygon), z)]) for z in z_range]
    return _hull(np.concatenate(layers))


# --------------------------------------------------------------------------- validation


def _check_int(label: str, value, lo: int, hi: int | None = None) -> int:
    """`value` as an int within [lo, hi], else a `UsageError`."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise UsageError(f"{label} must be an integer, got {value!r}")
    if value < lo or (hi is not None and value > hi):
        limit = f">= {lo}" if hi is None else f"in [{lo}, {hi}]"
        raise UsageError(f"{label} must be {limit}, got {value}")
    return int(value)


def _check_positive(label: str, value) -> float:
    """`value` as a positive finite float, else a `UsageError`."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise UsageError(f"{label} must be a number, got {value!r}") from None
    if not np.isfinite(x) or x <= 0:
        raise UsageError(f"{label} must be a positive finite number, got {value!r}")
    return x


# --------------------------------------------------------------------------- terrain


def _fbm(
    u: np.ndarray,
    v: np.ndarray,
    rng: np.random.Generator,
    octaves: int = 6,
    cells: int = 3,
    persistence: float = 0.5,
) -> np.ndarray:
    """Fractal value noise in about [0, 1] at texture coordinates (`u`, `v`) in [0, 1].

    Octave k interpolates a random lattice of ``cells * 2**k`` cells with cubic splines; the
    random draws do not depend on the sampling, so every resolution samples the same noise.
    """
    total = np.zeros(np.shape(u))
    amplitude, norm = 1.0, 0.0
    for k in range(octaves):
        n = cells * 2**k
        lattice = rng.random((n + 1, n + 1))
        coords = np.stack([np.asarray(v) * n, np.asarray(u) * n])
        total += amplitude * ndimage.map_coordinates(lattice, coords, order=3, mode="nearest")
        norm += amplitude
        amplitude *= persistence
    return total / norm


def _segment_distance(u, v, a, b) -> np.ndarray:
    """Distance from points (`u`, `v`) to the segment from `a` to `b` in the uv square."""
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    ab = b - a
    t = np.clip(((u - a[0]) * ab[0] + (v - a[1]) * ab[1]) / (ab @ ab), 0.0, 1.0)
    return np.hypot(u - (a[0] + t * ab[0]), v - (a[1] + t * ab[1]))


def terrain_heights(resolution: int = 128, seed: int = 0) -> np.ndarray:
    """A fractal landscape heightfield with a ridge, a river valley and a cliff-edged plateau.

    Parameters
    ----------
    resolution : int
        Samples per side, R >= 2.
    seed : int
        Random seed; the random draws do not depend on `resolution`, so other resolutions
        sample the same landscape.

    Returns
    -------
    numpy.ndarray
        (R, R) float32 heights in [0, 1]; ``heights[j, i]`` is the sample at
        ``u = (i + 0.5) / R``, ``v = (j + 0.5) / R`` (the DESIGN.md heightfield convention).
        Height 0 is the flat water of the river running along u near ``v = 0.22``.
    """
    r = _check_int("resolution", resolution, 2)
    rng = np.random.default_rng(seed)
    texel = (np.arange(r) + 0.5) / r
    u, v = np.meshgrid(texel, texel)  # u[j, i] = texel[i], v[j, i] = texel[j]
    jitter = rng.uniform(-0.04, 0.04, size=6)
    phase = rng.uniform(0.0, 1.0)

    hills = _fbm(u, v, rng)
    crest = _fbm(u, v, rng, octaves=3, cells=4)
    h = 1.2 * hills

    # A ridge: a line of peaks across the low-u, high-v corner (crest heights follow noise).
    d = _segment_distance(u, v, (0.08 + jitter[0], 0.62 + jitter[1]), (0.55, 0.92 + jitter[2]))
    h += 0.8 * np.exp(-np.minimum((d / 0.075) ** 2, 60.0)) * (0.3 + 1.2 * crest)

    # A river valley meandering along u, with a channel carved down to the water.
    river = 0.22 + jitter[3] + 0.06 * np.sin(2.0 * np.pi * (0.9 * u + phase))
    h -= 0.3 * np.exp(-np.minimum(((v - river) / 0.1) ** 2, 60.0))
    channel = np.exp(-np.minimum(((v - river) / 0.03) ** 2, 60.0))
    h += (h.min() - 0.1 - h) * channel

    # A plateau with a cliff: a rough table top raised above its surroundings.
    center = np.array([0.74 + jitter[4], 0.6 + jitter[5]])
    angle = np.arctan2(v - center[1], u - center[0])
    edge = 0.15 * (1.0 + 0.12 * np.sin(3.0 * angle + 6.0 * phase) + 0.05 * np.sin(7.0 * angle))
    inside = np.clip((edge - np.hypot(u - center[0], v - center[1])) * r / 1.5 + 0.5, 0.0, 1.0)
    top = np.quantile(h, 0.93) + 0.02 * crest
    h = h + (np.maximum(h, top) - h) * inside

    h = (h - h.min()) / max(float(np.ptp(h)), 1e-12)
    water = 0.14
    return np.clip((h - water) / (1.0 - water), 0.0, 1.0).astype(np.float32)


def _terrain_colors(heights: np.ndarray, up: np.ndarray, seed: int) -> np.ndarray:
    """Linear RGB by altitude and slope: water, beach, grass, forest, rock, snow.

    `heights` are in [0, 1]; `up` is the y component of the unit normals.
    """
    r = heights.shape[0]
    texel = (np.arange(r) + 0.5) / r
    u, v = np.meshgrid(texel, texel)
    rng = np.random.default_rng(np.random.SeedSequence(seed).spawn(1)[0])  # not the heights'
    noise = _fbm(u, v, rng, octaves=4, cells=8) - 0.5
    a = heights + 0.12 * noise  # jittered altitude breaks up straight colour bands

    color = _mix(_rgb(112, 156, 64), _rgb(48, 96, 42), _smoothstep(0.1, 0.6, a))
    color = _mix(_rgb(204, 190, 140), color, _smoothstep(0.0, 0.045, a))  # beach
    color = _mix(color, _rgb(128, 118, 106), _smoothstep(0.72, 0.86, a) * 0.8)  # bare highland
    color = _mix(color, _rgb(116, 110, 104), _smoothstep(0.82, 0.6, up))  # steep rock
    snow = _smoothstep(0.84, 0.92, a) * _smoothstep(0.5, 0.7, up)
    color = _mix(color, _rgb(242, 244, 250), snow)
    water = _mix(_rgb(52, 138, 140), _rgb(34, 92, 118), _smoothstep(0.0, 0.3, -noise))
    return np.where((heights <= 0.0)[..., None], water, color)


def terrain(
    resolution: int = 128, seed: int = 0, size: float = 2.0, height: float = 0.5
) -> RenderMesh:
    """The `terrain_heights` landscape as a grid mesh (a heightfield by construction).

    Parameters
    ----------
    resolution : int
        Grid vertices per side, R >= 2; the mesh has ``2 * (R - 1)**2`` triangles.
    seed : int
        Random seed (see `terrain_heights`).
    size : float
        Side of the square footprint, centred on the origin in x and z.
    height : float
        World height of a height of 1; ``y = heights * height``.

    Returns
    -------
    RenderMesh
        Vertex ``j * R + i`` lies at ``x = (u_i - 0.5) * size``, ``y = heights[j, i] * height``,
        ``z = (v_j - 0.5) * size`` with ``u_i = (i + 0.5) / R``, ``v_j = (j + 0.5) / R``.
        Front faces point +y, so a camera looking down -y sees the top.
    """
    size = _check_positive("size", size)
    height = _check_positive("height", height)
    heights = terrain_heights(resolution, seed)
    r = heights.shape[0]
    coord = ((np.arange(r) + 0.5) / r - 0.5) * size
    x, z = np.meshgrid(coord, coord)
    positions = np.stack([x, heights * height, z], axis=-1).reshape(-1, 3)
    a = (np.arange(r - 1)[:, None] * r + np.arange(r - 1)[None, :]).ravel()
    # Corners a=(i, j), a+r=(i, j+1), a+r+1, a+1: counter-clockwise seen from +y.
    indices = _quads_to_triangles(np.stack([a, a + r, a + r + 1, a + 1], axis=1))
    normals = vertex_normals(positions, indices)
    colors = _terrain_colors(heights, normals[:, 1].reshape(r, r), seed).reshape(-1, 3)
    builder = _MeshBuilder()
    builder.add("ground", _Geometry(positions, indices, normals), colors, closed=False)
    return builder.build("terrain")


# --------------------------------------------------------------------------- blob


def _smooth_min(a: np.ndarray, b: np.ndarray, k: float) -> np.ndarray:
    """Polynomial smooth minimum: the union of two distance fields, blended over `k`."""
    h = np.maximum(k - np.abs(a - b), 0.0) / k
    return np.minimum(a, b) - h * h * (k / 4.0)


def _length(p: np.ndarray) -> np.ndarray:
    """Euclidean length over the last axis (faster than `numpy.linalg.norm` here)."""
    return np.sqrt(np.einsum("...i,...i->...", p, p))


def _torus(p: np.ndarray, major: float, minor: float) -> np.ndarray:
    """Signed distance to a torus around the local z axis (`p` (..., 3), local coordinates)."""
    ring = np.hypot(p[..., 0], p[..., 1]) - major
    return np.hypot(ring, p[..., 2]) - minor


def _rotation(axis, angle: float) -> np.ndarray:
    """3x3 rotation by `angle` radians about `axis` (Rodrigues)."""
    x, y, z = _normalize(np.asarray(axis, dtype=np.float64))
    k = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    return np.eye(3) + np.sin(angle) * k + (1.0 - np.cos(angle)) * (k @ k)


def _dimple_directions(rng: np.random.Generator, count: int) -> np.ndarray:
    """Unit directions for dimples: off the equator (the ring) and, on top, off the arch."""
    out = []
    for _ in range(count):
        x, y, z = rng.normal(size=3)
        y = np.copysign(rng.uniform(0.35, 0.7), y)
        if y > 0:  # the arch stands in the x-y plane: keep top dimples to its front or back
            z = np.copysign(max(abs(z), 1.2 * abs(x)), z)
        out.append(_normalize(np.array([x, y, z])))
    return np.array(out)


def _capsule(p: np.ndarray, a: np.ndarray, b: np.ndarray, radius: float) -> np.ndarray:
    """Signed distance to the capsule of `radius` around the segment from `a` to `b`."""
    ab = b - a
    t = np.clip(((p - a) @ ab) / np.float32(ab @ ab), 0.0, 1.0)
    return _length(p - a - t[..., None] * ab) - np.float32(radius)


def _blob_field(p: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Signed-distance-like field (negative inside) of the blob at float32 points `p` (..., 3).

    A lumpy body with deep dimples; a slightly tilted ring around it, held by three spokes
    (overhangs and see-through gaps from above and below); an arch on top (a tunnel along z).
    All smoothly welded together: one solid of genus 4.
    """
    f32 = np.float32
    center = np.array([0.0, -0.05, 0.0])
    waves = rng.normal(size=(4, 3))
    waves *= rng.uniform(4.0, 6.0, size=(4, 1)) / _length(waves)[:, None]
    phases = rng.uniform(0.0, 2.0 * np.pi, size=4)
    dimples = center + 0.56 * _dimple_directions(rng, 6)
    tilt_axis = rng.normal(size=3) * [1.0, 0.0, 1.0] + [1e-3, 0.0, 0.0]
    tilt = _rotation(tilt_axis, rng.uniform(0.05, 0.15))
    spoke_angles = rng.uniform(0.0, 2.0 * np.pi) + 2.0 * np.pi * np.arange(3) / 3.0

    wobble = sum(np.sin(p @ w.astype(f32) + f32(phi)) for w, phi in zip(waves, phases, strict=True))
    body = _length(p - center.astype(f32)) - f32(0.46) + f32(0.025) * wobble
    for c in dimples.astype(f32):
        body = -_smooth_min(-body, _length(p - c) - f32(0.2), 0.05)
    ring_frame = tilt @ _rotation([1.0, 0.0, 0.0], np.pi / 2)  # torus axis z -> tilted y
    shape = _smooth_min(body, _torus(p @ ring_frame.astype(f32), 0.72, 0.1), 0.06)
    for angle in spoke_angles:
        spoke = tilt @ np.array([np.cos(angle), 0.0, np.sin(angle)])
        shape = _smooth_min(
            shape, _capsule(p, (0.3 * spoke).astype(f32), (0.72 * spoke).astype(f32), 0.055), 0.08
        )
    arch = _torus(p - np.array([0.0, 0.38, 0.0], f32), 0.3, 0.085)
    return _smooth_min(shape, arch, 0.1)


def _concavity(positions: np.ndarray, normals: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """Per-vertex concavity (> 0 in dents and creases) from the smoothed umbrella Laplacian."""
    edges = np.concatenate([indices[:, [0, 1]], indices[:, [1, 2]], indices[:, [2, 0]]])
    n = len(positions)
    degree = np.bincount(edges[:, 0], minlength=n).astype(np.float64)
    total = np.zeros_like(positions)
    np.add.at(total, edges[:, 0], positions[edges[:, 1]])
    laplacian = total / np.maximum(degree, 1.0)[:, None] - positions
    mean_edge = np.linalg.norm(positions[edges[:, 0]] - positions[edges[:, 1]], axis=1).mean()
    value = np.einsum("ij,ij->i", laplacian, normals) / mean_edge**2
    for _ in range(4):  # a few smoothing passes tame marching-cubes noise
        acc = np.zeros(n)
        np.add.at(acc, edges[:, 0], value[edges[:, 1]])
        value = 0.5 * value + 0.5 * acc / np.maximum(degree, 1.0)
    return value


def blob(seed: int = 0, subdivisions: int = 4) -> RenderMesh:
    """A closed, lumpy object with dimples, a ring and an arch: no heightfield from any axis.

    It is the zero isosurface of an implicit function (a lumpy sphere with deep dimples, a
    slightly tilted ring around its equator held by three spokes, an arch over its top making
    a tunnel along z), extracted with marching cubes: one watertight, outward-facing,
    smooth-shaded solid of genus 4. Vertical lines through the arch and horizontal lines
    through the ring cross the surface four or more times.

    Parameters
    ----------
    seed : int
        Random seed for the lumps, the dimples and the ring's tilt.
    subdivisions : int
        Level of detail in [1, 5]: the field is sampled on ``5 * 2**subdivisions`` points per
        axis over [-1, 1] (80 at the default, about 30k triangles).

    Returns
    -------
    RenderMesh
        One closed part ``"blob"``; colours go from coral at the bottom to gold at the top,
        with dimples and creases tinted plum.
    """
    from skimage.measure import marching_cubes  # heavy import, only needed here

    n = 5 * 2 ** _check_int("subdivisions", subdivisions, 1, 5)
    rng = np.random.default_rng(seed)
    axis = np.linspace(-1.0, 1.0, n)
    grid = np.stack(np.meshgrid(axis, axis, axis, indexing="ij"), axis=-1).astype(np.float32)
    field = np.pad(_blob_field(grid, rng), 1, constant_values=1.0)  # closed at the border
    step = axis[1] - axis[0]
    verts, faces, _, _ = marching_cubes(field, level=0.0, spacing=(step, step, step))
    positions = verts - (1.0 + step)
    faces = faces.astype(np.int64)
    corners = positions[faces]
    volume = np.einsum("ij,ij->i", corners[:, 0], np.cross(corners[:, 1], corners[:, 2])).sum()
    if volume < 0:
        faces = faces[:, ::-1]
    normals = vertex_normals(positions, faces).astype(np.float64)

    height = _smoothstep(positions[:, 1].min(), positions[:, 1].max(), positions[:, 1])
    around = 0.5 + 0.5 * np.sin(3.0 * np.arctan2(positions[:, 2], positions[:, 0]))
    color = _mix(_rgb(226, 96, 78), _rgb(244, 190, 76), height)
    color = _mix(color, _rgb(236, 140, 96), 0.35 * around)
    color = _mix(
        color, _rgb(108, 56, 128), _smoothstep(0.0, 0.35, _concavity(positions, normals, faces))
    )
    builder = _MeshBuilder()
    builder.add("blob", _Geometry(positions, faces, normals), color)
    return builder.build("blob")


# --------------------------------------------------------------------------- tree


class _Branch(NamedTuple):
    """One tapered cylinder of the tree: start point, unit direction, length, radii, depth."""

    start: np.ndarray
    direction: np.ndarray
    length: float
    radius: float
    tip_radius: float
    depth: int


def _tilt(direction: np.ndarray, angle: float, azimuth: float) -> np.ndarray:
    """`direction` turned by `angle` radians towards the side given by `azimuth`."""
    e1, e2 = _perpendicular_frame(direction)
    side = np.cos(azimuth) * e1 + np.sin(azimuth) * e2
    return np.cos(angle) * direction + np.sin(angle) * side


def _grow(rng: np.random.Generator, branch: _Branch, out: list[_Branch]) -> None:
    """Append `branch` and, recursively, its 2-3 children to `out`."""
    out.append(branch)
    if branch.depth == 0:
        return
    count = int(rng.integers(2, 4))
    azimuth0 = rng.uniform(0.0, 2.0 * np.pi)
    for k in range(count):
        leader = k == 0  # the first child carries on from the tip, the others fork lower
        t = 1.0 if leader else rng.uniform(0.5, 0.92)
        angle = np.radians(rng.uniform(8, 22) if leader else rng.uniform(30, 55))
        direction = _tilt(branch.direction, angle, azimuth0 + 2.0 * np.pi * k / count)
        direction = _normalize(direction + [0.0, 0.25, 0.0])  # branches reach for the light
        radius = branch.radius + (branch.tip_radius - branch.radius) * t
        radius *= 0.9 if leader else 0.7
        start = branch.start + branch.direction * branch.length * t - direction * radius
        length = branch.length * rng.uniform(0.62, 0.78)
        _grow(rng, _Branch(start, direction, length, radius, radius * 0.7, branch.depth - 1), out)


def _leaf_quads(rng: np.random.Generator, branches: list[_Branch], count: int) -> _Geometry:
    """Make `count` double-sided kite-shaped leaves on the outer branches.

    Each leaf has 8 vertices and 4 triangles: the front and the back are separate vertices
    with opposite normals and opposite windings.
    """
    twigs = [b for b in branches if b.depth <= 1]
    pick = rng.integers(0, len(twigs), size=count)
    t = rng.uniform(0.2, 1.0, size=count)
    start = np.array([twigs[i].start for i in pick])
    along = np.array([twigs[i].direction * twigs[i].length for i in pick])
    stem = start + along * t[:, None] + rng.normal(scale=0.025, size=(count, 3))
    up = _normalize(
        _normalize(along) * 0.6 + rng.normal(scale=0.7, size=(count, 3)) + [0.0, 0.2, 0.0]
    )
    normal = _normalize(np.cross(up, rng.normal(size=(count, 3))))
    across = np.cross(up, normal)  # cross(across, up) == normal
    length = rng.uniform(0.1, 0.16, size=(count, 1))
    width = 0.42 * length
    corners = np.stack(
        [
            stem,
            stem + 0.45 * length * up + width * across,
            stem + length * up,
            stem + 0.45 * length * up - width * across,
        ],
        axis=1,
    )
    front = np.arange(count)[:, None] * 8 + np.arange(4)
    back = front + 4
    positions = np.concatenate([corners, corners], axis=1).reshape(-1, 3)
    normals = np.concatenate(
        [np.repeat(normal[:, None], 4, 1), np.repeat(-normal[:, None], 4, 1)], axis=1
    ).reshape(-1, 3)
    indices = np.concatenate([_quads_to_triangles(front), _quads_to_triangles(back[:, ::-1])])
    return _Geometry(positions, indices, normals)


def _leaf_colors(rng: np.random.Generator, count: int) -> np.ndarray:
    """Per-vertex linear RGB for `count` leaves: greens varying per leaf, backs paler."""
    shade = _mix(_rgb(38, 104, 34), _rgb(126, 176, 52), rng.uniform(0.0, 1.0, size=count))
    shade *= rng.uniform(0.8, 1.15, size=(count, 1))
    back = _mix(shade, _rgb(170, 196, 110), 0.35)
    return np.concatenate(
        [np.repeat(shade[:, None], 4, 1), np.repeat(back[:, None], 4, 1)], axis=1
    ).reshape(-1, 3)


def tree(seed: int = 0, leaves: int = 600) -> RenderMesh:
    """A tree: a flared, tapered trunk, recursive branches and double-sided leaf quads.

    Parameters
    ----------
    seed : int
        Random seed for the branching and the leaves.
    leaves : int
        Number of leaves (>= 0); each is one quad emitted twice (both windings).

    Returns
    -------
    RenderMesh
        Stands on y = -1 and reaches to about y = 1. Parts: ``"trunk"`` and ``"branch"``
        (closed tapered cylinders, browns) and ``"leaves"`` (open, ``4 * leaves`` triangles,
        greens).
    """
    leaves = _check_int("leaves", leaves, 0)
    rng = np.random.default_rng(seed)
    trunk = _Branch(np.array([0.0, -1.0, 0.0]), np.array([0.0, 1.0, 0.0]), 0.8, 0.075, 0.055, 4)
    branches: list[_Branch] = []
    _grow(rng, trunk, branches)
    builder = _MeshBuilder()
    bark = _rgb(96, 64, 38)
    for b in branches:
        if b.depth == trunk.depth:  # a flared foot for the trunk
            profile = [(b.radius * 1.5, 0.0), (b.radius, 0.12), (b.tip_radius, b.length)]
        else:
            profile = [(b.radius, 0.0), (b.tip_radius, b.length)]
        segments = 14 if b.depth >= 3 else 7
        color = bark * rng.uniform(0.85, 1.15)
        name = "trunk" if b.depth == trunk.depth else "branch"
        builder.add(name, _lathe(b.start, b.direction, profile, segments), color)
    if leaves:
        builder.add(
            "leaves", _leaf_quads(rng, branches, leaves), _leaf_colors(rng, leaves), closed=False
        )
    return builder.build("tree")


# --------------------------------------------------------------------------- vehicle

_PAINTS = ((196, 38, 36), (32, 92, 170), (236, 236, 228), (240, 180, 30), (44, 130, 84))


class _VanShape(NamedTuple):
    """Main dimensions of the van (x: length, y: height, z: width; the ground is y = 0)."""

    half_length: float
    half_width: float
    floor: float  # bottom of the body
    belt: float  # top of the lower body, bottom of the cabin
    roof: float
    wheel_radius: float

    def windshield_x(self, y):
        """Return x on the windshield's outer plane at height `y` (it leans back from the nose)."""
        bottom, top = self.half_length - 0.16, self.half_length - 0.5
        return bottom + (top - bottom) * (np.asarray(y) - self.belt) / (self.roof - self.belt)


def _van_body(builder: _MeshBuilder, s: _VanShape, paint: np.ndarray) -> None:
    """Lower body (with a sloped nose) and cabin (with a raked windshield), both chamfered."""
    hl, hw = s.half_length, s.half_width
    lower = [(-hl, s.floor), (hl, s.floor), (hl, s.belt - 0.07), (hl - 0.14, s.belt), (-hl, s.belt)]
    cabin = [
        (-hl, s.belt - 0.02),
        (s.windshield_x(s.belt - 0.02), s.belt - 0.02),
        (s.windshield_x(s.roof), s.roof),
        (-hl, s.roof),
    ]
    builder.add("body", _chamfered_prism(lower, (-hw, hw), 0.04), paint)
    builder.add("cabin", _chamfered_prism(cabin, (-hw, hw), 0.05), paint)


def _van_wheels(builder: _MeshBuilder, s: _VanShape) -> None:
    """Four wheels: rounded tyres with silver rims, five spokes and a hub, set in the sides."""
    r = s.wheel_radius
    tyre = [(r - 0.03, 0.0), (r, 0.025), (r, 0.135), (r - 0.03, 0.16)]
    rim = [(0.62 * r, 0.15), (0.62 * r, 0.168), (0.5 * r, 0.175)]
    hub = [(0.2 * r, 0.17), (0.2 * r, 0.19)]
    for x in (-0.62 * s.half_length, 0.64 * s.half_length):
        for side in (-1.0, 1.0):
            axis = np.array([0.0, 0.0, side])
            base = np.array([x, r, side * (s.half_width - 0.12)])
            builder.add("tyre", _lathe(base, axis, tyre, 28), _rgb(34, 34, 36))
            builder.add("rim", _lathe(base, axis, rim, 28), _rgb(188, 190, 196))
            builder.add("hub", _lathe(base, axis, hub, 12), _rgb(90, 92, 98))
            for k in range(5):
                a = 2.0 * np.pi * k / 5 + 0.3
                spoke_axes = np.column_stack(
                    [[np.cos(a), np.sin(a), 0.0], [-np.sin(a), np.cos(a), 0.0], [0.0, 0.0, 1.0]]
                )
                center = base + [0.35 * r * np.cos(a), 0.35 * r * np.sin(a), side * 0.177]
                builder.add(
                    "spoke", _box(center, (0.17 * r, 0.035, 0.006), spoke_axes), _rgb(150, 152, 160)
                )


def _van_side(builder: _MeshBuilder, s: _VanShape, side: float, paint: np.ndarray) -> None:
    """Windows, door seams, handles, a rubbing strip, a marker light and a mirror on one side."""
    hl, hw = s.half_length, s.half_width
    glass, dark = _rgb(30, 40, 52), _rgb(24, 24, 26)

    def panel(polygon, proud: float, inset: float = 0.01):
        z = (side * (hw - inset), side * (hw + proud))
        return _slab(np.asarray(polygon, dtype=np.float64), z)

    lo, hi = s.belt + 0.08, s.roof - 0.08
    front = [(0.2, lo), (s.windshield_x(lo) - 0.07, lo), (s.windshield_x(hi) - 0.07, hi), (0.2, hi)]
    builder.add("window", panel(front, 0.006), glass)
    for x0, x1 in ((-0.42, 0.12), (-0.9, -0.5)):
        builder.add("window", panel([(x0, lo), (x1, lo), (x1, hi), (x0, hi)], 0.006), glass)
    for x in (0.16, -0.46):  # door seams, floor to roof
        builder.add(
            "seam",
            panel(
                [
                    (x - 0.006, s.floor + 0.04),
                    (x + 0.006, s.floor + 0.04),
                    (x + 0.006, s.roof - 0.04),
                    (x - 0.006, s.roof - 0.04),
                ],
                0.003,
            ),
            dark,
        )
    for x in (0.26, 0.06):  # handles
        builder.add(
            "handle",
            _box_between(
                (x - 0.04, s.belt - 0.06, side * (hw - 0.01)),
                (x + 0.04, s.belt - 0.035, side * (hw + 0.022)),
            ),
            dark,
        )
    strip_y = s.floor + 0.12
    builder.add(
        "strip",
        _box_between(
            (-0.36 * hl / 0.62, strip_y, side * (hw - 0.01)),
            (0.36, strip_y + 0.05, side * (hw + 0.012)),
        ),
        _rgb(60, 60, 64),
    )
    builder.add(
        "marker",
        _box_between(
            (0.86 * hl, strip_y, side * (hw - 0.01)),
            (0.93 * hl, strip_y + 0.04, side * (hw + 0.008)),
        ),
        _rgb(255, 150, 20),
    )
    mirror_x, mirror_y = s.windshield_x(s.belt + 0.06) - 0.03, s.belt + 0.12
    builder.add(
        "mirror", _box((mirror_x, mirror_y - 0.04, side * (hw + 0.035)), (0.02, 0.012, 0.04)), dark
    )
    builder.add(
        "mirror", _box((mirror_x, mirror_y, side * (hw + 0.085)), (0.025, 0.055, 0.04)), paint
    )
    builder.add(
        "mirror",
        _box((mirror_x - 0.027, mirror_y, side * (hw + 0.085)), (0.004, 0.045, 0.032)),
        glass,
    )


def _van_ends(builder: _MeshBuilder, s: _VanShape) -> None:
    """Windshield, headlights, grille and bumpers at the front; window and lights at the back."""
    hl, hw = s.half_length, s.half_width
    glass, dark = _rgb(30, 40, 52), _rgb(24, 24, 26)
    bottom = np.array([s.windshield_x(s.belt), s.belt])
    top = np.array([s.windshield_x(s.roof), s.roof])
    up = _normalize(top - bottom)
    out = np.array([up[1], -up[0]])  # the windshield's outward normal in x-y
    axes = np.column_stack([[out[0], out[1], 0.0], [up[0], up[1], 0.0], [0.0, 0.0, 1.0]])
    middle = (bottom + top) / 2.0
    half_span = np.linalg.norm(top - bottom) / 2.0
    builder.add(
        "windshield", _box((*middle, 0.0), (0.008, half_span - 0.08, hw - 0.07), axes), glass
    )

    for z in (-0.29 * hw / 0.42, 0.29 * hw / 0.42):
        base = (hl - 0.01, s.belt - 0.12, z)
        builder.add(
            "headlight",
            _lathe(base, (1.0, 0.0, 0.0), [(0.06, 0.0), (0.06, 0.018), (0.045, 0.028)], 20),
            _rgb(255, 244, 200),
        )
        builder.add(
            "taillight",
            _box_between(
                (-hl - 0.012, s.belt - 0.2, z - 0.05), (-hl + 0.01, s.belt + 0.02, z + 0.05)
            ),
            _rgb(200, 20, 24),
        )
    builder.add(
        "grille",
        _box_between((hl - 0.01, s.belt - 0.2, -0.17), (hl + 0.012, s.belt - 0.07, 0.17)),
        dark,
    )
    for x0, x1 in ((hl - 0.05, hl + 0.05), (-hl - 0.05, -hl + 0.05)):
        builder.add(
            "bumper",
            _box_between((x0, s.floor - 0.03, -hw - 0.01), (x1, s.floor + 0.1, hw + 0.01)),
            _rgb(64, 64, 68),
        )
    builder.add(
        "rear window",
        _box_between(
            (-hl - 0.006, s.belt + 0.08, -hw + 0.08), (-hl + 0.01, s.roof - 0.08, hw - 0.08)
        ),
        glass,
    )


def vehicle(seed: int = 0) -> RenderMesh:
    """A delivery van, long along x (nose towards +x), standing on y = 0, centred in z.

    Its sides are vertical and carry the detail (windows, door seams, handles, a rubbing
    strip, a marker light, mirrors, wheels with spoked rims), so a reverse-perspective frustum
    looking down sees them while an orthographic top view sees only the roof, the mirrors and
    the tops of the wheels and bumpers.

    Parameters
    ----------
    seed : int
        Random seed for the paint colour and small changes of length and height.

    Returns
    -------
    RenderMesh
        Closed, flat-shaded parts (chamfered body and cabin, boxes) and smooth round parts
        (tyres, rims, hubs, headlights), each listed in ``extra["parts"]``.
    """
    rng = np.random.default_rng(seed)
    paint = _rgb(*_PAINTS[int(rng.integers(len(_PAINTS)))])
    shape = _VanShape(
        half_length=0.95 * rng.uniform(0.97, 1.03),
        half_width=0.42,
        floor=0.16,
        belt=0.52,
        roof=0.9 + rng.uniform(-0.04, 0.04),
        wheel_radius=0.2,
    )
    builder = _MeshBuilder()
    _van_body(builder, shape, paint)
    _van_wheels(builder, shape)
    for side in (-1.0, 1.0):
        _van_side(builder, shape, side, paint)
    _van_ends(builder, shape)
    return builder.build("vehicle")


# --------------------------------------------------------------------------- registry

_FACTORIES: dict[str, Callable[[], RenderMesh]] = {
    "terrain": terrain,
    "blob": blob,
    "tree": tree,
    "vehicle": vehicle,
}


def make_asset(name: str) -> RenderMesh:
    """The demo asset called `name` (one of `ASSET_NAMES`) with its default parameters.

    Raises
    ------
    UsageError
        If `name` is not a known asset.
    """
    factory = _FACTORIES.get(name) if isinstance(name, str) else None
    if factory is None:
        raise UsageError(f"unknown asset {name!r}; choose one of: {', '.join(ASSET_NAMES)}")
    return factory()


def all_assets() -> dict[str, RenderMesh]:
    """Every demo asset with its default parameters, keyed by name (`ASSET_NAMES` order)."""
    return {name: make_asset(name) for name in ASSET_NAMES}
