"""Procedural base surfaces with texture coordinates, for techniques that need (u, v).

Shell volumes extrude a mesh along its vertex normals into prisms textured with a tiled 3D
texture, so these meshes come with smooth analytic normals and parametric uvs. Every one is
deterministic, light grey (linear RGBA, alpha 1), +y up, right-handed, fits roughly in
[-1, 1] and has counter-clockwise outward-facing triangles.

Seams are duplicated: the vertices at u = 0 and u = 1 (and v = 0, v = 1 on a torus) have the
same positions and normals but their own uvs. A pole (sphere, vase bottom, teapot lid knob
and bottom) is one vertex with u = 0.5, never one vertex per segment: coincident vertices of
one triangle would give flat prisms. `SURFACES` maps the demo names to the factories.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ...errors import UsageError
from ..mesh import RenderMesh, vertex_normals
from .teapot_data import patch_control_points

__all__ = [
    "SURFACES",
    "dented_sphere",
    "plane",
    "sphere",
    "teapot",
    "torus",
    "tube",
    "two_spheres",
    "vase",
]

#: Linear RGBA of every surface: a plain light grey.
GREY = (0.7, 0.7, 0.7, 1.0)

#: The teapot's parts: (name, first patch, patches around, patch rows along the profile).
#: Within a part, patch ``first + row * around + column`` continues its left neighbour in
#: the patch parameter s and the one above it in t (checked against the data in the tests).
TEAPOT_PARTS = (
    ("rim", 0, 4, 1),
    ("body", 4, 4, 2),
    ("handle", 12, 2, 2),
    ("spout", 16, 2, 2),
    ("lid", 20, 4, 2),
    ("bottom", 28, 4, 1),
)


# ----------------------------------------------------------------------------- grids


class _Grid:
    """A (rows + 1) x (columns + 1) sample grid of a parametric surface, u along columns.

    positions, normals (rows + 1, columns + 1, 3); uvs (rows + 1, columns + 1, 2). A row
    flagged as a pole collapses into one vertex (u = 0.5) whose quads become triangles.
    """

    def __init__(self, positions, normals, uvs, south_pole=False, north_pole=False):
        self.positions = np.asarray(positions, dtype=np.float64)
        self.normals = np.asarray(normals, dtype=np.float64)
        self.uvs = np.asarray(uvs, dtype=np.float64)
        self.poles = (south_pole, north_pole)

    def triangles(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(positions, normals, uvs, triangles) of the grid with its poles collapsed."""
        rows, cols = self.positions.shape[0] - 1, self.positions.shape[1] - 1
        index = np.arange((rows + 1) * (cols + 1)).reshape(rows + 1, cols + 1)
        keep = np.ones((rows + 1, cols + 1), bool)
        pos, nrm, uv = (a.copy() for a in (self.positions, self.normals, self.uvs))
        for row, pole in zip((0, rows), self.poles, strict=True):
            if pole:
                keep[row, 1:] = False
                index[row, :] = index[row, 0]
                pos[row, 0] = self.positions[row].mean(axis=0)
                nrm[row, 0] = _unit(self.normals[row].mean(axis=0))
                uv[row, 0] = (0.5, self.uvs[row, 0, 1])
        a, b = index[:-1, :-1], index[:-1, 1:]
        d, c = index[1:, :-1], index[1:, 1:]
        lower = np.stack([a, b, c], axis=-1)  # (rows, cols, 3)
        upper = np.stack([a, c, d], axis=-1)
        tris = []
        for r in range(rows):
            if not (r == 0 and self.poles[0]):
                tris.append(lower[r])
            if not (r == rows - 1 and self.poles[1]):
                tris.append(upper[r])
        tris = np.concatenate(tris).reshape(-1, 3)
        flat_keep = keep.ravel()
        remap = np.cumsum(flat_keep) - 1
        return (pos.reshape(-1, 3)[flat_keep], nrm.reshape(-1, 3)[flat_keep],
                uv.reshape(-1, 2)[flat_keep], remap[tris])


