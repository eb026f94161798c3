"""Visibility order of a shell's tetrahedra, front to back, for compositing.

**SXMPVO** (Cook, Max, Silva & Williams 2004; Dufort et al. 2005, §4.1) builds a graph of
"a is in front of b" relations and sorts it topologically:

1. *Adjacent cells.* Two tetrahedra sharing a face are ordered by that face's orientation:
   the tetrahedron for which the shared face is back-facing (the eye on the inner side of
   its plane; for an orthographic camera, the outward normal along the view direction) is
   crossed first by every ray through the face, so it is in front.
2. *Across gaps.* A shell is not convex: a ray leaves it and re-enters it, and nothing
   above links the cells on either side of the gap. The boundary (unshared) faces are
   rasterized into a low-resolution A-buffer: per sample ray, the list of boundary faces
   it meets, sorted by the exact distance along that ray. Consecutive faces on a ray give
   "the nearer face's tetrahedron is in front of the next one's". Faces met at the same
   point (a ray through an edge) form one layer and are related to the next layer as a
   whole, so a tie never invents an order.
3. *Traversal.* A depth-first traversal of the graph gives a topological order (reverse
   post-order). Edges that close a cycle (back edges) are dropped and counted in
   `VisibilityOrder.cycles`; the roots are visited in centroid-depth order, which makes
   the choice of dropped edge deterministic.

**Limitation.** Step 2 samples the image: the order is exact when every pair of
non-adjacent tetrahedra whose projections overlap across a gap is separated by some
A-buffer sample ray. Gaps thinner than an A-buffer sample (a pixel at `resolution` on the
longer side) can be missed; raise `resolution` for those. Boundary faces with a vertex
behind the eye are skipped (the eye is assumed outside the shell).

**Speed.** The renderer sorts every frame, so the whole pipeline is numba kernels over
int32 arrays, without numpy temporaries of the size of the A-buffer or the graph:

- what does not depend on the camera (the interior face pairs with their planes, the
  boundary faces with their vertices, planes and tetrahedra, the shell's size) is gathered
  once per shell (`order_cells`, cached on the shell object);
- shell vertices are projected once, not once per face corner; the A-buffer is a
  counting-sort layout (per-pixel lists in one array), each list sorted in place;
- the graph is built in *rank space* (nodes numbered by centroid depth): a counting sort
  by source, each source's successors sorted by decreasing rank and deduplicated in
  place, so there is no global sort of the relations, and the traversal's visiting order
  (farthest root first, nearest successor last) is the plain numbering;
- the A-buffer (step 2) runs on a second thread while the depths, the ranks and step 1
  are computed (the kernels release the GIL).

`method="centroid"` sorts by the centroids' distance from the eye (along the view
direction for orthographic cameras): the cheap, approximate baseline.
"""

from __future__ import annotations

import time
import weakref
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np
from numba import njit

from ...errors import UsageError
from .sorts import METHODS

#: Default A-buffer samples along the image's longer side.
RESOLUTION = 256

#: Distances along a ray closer than this times the shell's size are the same point.
TIE = 1e-9

#: Segments of a per-node list longer than this are sorted with np.sort, not by insertion.
_INSERTION = 24

#: Slots (a power of two) of the table of recent relations `_ray_edges` does not repeat.
_RECENT = 4096

_JIT = {"cache": True, "error_model": "numpy", "nogil": True}


@dataclass(frozen=True)
class VisibilityOrder:
    """A front-to-back order of all tetrahedra of a shell.

    order : (T,) int32 tetrahedron indices, the first one composited first (nearest).
    cycles : relations dropped to break cycles (0: the order satisfies every relation).
    edges : distinct "in front of" relations the sort used (0 for "centroid").
    seconds : wall time of the sort.
    method : "sxmpvo" or "centroid".
    """

    order: np.ndarray
    cycles: int
    edges: int
    seconds: float
    method: str


