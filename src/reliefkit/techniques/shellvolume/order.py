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

`method="centroid"` sorts by the centroids' distance from the eye (along the view
direction for orthographic cameras): the cheap, approximate baseline.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np
from numba import njit

from ...errors import UsageError
from ...scene.camera import pixel_segments

#: Methods `visibility_order` knows.
METHODS = ("sxmpvo", "centroid")

#: Default A-buffer samples along the image's longer side.
RESOLUTION = 256

#: Distances along a ray closer than this times the shell's size are the same point.
TIE = 1e-9

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
    """Sort `shell`'s tetrahedra front to back as seen by `camera` (Camera or MatrixCamera).

    resolution: A-buffer samples along the longer image side (SXMPVO only).
    """
    if method not in METHODS:
        raise UsageError(f"method must be one of {', '.join(METHODS)}, got {method!r}")
    if int(resolution) != resolution or resolution < 1:
        raise UsageError(f"resolution must be a positive integer, got {resolution!r}")
    start = time.perf_counter()
    depth = centroid_depths(shell, camera)
    if method == "centroid":
        order = np.argsort(depth, kind="stable").astype(np.int32)
        return VisibilityOrder(order, 0, 0, time.perf_counter() - start, method)
    src, dst = _relations(shell, camera, int(resolution))
    order, broken = topological_order(len(shell.tets), src, dst, depth)
    return VisibilityOrder(order, broken, len(src), time.perf_counter() - start, method)


def centroid_depths(shell, camera) -> np.ndarray:
    """(T,) float64 depth of each centroid: distance from the eye, or along the view
    direction for orthographic cameras (smaller is nearer)."""
    centroids = shell.tetrahedra().mean(axis=1)
    if camera.orthographic:
        return centroids @ _forward(camera)
    return np.linalg.norm(centroids - np.asarray(camera.eye, dtype=np.float64), axis=1)


def _forward(camera) -> np.ndarray:
    """Unit view direction (eye towards scene) of an orthographic camera."""
    if hasattr(camera, "view_dir"):  # MatrixCamera: view_dir points scene -> viewer
        d = -np.asarray(camera.view_dir, dtype=np.float64)
    else:
        d = np.asarray(camera.target, dtype=np.float64) - np.asarray(camera.eye, dtype=np.float64)
    return d / np.linalg.norm(d)


def _scale(shell) -> float:
    """Size of the shell, for tolerances."""
    p = shell.positions
    return float(np.linalg.norm(p.max(axis=0) - p.min(axis=0))) or 1.0


def _relations(shell, camera, resolution: int) -> tuple[np.ndarray, np.ndarray]:
    """Distinct (src, dst) int64 pairs "src in front of dst": adjacency plus A-buffer."""
    a_src, a_dst = adjacent_relations(shell, camera)
    g_src, g_dst = abuffer_relations(shell, camera, resolution)
    src = np.concatenate([a_src, g_src])
    dst = np.concatenate([a_dst, g_dst])
    keep = src != dst
    key = np.unique(src[keep] * len(shell.tets) + dst[keep])
    return key // len(shell.tets), key % len(shell.tets)


def adjacent_relations(shell, camera) -> tuple[np.ndarray, np.ndarray]:
    """Order every pair of face neighbours (step 1): the cell whose copy of the shared
    face is back-facing is in front. Edge-on faces (no ray crosses them) give nothing."""
    tet, face = np.nonzero(shell.neighbors >= 0)
    other = shell.neighbors[tet, face].astype(np.int64)
    once = tet < other
    tet, face, other = tet[once], face[once], other[once]
    plane = shell.planes[tet, face]
    if camera.orthographic:
        facing = -(plane[:, :3] @ _forward(camera))  # > 0: front-facing
        tol = 1e-12
    else:
        facing = plane[:, :3] @ np.asarray(camera.eye, dtype=np.float64) + plane[:, 3]
        tol = 1e-12 * _scale(shell)
    back = facing < -tol
    front = facing > tol
    src = np.concatenate([tet[back], other[front]])
    dst = np.concatenate([other[back], tet[front]])
    return src.astype(np.int64), dst.astype(np.int64)


def abuffer_size(camera, resolution: int) -> tuple[int, int]:
    """(width, height) of the A-buffer: `resolution` on the longer side, same aspect."""
    w, h = camera.size
    scale = resolution / max(w, h)
    return max(1, round(w * scale)), max(1, round(h * scale))


