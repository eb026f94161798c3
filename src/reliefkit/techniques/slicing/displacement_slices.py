"""Per-frame slice polygons through a displacement volume (§3.1-§3.3), as triangle lists.

All three slicings cut the volume's tetrahedra (`displacement.DisplacementVolume`) or its
offset surfaces, so every slice vertex carries its exact box coordinates (u, v, h) and the
tetrahedron's Jacobian d(world)/d(u, v, h) (the tangent frame the shader maps the height
gradient through):

* ``surface`` (§3.1): K offset surfaces h = k / (K - 1), k = 0 .. K - 1: the base mesh with
  every vertex moved by h * scale * n_i (so k = 0 is the base itself).
* ``orthogonal`` (§3.2): per base triangle (prism), the slicing direction most perpendicular
  to the view among a (h = const), b (u = const) and c (v = const), i.e. the largest
  |cos| between the view direction and the gradient of h (the face normal), of u or of v
  (in the triangle's plane, from its uv gradient). Levels are shared by all prisms, so
  neighbours using the same direction continue each other's slices: h at the cell centres
  (k + 0.5) / K, u and v at the centres of equal cells over the base's uv range whose world
  spacing is that of the h slices (scale / K) at the median uv gradient. This is §3.4's
  rule: the counts of b and c grow by the ratio of edge length to displacement.
* ``screen`` (§3.3, the exact variant): planes perpendicular to the view direction (as
  `slices.view_direction` defines it) at the centres of equal intervals of world width
  scale / K over the volume's depth range, each cut exactly through every tetrahedron it
  meets: no texture borders, the polygons cover exactly the volume's cross-sections.

A plane cuts a tetrahedron in a triangle (one vertex on one side) or a quad (two and two);
quads are drawn as two triangles. Orthogonal and screen slicing also draw the base itself
(the offset surface h = 0): height 0 is surface, and no slice of theirs lies at h = 0.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...errors import UsageError
from .slices import view_direction

MODES = ("surface", "orthogonal", "screen")
MAX_PLANES = 8192         # screen slicing: planes over the depth range, at most
MAX_POLYGONS = 2_000_000  # per frame, at most (a clear error instead of running out of memory)



class TooManyPolygons(UsageError):
    """More than `MAX_POLYGONS` slice polygons would be needed."""


_EDGES = np.array([(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)], np.int64)


def _edge(a: int, b: int) -> int:
    a, b = min(a, b), max(a, b)
    return next(k for k, (i, j) in enumerate(_EDGES) if (i, j) == (a, b))


def _cut_table() -> tuple[np.ndarray, np.ndarray]:
    """Per pattern of vertices above the plane (bit i = vertex i): the crossed edges in
    cyclic order (up to 4, -1 padded) and their count (0, 3 or 4)."""
    table = np.full((16, 4), -1, np.int64)
    count = np.zeros(16, np.int64)
    for m in range(16):
        up = [i for i in range(4) if m >> i & 1]
        down = [i for i in range(4) if not m >> i & 1]
        if len(up) in (1, 3):
            lone, rest = (up[0], down) if len(up) == 1 else (down[0], up)
            table[m, :3] = [_edge(lone, r) for r in rest]
            count[m] = 3
        elif len(up) == 2:
            (a, b), (c, d) = up, down
            table[m] = [_edge(a, c), _edge(a, d), _edge(b, d), _edge(b, c)]
            count[m] = 4
    return table, count


_TABLE, _COUNT = _cut_table()


@dataclass(frozen=True, eq=False)
class SliceTriangles:
    """A non-indexed triangle list of slice polygons.

    positions : (3M, 3) float64 world.
    box : (3M, 3) float64 (u, v, h) of each vertex.
    jacobian : (3M, 3, 3) float64 d(world)/d(u, v, h) of the tetrahedron (or offset triangle)
        the vertex belongs to.
    triangle : (3M,) int64 the base triangle whose prism (or offset) the vertex lies in.
    polygons : slice polygons (tetrahedron cuts, or offset triangles) drawn.
    slices : slicing planes / surfaces used (for orthogonal: the sum over the three
        directions of the levels that cut something), the base included.
    spacing : world spacing of the h slices (scale / K, or scale / (K - 1) for surface).
    mode : the slicing.
    base : how many of the first triangles are the base itself (h = 0), drawn by orthogonal
        and screen slicing besides their cuts.
    """

    positions: np.ndarray
    box: np.ndarray
    jacobian: np.ndarray
    triangle: np.ndarray
    polygons: int
    slices: int
    spacing: float
    mode: str
    directions: dict
    base: int = 0

    @property
    def triangle_count(self) -> int:
        return len(self.positions) // 3

    def area(self) -> float:
        t = self.positions.reshape(-1, 3, 3)
        return float(0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]),
                                          axis=1).sum())


def cut_tetrahedra(positions, box, tets, jacobian, values, levels, reserved: int = 0) -> tuple:
    """Polygons where the levels ``levels`` (sorted (L,)) of the scalar ``values`` (per volume
    vertex, affine inside each tetrahedron) cut the tetrahedra ``tets``; refused before they
    are built when they and the ``reserved`` polygons of the same frame exceed `MAX_POLYGONS`.

    Returns (positions (3M, 3), box (3M, 3), jacobian (3M, 3, 3), polygons, levels used,
    tetrahedron (3M,): the row of ``tets`` each vertex's polygon cuts).
    """
    levels = np.asarray(levels, np.float64)
    s = values[tets]                                      # (T, 4)
    lo = np.searchsorted(levels, s.min(axis=1), side="right")
    hi = np.searchsorted(levels, s.max(axis=1), side="left")
    n = np.maximum(hi - lo, 0)
    total = int(n.sum())
    if total + reserved > MAX_POLYGONS:
        raise TooManyPolygons(f"{total + reserved} slice polygons would be needed (at most "
                              f"{MAX_POLYGONS}); use fewer slices (--slices)")
    empty = (np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3, 3)), 0, 0,
             np.zeros(0, np.int64))
    if total == 0:
        return empty
    tet = np.repeat(np.arange(len(tets)), n)
    start = np.repeat(np.cumsum(n) - n, n)
    level_index = np.repeat(lo, n) + (np.arange(total) - start)
    level = levels[level_index]
    sv = s[tet]                                           # (P, 4)
    above = sv > level[:, None]
    pattern = (above * (1 << np.arange(4))).sum(axis=1)
    count = _COUNT[pattern]
    keep = count > 0
    tet, level, sv, pattern, count = tet[keep], level[keep], sv[keep], pattern[keep], \
        count[keep]
    used_levels = len(np.unique(level_index[keep]))
    edges = _TABLE[pattern]                               # (P, 4)
    ends = _EDGES[np.maximum(edges, 0)]                   # (P, 4, 2)
    ia = np.take_along_axis(tets[tet], ends[..., 0], 1)   # vertex ids (P, 4)
    ib = np.take_along_axis(tets[tet], ends[..., 1], 1)
    sa = np.take_along_axis(sv, ends[..., 0], 1)
    sb = np.take_along_axis(sv, ends[..., 1], 1)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(sb != sa, (level[:, None] - sa) / (sb - sa), 0.0)
    t = np.clip(t, 0.0, 1.0)[..., None]
    pos = positions[ia] + t * (positions[ib] - positions[ia])   # (P, 4, 3)
    uvh = box[ia] + t * (box[ib] - box[ia])
    # triangles (0, 1, 2) for every polygon, (0, 2, 3) for quads
    quad = count == 4
    first = np.array([0, 1, 2])
    second = np.array([0, 2, 3])
    tri_pos = np.concatenate([pos[:, first], pos[quad][:, second]])
    tri_box = np.concatenate([uvh[:, first], uvh[quad][:, second]])
    jac = np.concatenate([jacobian[tet], jacobian[tet[quad]]])
    source = np.concatenate([tet, tet[quad]])
    return (tri_pos.reshape(-1, 3), tri_box.reshape(-1, 3),
            np.repeat(jac, 3, axis=0), int(len(tet)), used_levels, np.repeat(source, 3))


def _offset_surface(rep, h: float) -> tuple:
    """The base mesh moved by h * scale along its normals: (positions (3F, 3), box (3F, 3),
    jacobian (3F, 3, 3), polygons F, 1 level, triangle (3F,))."""
    base = rep.base
    tris = np.asarray(base.indices, np.int64)
    n = np.asarray(base.normals, np.float64)
    tri_uv = np.asarray(base.uvs, np.float64)[tris]
    duv = np.stack([tri_uv[:, 1] - tri_uv[:, 0], tri_uv[:, 2] - tri_uv[:, 0]], axis=2)
    good = np.abs(np.linalg.det(duv)) > 1e-14
    inv = np.zeros_like(duv)
    inv[good] = np.linalg.inv(duv[good])
    tp = (base.world_positions + (h * rep.scale) * n)[tris]    # (F, 3, 3)
    dp = np.stack([tp[:, 1] - tp[:, 0], tp[:, 2] - tp[:, 0]], axis=2)  # (F, 3, 2)
    juv = dp @ inv                                              # (F, 3, 2): d/du, d/dv
    jh = rep.scale * n[tris]                                    # (F, 3 vertices, 3)
    j = np.concatenate([np.repeat(juv[:, None], 3, axis=1), jh[..., None]], axis=3)
    box = np.concatenate([tri_uv, np.full((*tris.shape, 1), h)], axis=2)
    return (tp.reshape(-1, 3), box.reshape(-1, 3), j.reshape(-1, 3, 3), len(tris), 1,
            np.repeat(np.arange(len(tris)), 3))


def _offset_surfaces(rep, count: int) -> SliceTriangles:
    levels = np.linspace(0.0, 1.0, count) if count > 1 else np.zeros(1)
    surfaces = [_offset_surface(rep, h) for h in levels]
    spacing = rep.scale / (count - 1) if count > 1 else rep.scale
    return _joined(surfaces, spacing, "surface", {"a": surfaces[0][3]})


def base_triangles(rep) -> SliceTriangles:
    """The base itself (the offset surface h = 0), which every slicing draws."""
    return _offset_surfaces(rep, 1)


def _joined(parts, spacing: float, mode: str, directions: dict,
            base: int = 0) -> SliceTriangles:
    """One `SliceTriangles` of several (positions, box, jacobian, polygons, levels, base
    triangle) parts."""
    return SliceTriangles(np.concatenate([c[0] for c in parts]),
                          np.concatenate([c[1] for c in parts]),
                          np.concatenate([c[2] for c in parts]),
                          np.concatenate([c[5] for c in parts]),
                          sum(c[3] for c in parts), sum(c[4] for c in parts), spacing, mode,
                          directions, base)


def _uv_gradients(rep) -> np.ndarray:
    """(F, 2, 3) world gradients of u and v in each base triangle's plane."""
    base = rep.base
    tris = np.asarray(base.indices, np.int64)
    tp = base.world_positions[tris]
    tuv = np.asarray(base.uvs, np.float64)[tris]
    e1, e2 = tp[:, 1] - tp[:, 0], tp[:, 2] - tp[:, 0]
    d1, d2 = tuv[:, 1] - tuv[:, 0], tuv[:, 2] - tuv[:, 0]
    # gradient g of a scalar f with f(p0 + e) - f(p0) = g . e, g in the plane span(e1, e2)
    gram = np.stack([np.stack([np.einsum("ij,ij->i", e1, e1), np.einsum("ij,ij->i", e1, e2)],
                              1),
                     np.stack([np.einsum("ij,ij->i", e1, e2), np.einsum("ij,ij->i", e2, e2)],
                              1)], 1)
    det = np.linalg.det(gram)
    good = np.abs(det) > 1e-30
    inv = np.zeros_like(gram)
    inv[good] = np.linalg.inv(gram[good])
    out = np.zeros((len(tris), 2, 3))
    for k in range(2):
        rhs = np.stack([d1[:, k], d2[:, k]], 1)
        c = np.einsum("fij,fj->fi", inv, rhs)
        out[:, k] = c[:, :1] * e1 + c[:, 1:] * e2
    return out


def orthogonal_levels(rep, count: int, min_spacing: float = 0.0) -> tuple[
        np.ndarray, np.ndarray, np.ndarray]:
    """The shared levels of the three directions: (h levels, u levels, v levels); the u and
    v slices are scale / count apart, or ``min_spacing`` where that is wider."""
    h_levels = (np.arange(count) + 0.5) / count
    spacing = max(rep.scale / count, min_spacing)
    grads = np.linalg.norm(_uv_gradients(rep), axis=2)   # (F, 2) uv units per world unit
    uv = np.asarray(rep.base.uvs, np.float64)
    out = [h_levels]
    for k in range(2):
        g = grads[:, k][grads[:, k] > 0]
        lo, hi = float(uv[:, k].min()), float(uv[:, k].max())
        if not len(g) or hi <= lo:
            out.append(np.zeros(0))
            continue
        step = spacing * float(np.median(g))
        n = min(max(1, math.ceil((hi - lo) / step - 1e-9)), MAX_PLANES)
        out.append(lo + (hi - lo) * (np.arange(n) + 0.5) / n)
    return tuple(out)


def orthogonal_choice(rep, camera) -> np.ndarray:
    """(F,) per base triangle the direction most perpendicular to the view: 0 = a
    (h = const), 1 = b (u = const), 2 = c (v = const). Ties go to a."""
    base = rep.base
    tris = np.asarray(base.indices, np.int64)
    tp = base.world_positions[tris]
    normal = np.cross(tp[:, 1] - tp[:, 0], tp[:, 2] - tp[:, 0])
    grads = _uv_gradients(rep)
    dirs = np.stack([normal, grads[:, 0], grads[:, 1]], axis=1)     # (F, 3, 3)
    norms = np.linalg.norm(dirs, axis=2)
    safe = np.where(norms > 0, norms, 1.0)
    unit = dirs / safe[..., None]
    f = _view_per_point(camera, tp.mean(axis=1))
    score = np.abs(np.einsum("fkx,fx->fk", unit, f))
    score[norms == 0] = -1.0
    best = np.argmax(score, axis=1)
    tie = score[:, 0] >= score.max(axis=1) - 1e-9
    return np.where(tie, 0, best)


def _view_per_point(camera, points) -> np.ndarray:
    """(N, 3) unit view directions at world points (from the eye, or the orthographic one)."""
    if hasattr(camera, "view_dir") or camera.orthographic:
        f = view_direction(camera, points.mean(axis=0))
        return np.broadcast_to(f, points.shape)
    d = points - np.asarray(camera.eye, np.float64)
    return d / np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-300)