def visibility_order(shell, camera, method: str = "sxmpvo",
                     resolution: int = RESOLUTION) -> VisibilityOrder:
    """Sort `shell`'s tetrahedra (a shell or its `OrderCells`) front to back as seen by
    `camera` (Camera or MatrixCamera).

    resolution: A-buffer samples along the longer image side (SXMPVO only).
    """
    if method not in METHODS:
        raise UsageError(f"method must be one of {', '.join(METHODS)}, got {method!r}")
    if int(resolution) != resolution or resolution < 1:
        raise UsageError(f"resolution must be a positive integer, got {resolution!r}")
    start = time.perf_counter()
    if method == "centroid":
        order = _by_depth(centroid_depths(shell, camera))
        return VisibilityOrder(order, 0, 0, time.perf_counter() - start, method)
    # step 2 on the worker thread, the depths and step 1 here, then the traversal
    gaps = _worker().submit(abuffer_relations, shell, camera, int(resolution))
    by_depth = _by_depth(centroid_depths(shell, camera))
    a_src, a_dst = adjacent_relations(shell, camera)
    g_src, g_dst = gaps.result()
    order, broken, edges = topological_order(by_depth, (a_src, a_dst), (g_src, g_dst))
    return VisibilityOrder(order, broken, edges, time.perf_counter() - start, method)


_WORKER: list[ThreadPoolExecutor] = []


def _worker() -> ThreadPoolExecutor:
    """The one thread the A-buffer runs on, next to the caller's (started on first use)."""
    if not _WORKER:
        _WORKER.append(ThreadPoolExecutor(1, thread_name_prefix="sxmpvo"))
    return _WORKER[0]


# --------------------------------------------------------------------------- per shell


@dataclass(frozen=True, eq=False)
class OrderCells:
    """What SXMPVO needs of a shell, as plain arrays: the same for every camera, gathered
    once per shell (`order_cells`); a draw plan's view hook holds them.

    positions : (V, 3) float64 shell vertices; tets : (T, 4) int32 their tetrahedra.
    pair_tet, pair_other : (K,) int32 the two tetrahedra of each interior face, once.
    pair_plane : (K, 4) float64 that face's plane as seen from pair_tet (outward normal).
    face_tet : (N,) int32 tetrahedron of each boundary face.
    face_vertices : (N, 3) int32 its three shell vertices.
    face_plane : (N, 4) float64 its plane (outward normal).
    scale : the shell's size (bounding-box diagonal), for tolerances.
    """

    positions: np.ndarray
    tets: np.ndarray
    pair_tet: np.ndarray
    pair_other: np.ndarray
    pair_plane: np.ndarray
    face_tet: np.ndarray
    face_vertices: np.ndarray
    face_plane: np.ndarray
    scale: float


_CELLS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()

# the three vertices of face f (the ones other than f) of a tetrahedron
_FACE_CORNERS = np.array([[v for v in range(4) if v != f] for f in range(4)])


def order_cells(shell) -> OrderCells:
    """The shell's `OrderCells`, gathered on the first call for that shell object (shells
    are frozen; the cache holds no reference to the shell); cells are their own."""
    if isinstance(shell, OrderCells):
        return shell
    cells = _CELLS.get(shell)
    if cells is None:
        tet, face = np.nonzero(shell.neighbors >= 0)
        other = shell.neighbors[tet, face]
        once = tet < other
        tet, face, other = tet[once], face[once], other[once]
        b_tet, b_face = np.nonzero(shell.neighbors < 0)
        corners = np.take_along_axis(shell.tets[b_tet], _FACE_CORNERS[b_face], axis=1)
        p = shell.positions
        cells = OrderCells(
            positions=np.ascontiguousarray(p, dtype=np.float64),
            tets=np.ascontiguousarray(shell.tets, dtype=np.int32),
            pair_tet=tet.astype(np.int32), pair_other=other.astype(np.int32),
            pair_plane=np.ascontiguousarray(shell.planes[tet, face]),
            face_tet=b_tet.astype(np.int32),
            face_vertices=np.ascontiguousarray(corners, dtype=np.int32),
            face_plane=np.ascontiguousarray(shell.planes[b_tet, b_face]),
            scale=float(np.linalg.norm(p.max(axis=0) - p.min(axis=0))) or 1.0)
        _CELLS[shell] = cells
    return cells


# --------------------------------------------------------------------------- depths