def abuffer_relations(shell, camera, resolution: int) -> tuple[np.ndarray, np.ndarray]:
    """Relations along the A-buffer's sample rays between consecutive boundary faces
    (step 2), which link cells across the gaps of a non-convex shell."""
    width, height = abuffer_size(camera, resolution)
    near, far = pixel_segments(SimpleNamespace(view=camera.view, proj=camera.proj,
                                               size=(width, height)))
    faces = shell.boundary_faces()
    tets = faces[:, 0].astype(np.int64)
    planes = np.ascontiguousarray(shell.planes[faces[:, 0], faces[:, 1]])
    corner_ids = _face_corners(shell.tets[faces[:, 0]], faces[:, 1])
    screen, valid = _project(shell.positions[corner_ids], camera, width, height)
    starts, entries, t = _rasterize(screen, valid, planes, np.ascontiguousarray(near),
                                    np.ascontiguousarray(far - near))
    tie = TIE * _scale(shell) / max(float(np.linalg.norm(far - near, axis=-1).min()), 1e-300)
    count = _ray_edges(starts, entries, t, tets, tie, np.empty(0, np.int64),
                       np.empty(0, np.int64), False)
    src, dst = np.empty(count, np.int64), np.empty(count, np.int64)
    _ray_edges(starts, entries, t, tets, tie, src, dst, True)
    return src, dst


def _face_corners(tet_vertices: np.ndarray, face: np.ndarray) -> np.ndarray:
    """(N, 3) vertex indices of face f (the three vertices other than f) of each tet."""
    others = np.array([[v for v in range(4) if v != f] for f in range(4)])
    return np.take_along_axis(tet_vertices, others[face], axis=1)


def _project(points: np.ndarray, camera, width: int, height: int):
    """(N, 3, 2) A-buffer pixel coordinates (x right, y down) of (N, 3, 3) world points and
    (N,) bool: all three in front of the eye (w > 0)."""
    m = np.asarray(camera.proj) @ np.asarray(camera.view)
    clip = points @ m[:3, :3].T + m[:3, 3]
    w = points @ m[3, :3] + m[3, 3]
    valid = (w > 0).all(axis=1)
    w = np.where(w > 0, w, 1.0)
    screen = np.empty(points.shape[:2] + (2,))
    screen[..., 0] = (clip[..., 0] / w + 1.0) * 0.5 * width
    screen[..., 1] = (1.0 - clip[..., 1] / w) * 0.5 * height
    return np.ascontiguousarray(screen), valid


@njit(**_JIT)
def _covered(screen, valid, h, w):
    """Per face, the pixel box it may cover (or an empty box) and its signed doubled area."""
    n = screen.shape[0]
    box = np.zeros((n, 4), np.int64)
    area = np.zeros(n)
    for i in range(n):
        box[i, 1] = -1  # empty column range unless set below
        if not valid[i]:
            continue
        x0, y0 = screen[i, 0, 0], screen[i, 0, 1]
        x1, y1 = screen[i, 1, 0], screen[i, 1, 1]
        x2, y2 = screen[i, 2, 0], screen[i, 2, 1]
        a = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)
        if abs(a) < 1e-12:
            continue  # edge-on: its neighbours on the boundary cover those rays
        area[i] = a
        box[i, 0] = max(0, int(np.ceil(min(x0, x1, x2) - 0.5)))
        box[i, 1] = min(w - 1, int(np.floor(max(x0, x1, x2) - 0.5)))
        box[i, 2] = max(0, int(np.ceil(min(y0, y1, y2) - 0.5)))
        box[i, 3] = min(h - 1, int(np.floor(max(y0, y1, y2) - 0.5)))
    return box, area


@njit(inline="always", **_JIT)
def _edge(screen, i, a, b, x, y):
    """Doubled signed area of (corner a, corner b, sample) of triangle i."""
    return (screen[i, a, 0] - x) * (screen[i, b, 1] - y) \
        - (screen[i, b, 0] - x) * (screen[i, a, 1] - y)


@njit(inline="always", **_JIT)
def _inside(screen, i, area, x, y):
    """Whether sample (x, y) is inside or on triangle i (inclusive: ties are layered)."""
    e0 = _edge(screen, i, 1, 2, x, y)
    e1 = _edge(screen, i, 2, 0, x, y)
    e2 = _edge(screen, i, 0, 1, x, y)
    if area > 0:
        return e0 >= 0 and e1 >= 0 and e2 >= 0
    return e0 <= 0 and e1 <= 0 and e2 <= 0