def slice_triangles(rep, camera, mode: str, count: int, volume=None,
                    min_spacing: float = 0.0) -> SliceTriangles:
    """The slice polygons of ``rep`` for ``camera`` in slicing ``mode`` with ``count`` h
    slices (see the module docstring). Orthogonal u and v slices and screen planes, spaced
    scale / count, are spaced ``min_spacing`` apart where that is wider: a volume thinner
    than a pixel needs no planes closer than one (their count would grow as 1 / scale)."""
    if mode not in MODES:
        raise UsageError(f"slicing must be one of {', '.join(MODES)}, got {mode!r}")
    if isinstance(count, bool) or int(count) != count or count < 1:
        raise UsageError(f"slice count must be a positive integer, got {count!r}")
    count = int(count)
    if mode == "surface":
        if count * len(rep.base.indices) > MAX_POLYGONS:
            raise TooManyPolygons(f"{count * len(rep.base.indices)} slice polygons would be "
                                  f"needed (at most {MAX_POLYGONS}); use fewer slices "
                                  "(--slices)")
        return _offset_surfaces(rep, count)
    vol = volume if volume is not None else rep.volume()
    if mode == "orthogonal":
        choice = orthogonal_choice(rep, camera)
        levels = orthogonal_levels(rep, count, min_spacing)
        parts, directions = [_offset_surface(rep, 0.0)], {}
        for k, name, axis in ((0, "a", 2), (1, "b", 0), (2, "c", 1)):
            tets = np.flatnonzero(choice[vol.prism_of] == k)
            directions[name] = int(np.count_nonzero(choice == k))
            if not len(tets) or not len(levels[k]):
                continue
            *cut, source = cut_tetrahedra(vol.positions, vol.box, vol.tets[tets],
                                          vol.jacobian[tets], vol.box[:, axis], levels[k],
                                          sum(c[3] for c in parts))
            parts.append((*cut, vol.prism_of[tets][source]))
        return _joined(parts, rep.scale / count, "orthogonal", directions, parts[0][3])
    # screen
    spacing = max(rep.scale / count, min_spacing)
    centre = 0.5 * (vol.positions.min(axis=0) + vol.positions.max(axis=0))
    f = view_direction(camera, centre)
    depth = vol.positions @ f
    near, far = float(depth.min()), float(depth.max())
    planes = min(max(1, math.ceil((far - near) / spacing - 1e-9)), MAX_PLANES)
    levels = near + (far - near) * (np.arange(planes) + 0.5) / planes
    base = _offset_surface(rep, 0.0)
    *cut, source = cut_tetrahedra(vol.positions, vol.box, vol.tets, vol.jacobian, depth, levels,
                                  base[3])
    cut = (*cut, vol.prism_of[source])
    return _joined([base, cut], (far - near) / planes, "screen", {"planes": planes}, base[3])