def centroid_depths(shell, camera) -> np.ndarray:
    """(T,) float64 depth of each centroid: distance from the eye, or along the view
    direction for orthographic cameras (smaller is nearer)."""
    point = _forward(camera) if camera.orthographic \
        else np.asarray(camera.eye, dtype=np.float64)
    return _depths(np.ascontiguousarray(shell.positions, dtype=np.float64),
                   np.ascontiguousarray(shell.tets, dtype=np.int32), point,
                   bool(camera.orthographic))


def _forward(camera) -> np.ndarray:
    """Unit view direction (eye towards scene) of an orthographic camera."""
    if hasattr(camera, "view_dir"):  # MatrixCamera: view_dir points scene -> viewer
        d = -np.asarray(camera.view_dir, dtype=np.float64)
    else:
        d = np.asarray(camera.target, dtype=np.float64) - np.asarray(camera.eye, dtype=np.float64)
    return d / np.linalg.norm(d)


@njit(**_JIT)
def _depths(positions, tets, point, ortho):
    """Centroid depths: dot with the view direction `point` (ortho), or distance to the
    eye `point`."""
    out = np.empty(tets.shape[0])
    for i in range(tets.shape[0]):
        c = np.zeros(3)
        for k in range(3):
            c[k] = (positions[tets[i, 0], k] + positions[tets[i, 1], k]
                    + positions[tets[i, 2], k] + positions[tets[i, 3], k]) / 4.0
        if ortho:
            out[i] = c[0] * point[0] + c[1] * point[1] + c[2] * point[2]
        else:
            d0, d1, d2 = c[0] - point[0], c[1] - point[1], c[2] - point[2]
            out[i] = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
    return out


def _by_depth(depth: np.ndarray) -> np.ndarray:
    """(T,) int32 indices by increasing depth, ties by index: a stable argsort, done as the
    (much faster) unstable one followed by sorting each run of equal depths by index."""
    order = np.argsort(depth, kind="quicksort").astype(np.int32)
    _stabilize(depth, order)
    return order


@njit(**_JIT)
def _stabilize(keys, order):
    """Sort every run of equal keys (NaNs count as equal) in `order` by index, in place."""
    n = order.shape[0]
    i = 0
    while i < n:
        j = i + 1
        ki = keys[order[i]]
        while j < n and (keys[order[j]] == ki or (ki != ki and keys[order[j]] != keys[order[j]])):
            j += 1
        if j - i > 1:
            order[i:j] = np.sort(order[i:j])
        i = j


# --------------------------------------------------------------------------- step 1


def adjacent_relations(shell, camera) -> tuple[np.ndarray, np.ndarray]:
    """(src, dst) int32: order every pair of face neighbours (step 1): the cell whose copy
    of the shared face is back-facing is in front. Edge-on faces (no ray crosses them) give
    nothing."""
    cells = order_cells(shell)
    if camera.orthographic:
        point, tol = _forward(camera), 1e-12
    else:
        point, tol = np.asarray(camera.eye, dtype=np.float64), 1e-12 * cells.scale
    src = np.empty(len(cells.pair_tet), np.int32)
    dst = np.empty(len(cells.pair_tet), np.int32)
    n = _adjacent(cells.pair_tet, cells.pair_other, cells.pair_plane, point,
                  bool(camera.orthographic), tol, src, dst)
    return src[:n], dst[:n]


@njit(**_JIT)
def _adjacent(tet, other, plane, point, ortho, tol, src, dst):
    """Writes the relation of each face pair (facing > 0: the face is front-facing for
    `tet`, so `other` is in front); returns how many."""
    n = 0
    for k in range(tet.shape[0]):
        if ortho:
            facing = -(plane[k, 0] * point[0] + plane[k, 1] * point[1] + plane[k, 2] * point[2])
        else:
            facing = plane[k, 0] * point[0] + plane[k, 1] * point[1] \
                + plane[k, 2] * point[2] + plane[k, 3]
        if facing < -tol:
            src[n], dst[n] = tet[k], other[k]
            n += 1
        elif facing > tol:
            src[n], dst[n] = other[k], tet[k]
            n += 1
    return n


# --------------------------------------------------------------------------- step 2