def _unit(v: np.ndarray) -> np.ndarray:
    v = np.asarray(v, dtype=np.float64)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _mesh(grids: list[_Grid], name: str, extra: dict | None = None) -> RenderMesh:
    """One light-grey RenderMesh from the grids' vertices and triangles."""
    positions, normals, uvs, triangles = [], [], [], []
    count = 0
    for grid in grids:
        p, n, uv, t = grid.triangles()
        positions.append(p)
        normals.append(n)
        uvs.append(uv)
        triangles.append(t + count)
        count += len(p)
    positions = _snap(np.concatenate(positions))
    return RenderMesh(
        positions=positions.astype(np.float32),
        indices=np.concatenate(triangles).astype(np.uint32),
        normals=_snap(_unit(np.concatenate(normals))).astype(np.float32),
        colors=np.broadcast_to(np.asarray(GREY, np.float32), (len(positions), 4)),
        uvs=np.concatenate(uvs).astype(np.float32),
        name=name,
        extra={} if extra is None else extra,
    )


def _snap(values: np.ndarray) -> np.ndarray:
    """Rounding residue (sin(pi) ~ 1e-16) set to zero: float32 squares of it underflow."""
    return np.where(np.abs(values) < 1e-12, 0.0, values)


def _check_count(label: str, value, low: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < low:
        raise UsageError(f"{label} must be an integer >= {low}, got {value!r}")
    return int(value)


def _check_positive(label: str, value) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        number = float("nan")
    if isinstance(value, bool) or not np.isfinite(number) or number <= 0:
        raise UsageError(f"{label} must be a positive number, got {value!r}")
    return number


def _uv(columns: int, rows: int) -> tuple[np.ndarray, np.ndarray]:
    """(rows + 1, columns + 1) u and v in [0, 1]."""
    return np.meshgrid(np.linspace(0.0, 1.0, columns + 1), np.linspace(0.0, 1.0, rows + 1))


# ----------------------------------------------------------------------------- spheres


def _sphere_grid(segments: int, rings: int, radius: float, center=(0.0, 0.0, 0.0)) -> _Grid:
    """UV sphere: longitude 2 pi u - pi (the seam at -z), latitude pi v - pi / 2."""
    u, v = _uv(segments, rings)
    lon, lat = 2.0 * np.pi * u - np.pi, np.pi * v - np.pi / 2
    normal = np.stack([np.cos(lat) * np.sin(lon), np.sin(lat), np.cos(lat) * np.cos(lon)], -1)
    normal[0] = (0.0, -1.0, 0.0)  # exact poles
    normal[-1] = (0.0, 1.0, 0.0)
    normal[:, -1] = normal[:, 0]  # the seam: the same positions and normals
    positions = np.asarray(center, dtype=np.float64) + radius * normal
    return _Grid(positions, normal, np.stack([u, v], -1), south_pole=True, north_pole=True)


def sphere(segments: int = 32, rings: int = 16, radius: float = 1.0) -> RenderMesh:
    """UV sphere about the origin: u = longitude / 2 pi (seam duplicated at -z), v =
    latitude from 0 at the south pole to 1 at the north; each pole is one vertex."""
    segments = _check_count("segments", segments, 3)
    rings = _check_count("rings", rings, 2)
    radius = _check_positive("radius", radius)
    return _mesh([_sphere_grid(segments, rings, radius)], "sphere")


def dented_sphere(segments: int = 48, rings: int = 24, radius: float = 1.0,
                  depth: float = 0.5, width: float = 0.7) -> RenderMesh:
    """The unit UV sphere with a smooth Gaussian dent facing +z (the viewer's side).

    The radius at angle a from +z is ``radius * (1 - depth * exp(-(a / width)^2))``: a bowl
    deep enough that rays grazing it leave and re-enter the surface (and a shell over it),
    its concave curvature radius (about 0.16 at the defaults) above a 0.1 shell. Normals are
    recomputed from the geometry, with the seam welded so both copies agree.
    """
    segments = _check_count("segments", segments, 3)
    rings = _check_count("rings", rings, 2)
    radius = _check_positive("radius", radius)
    width = _check_positive("width", width)
    if not 0.0 <= float(depth) < 1.0:
        raise UsageError(f"depth must be in [0, 1), got {depth!r}")
    grid = _sphere_grid(segments, rings, 1.0)
    direction = grid.positions
    angle = np.arccos(np.clip(direction[..., 2], -1.0, 1.0))
    scale = radius * (1.0 - float(depth) * np.exp(-((angle / width) ** 2)))
    grid.positions = direction * scale[..., None]
    positions, _, uvs, faces = grid.triangles()
    welded = faces.copy()
    seam = np.isclose(uvs[:, 0], 1.0) & (uvs[:, 1] > 0) & (uvs[:, 1] < 1)
    seam_rows = np.flatnonzero(seam)
    welded[np.isin(welded, seam_rows)] -= segments  # u = 1 column onto its u = 0 twin
    normals = vertex_normals(positions, welded)
    normals[seam_rows] = normals[seam_rows - segments]
    return RenderMesh(
        positions=positions.astype(np.float32), indices=faces.astype(np.uint32),
        normals=normals, uvs=uvs.astype(np.float32),
        colors=np.broadcast_to(np.asarray(GREY, np.float32), (len(positions), 4)),
        name="dented-sphere")


def two_spheres(segments: int = 32, rings: int = 16, radius: float = 0.45,
                gap: float = 1.2) -> RenderMesh:
    """Two separate UV spheres, one behind the other: centres at z = -gap / 2 and +gap / 2."""
    segments = _check_count("segments", segments, 3)
    rings = _check_count("rings", rings, 2)
    radius = _check_positive("radius", radius)
    gap = _check_positive("gap", gap)
    grids = [_sphere_grid(segments, rings, radius, (0.0, 0.0, z)) for z in (-gap / 2, gap / 2)]
    return _mesh(grids, "two-spheres")


# ----------------------------------------------------------------------------- others


def torus(major: float = 1.0, minor: float = 0.35, major_segments: int = 32,
          minor_segments: int = 16) -> RenderMesh:
    """Torus about +y, scaled into [-1, 1]: u along the major circle (seam at -z), v along
    the minor one (seam on the inner equator); both seams duplicated."""
    major = _check_positive("major", major)
    minor = _check_positive("minor", minor)
    if minor >= major:
        raise UsageError(f"minor ({minor}) must be smaller than major ({major})")
    major_segments = _check_count("major_segments", major_segments, 3)
    minor_segments = _check_count("minor_segments", minor_segments, 3)
    u, v = _uv(major_segments, minor_segments)
    alpha, gamma = 2.0 * np.pi * u - np.pi, 2.0 * np.pi * v - np.pi
    alpha[:, -1], gamma[-1] = alpha[:, 0], gamma[0]  # exact seams
    normal = np.stack([np.cos(gamma) * np.sin(alpha), np.sin(gamma),
                       np.cos(gamma) * np.cos(alpha)], -1)
    centre = major * np.stack([np.sin(alpha), np.zeros_like(alpha), np.cos(alpha)], -1)
    positions = (centre + minor * normal) / (major + minor)
    return _mesh([_Grid(positions, normal, np.stack([u, v], -1))], "torus")


def plane(size: float = 2.0, cells: int = 8) -> RenderMesh:
    """A flat square in the xz plane facing +y: u along +x, v along -z (uvs in [0, 1])."""
    size = _check_positive("size", size)
    cells = _check_count("cells", cells, 1)
    u, v = _uv(cells, cells)
    positions = np.stack([(u - 0.5) * size, np.zeros_like(u), (0.5 - v) * size], -1)
    normals = np.broadcast_to([0.0, 1.0, 0.0], positions.shape)
    return _mesh([_Grid(positions, normals, np.stack([u, v], -1))], "plane")


def tube(radius: float = 0.5, height: float = 2.0, segments: int = 32,
         rings: int = 8) -> RenderMesh:
    """An open cylinder about +y (no caps), centred on the origin: u around (seam at -z),
    v from 0 at the bottom to 1 at the top; outward normals."""
    radius = _check_positive("radius", radius)
    height = _check_positive("height", height)
    segments = _check_count("segments", segments, 3)
    rings = _check_count("rings", rings, 1)
    u, v = _uv(segments, rings)
    angle = 2.0 * np.pi * u - np.pi
    angle[:, -1] = angle[:, 0]
    normal = np.stack([np.sin(angle), np.zeros_like(angle), np.cos(angle)], -1)
    positions = radius * normal + np.stack([0 * u, (v - 0.5) * height, 0 * u], -1)
    return _mesh([_Grid(positions, normal, np.stack([u, v], -1))], "tube")


#: The vase's profile: (radius, height) points from the bottom centre to the lip.
VASE_PROFILE = np.array([
    (0.0, -1.0), (0.3, -0.98), (0.52, -0.86), (0.66, -0.6), (0.7, -0.3), (0.62, 0.05),
    (0.42, 0.38), (0.3, 0.62), (0.3, 0.8), (0.36, 0.93), (0.44, 1.0),
])


def _revolve(radius: np.ndarray, height: np.ndarray, d_radius: np.ndarray,
             d_height: np.ndarray, segments: int) -> tuple[np.ndarray, np.ndarray]:
    """(rows, segments + 1, 3) positions and unit normals of a profile turned about +y."""
    angle = np.linspace(-np.pi, np.pi, segments + 1)
    angle[-1] = angle[0]
    sin, cos = np.sin(angle)[None], np.cos(angle)[None]
    r, h = radius[:, None], height[:, None]
    shape = (len(radius), segments + 1)
    positions = np.stack([r * sin, np.broadcast_to(h, shape), r * cos], -1)
    # the outward normal of the profile (rotated tangent): (dh, -dr) in (radial, y)
    nr, ny = d_height[:, None], -d_radius[:, None]
    length = np.hypot(nr, ny)
    nr, ny = nr / length, ny / length
    normals = np.stack([nr * sin, np.broadcast_to(ny, shape), nr * cos], -1)
    return positions, normals


def vase(segments: int = 32, rings: int = 24) -> RenderMesh:
    """A closed-bottom vase about +y: bulge, neck and flared lip (open at the top).

    The profile is a clamped cubic spline through `VASE_PROFILE`, sampled at equal arc
    length: u goes around (seam at -z), v along the profile's arc length from 0 at the
    bottom centre (one pole vertex) to 1 at the lip. Normals come from the spline's tangent.
    """
    from scipy.interpolate import CubicSpline  # scipy: slow to import
    segments = _check_count("segments", segments, 3)
    rings = _check_count("rings", rings, 2)
    chord = np.linalg.norm(np.diff(VASE_PROFILE, axis=0), axis=1)
    knots = np.concatenate([[0.0], np.cumsum(chord)])
    spline = CubicSpline(knots, VASE_PROFILE, bc_type=((1, [1.0, 0.0]), "not-a-knot"))
    fine = np.linspace(0.0, knots[-1], 4097)
    speed = np.linalg.norm(spline(fine, 1), axis=1)
    arc = np.concatenate([[0.0], np.cumsum((speed[1:] + speed[:-1]) / 2 * np.diff(fine))])
    param = np.interp(np.linspace(0.0, arc[-1], rings + 1), arc, fine)
    point, tangent = spline(param), spline(param, 1)
    point[0, 0] = 0.0
    positions, normals = _revolve(point[:, 0], point[:, 1], tangent[:, 0], tangent[:, 1],
                                  segments)
    u, v = _uv(segments, rings)
    return _mesh([_Grid(positions, normals, np.stack([u, v], -1), south_pole=True)], "vase")


# ----------------------------------------------------------------------------- teapot


def _bernstein(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(N, 4) cubic Bernstein weights at t and their derivatives."""
    t = np.asarray(t, dtype=np.float64)[:, None]
    s = 1.0 - t
    weights = np.concatenate([s ** 3, 3 * t * s ** 2, 3 * t ** 2 * s, t ** 3], axis=1)
    slopes = np.concatenate([-3 * s ** 2, 3 * s ** 2 - 6 * t * s, 6 * t * s - 3 * t ** 2,
                             3 * t ** 2], axis=1)
    return weights, slopes


def _teapot_part(nets: np.ndarray, around: int, rows: int, n: int) -> _Grid:
    """One part's patches sampled as a single grid, n x n quads per patch.

    Its uv is the part's own chart, u = (column + s) / around, v = (row + t) / rows, so
    vertices on the borders between its patches are shared; the u = 0 / 1 seam is
    duplicated and a row whose samples all coincide (the lid knob's top, the bottom's
    centre) is a pole.
    """
    local = np.linspace(0.0, 1.0, n + 1)
    weights, slopes = _bernstein(local)
    size = (rows * n + 1, around * n + 1)
    positions, d_s, d_t = (np.zeros(size + (3,)) for _ in range(3))
    for row in range(rows):
        for col in range(around):
            net = nets[row * around + col]  # [t, s] control points
            block = (slice(row * n, row * n + n + 1), slice(col * n, col * n + n + 1))
            positions[block] = np.einsum("ti,sj,ijx->tsx", weights, weights, net)
            d_s[block] = np.einsum("ti,sj,ijx->tsx", weights, slopes, net)
            d_t[block] = np.einsum("ti,sj,ijx->tsx", slopes, weights, net)
    normals = np.cross(d_s, d_t)
    poles = [bool(np.ptp(positions[r], axis=0).max() < 1e-9) for r in (0, -1)]
    for r, pole in zip((0, -1), poles, strict=True):
        if pole:  # the limit normal: along the t derivative's turn, nearly at the pole
            near = 1e-4 if r == 0 else 1.0 - 1e-4
            w, dw = _bernstein(np.array([near]))
            row = 0 if r == 0 else rows - 1
            limit = [np.cross(np.einsum("i,sj,ijx->sx", w[0], slopes, net),
                              np.einsum("i,sj,ijx->sx", dw[0], weights, net))
                     for net in nets[row * around:(row + 1) * around]]
            normals[r] = _unit(np.concatenate(limit).sum(axis=0))
    u, v = _uv(around * n, rows * n)
    return _Grid(positions, _unit(normals), np.stack([u, v], -1), *poles)


def teapot(subdivisions: int = 8) -> RenderMesh:
    """The Utah teapot (Newell's 32 Bezier patches, `teapot_data`), +y up, fitted to [-1, 1].

    Each patch is an ``subdivisions x subdivisions`` grid. The uvs are per part (rim, body,
    handle, spout, lid, bottom; see `TEAPOT_PARTS`), so patches of one part share their
    border vertices, while the parts stay apart: the mesh has boundaries at the lid's and
    the rim's open edges, the spout's ends, the handle's ends and between parts. The data's
    z-up axes become +y up (x stays, the spout along +x); the bounding box is centred on the
    origin and its largest extent (spout to handle) scaled to 2. ``extra["parts"]`` lists
    each part's triangle range.
    """
    n = _check_count("subdivisions", subdivisions, 1)
    nets = patch_control_points()
    nets = np.stack([nets[..., 0], nets[..., 2], -nets[..., 1]], axis=-1)  # z up -> y up
    grids, parts, start = [], [], 0
    for name, first, around, rows in TEAPOT_PARTS:
        grid = _teapot_part(nets[first:first + around * rows], around, rows, n)
        grids.append(grid)
        stop = start + len(grid.triangles()[3])
        parts.append({"name": name, "triangles": (start, stop), "closed": False,
                      "patches": (first, first + around * rows)})
        start = stop
    low = np.min([g.positions.reshape(-1, 3).min(axis=0) for g in grids], axis=0)
    high = np.max([g.positions.reshape(-1, 3).max(axis=0) for g in grids], axis=0)
    centre, scale = (low + high) / 2, 2.0 / float((high - low).max())
    for grid in grids:
        grid.positions = (grid.positions - centre) * scale
    return _mesh(grids, "teapot", extra={"parts": parts, "patches": len(nets),
                                          "scale": scale, "data_center": centre.tolist()})


#: The thickest shell the teapot takes along its exact normals (checked in the tests): the
#: classic data's creases are tight, the foot's concave curvature radius is 0.017 data units
#: (0.005 here) and the spout's rolled-back lip is a bore about 0.05 across.
TEAPOT_SHELL = 0.008


#: The surfaces by demo name (``demo:NAME``), each called with its defaults.
SURFACES: dict[str, Callable[[], RenderMesh]] = {
    "sphere": sphere,
    "dented-sphere": dented_sphere,
    "torus": torus,
    "two-spheres": two_spheres,
    "plane": plane,
    "tube": tube,
    "vase": vase,
    "teapot": teapot,
}