@njit(**_JIT)
def _rasterize(screen, valid, planes, origins, dirs):
    """The A-buffer: per pixel (row-major) the boundary faces covering its sample, sorted
    by the ray parameter of the exact ray-plane hit. Returns (starts (P+1,), faces, t)."""
    h, w = origins.shape[0], origins.shape[1]
    box, area = _covered(screen, valid, h, w)
    counts = np.zeros(h * w, np.int64)
    faces = np.empty(0, np.int64)
    t = np.empty(0)
    _scan(screen, box, area, planes, origins, dirs, counts, faces, t, False)
    starts = np.zeros(h * w + 1, np.int64)
    for p in range(h * w):
        starts[p + 1] = starts[p] + counts[p]
    fill = starts[:-1].copy()
    faces = np.empty(starts[-1], np.int64)
    t = np.empty(starts[-1])
    _scan(screen, box, area, planes, origins, dirs, fill, faces, t, True)
    for p in range(h * w):  # insertion sort: a few faces per pixel
        for k in range(starts[p] + 1, starts[p + 1]):
            tk, fk, j = t[k], faces[k], k - 1
            while j >= starts[p] and (t[j] > tk or (t[j] == tk and faces[j] > fk)):
                t[j + 1], faces[j + 1] = t[j], faces[j]
                j -= 1
            t[j + 1], faces[j + 1] = tk, fk
    return starts, faces, t


@njit(**_JIT)
def _scan(screen, box, area, planes, origins, dirs, cursor, faces, t, write):
    """One pass over the covered samples: counts per pixel into `cursor`, or (`write`)
    stores the face and its ray parameter at `cursor` and advances it."""
    w = origins.shape[1]
    for i in range(screen.shape[0]):
        for r in range(box[i, 2], box[i, 3] + 1):
            for c in range(box[i, 0], box[i, 1] + 1):
                if not _inside(screen, i, area[i], c + 0.5, r + 0.5):
                    continue
                p = r * w + c
                if write:
                    den = planes[i, 0] * dirs[r, c, 0] + planes[i, 1] * dirs[r, c, 1] \
                        + planes[i, 2] * dirs[r, c, 2]
                    num = planes[i, 0] * origins[r, c, 0] + planes[i, 1] * origins[r, c, 1] \
                        + planes[i, 2] * origins[r, c, 2] + planes[i, 3]
                    faces[cursor[p]] = i
                    t[cursor[p]] = -num / den if den != 0 else np.inf
                cursor[p] += 1


@njit(**_JIT)
def _ray_edges(starts, faces, t, tets, tie, src, dst, write):
    """Relations between consecutive depth layers of each pixel's list (faces closer than
    `tie` form one layer); writes them when `write`, returns how many there are."""
    n = 0
    for p in range(starts.shape[0] - 1):
        prev_lo, prev_hi = -1, -1
        k = starts[p]
        while k < starts[p + 1]:
            hi = k + 1
            while hi < starts[p + 1] and t[hi] - t[hi - 1] <= tie:
                hi += 1
            if prev_lo >= 0:
                for a in range(prev_lo, prev_hi):
                    for b in range(k, hi):
                        if tets[faces[a]] != tets[faces[b]]:
                            if write:
                                src[n] = tets[faces[a]]
                                dst[n] = tets[faces[b]]
                            n += 1
            prev_lo, prev_hi = k, hi
            k = hi
    return n


def topological_order(count: int, src: np.ndarray, dst: np.ndarray,
                      depth: np.ndarray) -> tuple[np.ndarray, int]:
    """Order `count` nodes so that every relation src -> dst (src first) holds, by a
    depth-first traversal (reverse post-order). Relations closing a cycle are dropped;
    returns (order (count,) int32, how many were dropped). Roots and successors are
    visited by `depth` (then index), so the result, dropped edges included, is
    deterministic and unconstrained nodes come out nearest first."""
    src = np.asarray(src, dtype=np.int64)
    dst = np.asarray(dst, dtype=np.int64)
    rank = np.empty(count, np.int64)
    rank[np.argsort(depth, kind="stable")] = np.arange(count)
    # successors sorted by decreasing rank: the nearest successor finishes last
    by = np.lexsort((-rank[dst], src))
    src, dst = src[by], dst[by]
    offsets = np.zeros(count + 1, np.int64)
    np.add.at(offsets, src + 1, 1)
    offsets = np.cumsum(offsets)
    roots = np.argsort(-rank, kind="stable").astype(np.int64)  # farthest first
    post, broken = _dfs(offsets, dst, roots)
    return post[::-1].astype(np.int32).copy(), int(broken)


@njit(**_JIT)
def _dfs(offsets, targets, roots):
    """Iterative depth-first post-order over a CSR graph; counts back edges."""
    count = offsets.shape[0] - 1
    state = np.zeros(count, np.int8)  # 0 new, 1 on the stack, 2 done
    nxt = offsets[:-1].copy()
    stack = np.empty(count, np.int64)
    post = np.empty(count, np.int64)
    n_post, broken = 0, 0
    for root in roots:
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