def abuffer_size(camera, resolution: int) -> tuple[int, int]:
    """(width, height) of the A-buffer: `resolution` on the longer side, same aspect."""
    w, h = camera.size
    scale = resolution / max(w, h)
    return max(1, round(w * scale)), max(1, round(h * scale))


def abuffer_relations(shell, camera, resolution: int) -> tuple[np.ndarray, np.ndarray]:
    """(src, dst) int32 relations along the A-buffer's sample rays between consecutive
    boundary faces (step 2), which link cells across the gaps of a non-convex shell.
    A relation may come more than once (from several rays)."""
    cells = order_cells(shell)
    width, height = abuffer_size(camera, resolution)
    mvp = np.asarray(camera.proj, dtype=np.float64) @ np.asarray(camera.view, dtype=np.float64)
    screen, front = _project(np.ascontiguousarray(shell.positions, dtype=np.float64), mvp,
                             width, height)
    origins, dirs, shortest = _pixel_rays(np.linalg.inv(mvp), width, height)
    starts, faces, t = _rasterize(screen, front, cells.face_vertices, cells.face_plane,
                                  origins, dirs, width, height)
    tie = TIE * cells.scale / max(shortest, 1e-300)
    return _ray_edges(starts, faces, t, cells.face_tet, tie)


@njit(**_JIT)
def _project(positions, m, width, height):
    """(V, 2) A-buffer pixel coordinates (x right, y down) of every shell vertex and (V,)
    bool: in front of the eye (w > 0). Shared vertices of neighbouring faces get the same
    coordinates, so the inclusive coverage test below leaves no crack between them."""
    n = positions.shape[0]
    screen = np.empty((n, 2))
    front = np.empty(n, np.bool_)
    for i in range(n):
        x, y, z = positions[i, 0], positions[i, 1], positions[i, 2]
        cx = m[0, 0] * x + m[0, 1] * y + m[0, 2] * z + m[0, 3]
        cy = m[1, 0] * x + m[1, 1] * y + m[1, 2] * z + m[1, 3]
        w = m[3, 0] * x + m[3, 1] * y + m[3, 2] * z + m[3, 3]
        front[i] = w > 0
        if not w > 0:
            w = 1.0
        screen[i, 0] = (cx / w + 1.0) * 0.5 * width
        screen[i, 1] = (1.0 - cy / w) * 0.5 * height
    return screen, front


@njit(**_JIT)
def _pixel_rays(inv, width, height):
    """Per pixel (row-major, rows top down) the world point of its ray on the near plane
    and the vector to the far plane ((H * W, 3) each), as `camera.pixel_segments`; and the
    shortest such vector's length (for the tie tolerance)."""
    origins = np.empty((height * width, 3))
    dirs = np.empty((height * width, 3))
    shortest = np.inf
    ends = np.empty((2, 3))
    for r in range(height):
        ny = 1.0 - 2.0 * (r + 0.5) / height
        for c in range(width):
            nx = 2.0 * (c + 0.5) / width - 1.0
            for e in range(2):
                nz = -1.0 if e == 0 else 1.0
                hw = inv[3, 0] * nx + inv[3, 1] * ny + inv[3, 2] * nz + inv[3, 3]
                for k in range(3):
                    ends[e, k] = (inv[k, 0] * nx + inv[k, 1] * ny + inv[k, 2] * nz
                                  + inv[k, 3]) / hw
            length = 0.0
            p = r * width + c
            for k in range(3):
                origins[p, k] = ends[0, k]
                dirs[p, k] = ends[1, k] - ends[0, k]
                length += dirs[p, k] * dirs[p, k]
            shortest = min(shortest, np.sqrt(length))
    return origins, dirs, shortest


@njit(**_JIT)
def _covered(screen, front, corners, h, w):
    """Per face, its three screen corners, the pixel box it may cover (empty when a corner
    is behind the eye or the face is edge-on) and its signed doubled area."""
    n = corners.shape[0]
    tri = np.empty((n, 3, 2))
    box = np.zeros((n, 4), np.int32)
    area = np.zeros(n)
    for i in range(n):
        for k in range(3):
            tri[i, k, 0] = screen[corners[i, k], 0]
            tri[i, k, 1] = screen[corners[i, k], 1]
        box[i, 1] = -1  # empty column range unless set below
        if not (front[corners[i, 0]] and front[corners[i, 1]] and front[corners[i, 2]]):
            continue
        x0, y0 = tri[i, 0, 0], tri[i, 0, 1]
        x1, y1 = tri[i, 1, 0], tri[i, 1, 1]
        x2, y2 = tri[i, 2, 0], tri[i, 2, 1]
        a = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)
        if abs(a) < 1e-12:
            continue  # edge-on: its neighbours on the boundary cover those rays
        area[i] = a
        box[i, 0] = max(0, int(np.ceil(min(x0, x1, x2) - 0.5)))
        box[i, 1] = min(w - 1, int(np.floor(max(x0, x1, x2) - 0.5)))
        box[i, 2] = max(0, int(np.ceil(min(y0, y1, y2) - 0.5)))
        box[i, 3] = min(h - 1, int(np.floor(max(y0, y1, y2) - 0.5)))
    return tri, box, area


@njit(inline="always", **_JIT)
def _edge(tri, i, a, b, x, y):
    """Doubled signed area of (corner a, corner b, sample) of triangle i (exactly the
    negative of (b, a, sample): the two faces on an edge agree on which side it is)."""
    return (tri[i, a, 0] - x) * (tri[i, b, 1] - y) - (tri[i, b, 0] - x) * (tri[i, a, 1] - y)


@njit(inline="always", **_JIT)
def _inside(tri, i, area, x, y):
    """Whether sample (x, y) is inside or on triangle i (inclusive: ties are layered)."""
    e0 = _edge(tri, i, 1, 2, x, y)
    e1 = _edge(tri, i, 2, 0, x, y)
    e2 = _edge(tri, i, 0, 1, x, y)
    if area > 0:
        return e0 >= 0 and e1 >= 0 and e2 >= 0
    return e0 <= 0 and e1 <= 0 and e2 <= 0


@njit(**_JIT)
def _rasterize(screen, front, corners, planes, origins, dirs, w, h):
    """The A-buffer of w x h pixels (rays: (P, 3) `origins` and `dirs`, row-major): per
    pixel the boundary faces covering its sample, sorted by the ray parameter of the exact
    ray-plane hit (ties by face). Returns (starts (P+1,), faces, t): pixel p's list is
    faces[starts[p]:starts[p + 1]]."""
    tri, box, area = _covered(screen, front, corners, h, w)
    pixels, face_end, starts = _cover(tri, box, area, h, w)
    fill = starts[:-1].copy()
    faces = np.empty(starts[-1], np.int32)
    t = np.empty(starts[-1])
    _hits(pixels, face_end, planes, origins, dirs, fill, faces, t)
    for p in range(h * w):
        _sort_hits(t, faces, starts[p], starts[p + 1])
    return starts, faces, t


@njit(**_JIT)
def _cover(tri, box, area, h, w):
    """The covered samples, face by face (the only pass that runs the coverage test):
    (pixels of face i at pixels[face_end[i - 1]:face_end[i]], face_end, starts: the
    prefix sums of the per-pixel counts, the A-buffer's layout). Branch-free: every
    sample of a box is written, and kept (the count advanced) when covered."""
    pixels = np.empty(max(16, 2 * tri.shape[0]), np.int32)
    face_end = np.empty(tri.shape[0], np.int64)
    starts = np.zeros(h * w + 1, np.int64)
    n = 0
    for i in range(tri.shape[0]):
        for r in range(box[i, 2], box[i, 3] + 1):
            if n + w > pixels.shape[0]:  # grow: fragments are not known in advance
                more = np.empty(2 * pixels.shape[0] + w, np.int32)
                more[:n] = pixels[:n]
                pixels = more
            for c in range(box[i, 0], box[i, 1] + 1):
                hit = _inside(tri, i, area[i], c + 0.5, r + 0.5)
                pixels[n] = r * w + c
                n += hit
                starts[r * w + c + 1] += hit
        face_end[i] = n
    for p in range(h * w):
        starts[p + 1] += starts[p]
    return pixels, face_end, starts


@njit(**_JIT)
def _hits(pixels, face_end, planes, origins, dirs, cursor, faces, t):
    """Stores every covered sample's face and ray parameter (exact ray-plane hit) at its
    pixel's `cursor` and advances it."""
    k = 0
    for i in range(face_end.shape[0]):
        while k < face_end[i]:
            p = pixels[k]
            den = planes[i, 0] * dirs[p, 0] + planes[i, 1] * dirs[p, 1] \
                + planes[i, 2] * dirs[p, 2]
            num = planes[i, 0] * origins[p, 0] + planes[i, 1] * origins[p, 1] \
                + planes[i, 2] * origins[p, 2] + planes[i, 3]
            faces[cursor[p]] = i
            t[cursor[p]] = -num / den if den != 0 else np.inf
            cursor[p] += 1
            k += 1


@njit(**_JIT)
def _sort_hits(t, faces, lo, hi):
    """Insertion sort of one pixel's list by (t, face): a few faces per pixel."""
    for k in range(lo + 1, hi):
        tk, fk, j = t[k], faces[k], k - 1
        while j >= lo and (t[j] > tk or (t[j] == tk and faces[j] > fk)):
            t[j + 1], faces[j + 1] = t[j], faces[j]
            j -= 1
        t[j + 1], faces[j + 1] = tk, fk


@njit(**_JIT)
def _ray_edges(starts, faces, t, tets, tie):
    """(src, dst) int32 relations between consecutive depth layers of each pixel's list
    (faces closer than `tie` form one layer). A relation found in a small table of the
    recent ones (the same gap seen by the neighbouring pixels) is not repeated; the graph
    drops the remaining repeats."""
    n = _layer_pairs(starts, faces, t, tets, tie, np.empty(0, np.int32),
                     np.empty(0, np.int32), False)
    src, dst = np.empty(n, np.int32), np.empty(n, np.int32)
    _layer_pairs(starts, faces, t, tets, tie, src, dst, True)
    return src, dst


@njit(**_JIT)
def _layer_pairs(starts, faces, t, tets, tie, src, dst, write):
    """One pass for `_ray_edges`: returns how many relations, writes them when `write`."""
    n = 0
    recent = np.full(_RECENT, -1, np.int64)  # direct-mapped: same decisions in both passes
    for p in range(starts.shape[0] - 1):
        if starts[p + 1] - starts[p] < 2:
            continue  # a ray meeting fewer than two faces relates nothing
        prev_lo, prev_hi = -1, -1
        k = starts[p]
        while k < starts[p + 1]:
            hi = k + 1
            while hi < starts[p + 1] and t[hi] - t[hi - 1] <= tie:
                hi += 1
            if prev_lo >= 0:
                for a in range(prev_lo, prev_hi):
                    for b in range(k, hi):
                        ta, tb = tets[faces[a]], tets[faces[b]]
                        key = (np.int64(ta) << 32) | tb
                        slot = (ta * 40503 + tb) & (_RECENT - 1)
                        if ta != tb and recent[slot] != key:
                            recent[slot] = key
                            if write:
                                src[n], dst[n] = ta, tb
                            n += 1
            prev_lo, prev_hi = k, hi
            k = hi
    return n


# --------------------------------------------------------------------------- step 3


def topological_order(by_depth: np.ndarray, *relations) -> tuple[np.ndarray, int, int]:
    """Order the nodes so that every relation src -> dst (src first) holds, by a depth-first
    traversal (reverse post-order); returns (order (count,) int32, relations dropped to
    break cycles, distinct relations).

    by_depth: (count,) the nodes nearest first, ties by index: roots and successors are
    visited in that order, so the result, dropped edges included, is deterministic and
    unconstrained nodes come out nearest first. relations: one or two (src, dst) lists
    (two are read as they are, not concatenated). Repeated relations count once and a node
    is not in front of itself (src == dst is ignored).
    """
    by_depth = np.ascontiguousarray(by_depth, dtype=np.int32)
    empty = np.empty(0, np.int32)
    lists = [tuple(np.ascontiguousarray(x, dtype=np.int32) for x in pair) for pair in relations]
    (a_src, a_dst), (b_src, b_dst) = lists + [(empty, empty)] * (2 - len(lists))
    offsets, targets = _rank_graph(by_depth, a_src, a_dst, b_src, b_dst)
    post, broken = _dfs(offsets, targets)
    return _from_ranks(by_depth, post), int(broken), int(offsets[-1])


@njit(**_JIT)
def _rank_graph(by_depth, a_src, a_dst, b_src, b_dst):
    """The relations as a CSR graph over ranks (rank r is node by_depth[r]): (offsets,
    targets), each node's successors by decreasing rank, without repeats or self loops."""
    count = by_depth.shape[0]
    rank = np.empty(count, np.int32)
    for r in range(count):
        rank[by_depth[r]] = r
    offsets = np.zeros(count + 1, np.int64)
    _scatter(rank, a_src, a_dst, offsets[1:], offsets[:0], False)
    _scatter(rank, b_src, b_dst, offsets[1:], offsets[:0], False)
    for v in range(count):
        offsets[v + 1] += offsets[v]
    targets = np.empty(offsets[count], np.int32)
    fill = offsets[:-1].copy()
    _scatter(rank, a_src, a_dst, fill, targets, True)
    _scatter(rank, b_src, b_dst, fill, targets, True)
    _dedupe(offsets, targets)
    return offsets, targets


@njit(**_JIT)
def _scatter(rank, src, dst, cursor, targets, write):
    """Counting sort by source rank: counts each relation into `cursor` or (`write`)
    stores its target's rank at `cursor` and advances it; self loops are skipped."""
    for k in range(src.shape[0]):
        if src[k] != dst[k]:
            v = rank[src[k]]
            if write:
                targets[cursor[v]] = rank[dst[k]]
            cursor[v] += 1


@njit(**_JIT)
def _dedupe(offsets, targets):
    """Sort each node's successors by decreasing rank and drop repeats, compacting the CSR
    arrays in place (the write position never passes the read position)."""
    out = 0
    lo = offsets[0]
    for v in range(offsets.shape[0] - 1):
        hi = offsets[v + 1]
        if hi - lo <= _INSERTION:
            _sort_descending(targets, lo, hi)
        else:
            targets[lo:hi] = np.sort(targets[lo:hi])[::-1]
        offsets[v] = out
        for k in range(lo, hi):
            if k == lo or targets[k] != targets[k - 1]:
                targets[out] = targets[k]
                out += 1
        lo = hi
    offsets[offsets.shape[0] - 1] = out


@njit(**_JIT)
def _sort_descending(a, lo, hi):
    """Insertion sort of a[lo:hi], largest first."""
    for k in range(lo + 1, hi):
        x, j = a[k], k - 1
        while j >= lo and a[j] < x:
            a[j + 1] = a[j]
            j -= 1
        a[j + 1] = x


@njit(**_JIT)
def _dfs(offsets, targets):
    """Iterative depth-first post-order over a CSR graph, roots by decreasing node number
    (farthest first); counts back edges (relations that close a cycle)."""
    count = offsets.shape[0] - 1
    state = np.zeros(count, np.int8)  # 0 new, 1 on the stack, 2 done
    nxt = offsets[:-1].copy()
    stack = np.empty(count, np.int32)
    post = np.empty(count, np.int32)
    n_post, broken = 0, 0
    for root in range(count - 1, -1, -1):
        if state[root] != 0:
            continue
        top = 0
        stack[0] = root
        state[root] = 1
        while top >= 0:
            v = stack[top]
            if nxt[v] < offsets[v + 1]:
                u = targets[nxt[v]]
                nxt[v] += 1
                if state[u] == 0:
                    state[u] = 1
                    top += 1
                    stack[top] = u
                elif state[u] == 1:
                    broken += 1  # back edge: it closes a cycle
            else:
                state[v] = 2
                post[n_post] = v
                n_post += 1
                top -= 1
    return post, broken


@njit(**_JIT)
def _from_ranks(by_depth, post):
    """The order: the reverse post-order, ranks mapped back to nodes."""
    n = post.shape[0]
    order = np.empty(n, np.int32)
    for k in range(n):
        order[k] = by_depth[post[n - 1 - k]]
    return order
