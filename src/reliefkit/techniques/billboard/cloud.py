"""The billboard cloud generator of Décoret, Durand, Sillion & Dorsey 2003.

A billboard cloud replaces a mesh by textured rectangles: every triangle is assigned to a plane
that all its vertices are within epsilon of. The planes are picked greedily from a density over
plane space (theta, phi, rho): a face adds its projected area to every plane valid for it, and
planes that "miss" faces (the face would be valid if the plane moved outwards by less than
epsilon) are penalized, which favours planes nearly tangent to the model. The densest bin is
refined, refitted to its faces, those faces are removed from the density, and so on.

Plane space: unit normals on the upper hemisphere (a plane and its flipped copy are one plane),
rho = the signed distance of the plane from the bounding-box centre along the normal.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ...errors import UsageError
from ...scene.mesh import RenderMesh
from .rectangles import min_area_rectangle, plane_basis

PENALTY_WEIGHT = 10.0   # w_penalty of Décoret et al. 2003, section 4.2
_SLACK = 1e-9            # relative safety margin so that rounding never breaks validity


@dataclass(frozen=True, eq=False)
class BillboardPlane:
    """One billboard: its plane {x : normal . x = offset} (world), faces and rectangle.

    The rectangle is corner + s*u_axis + t*v_axis, s, t in [0, 1]; cross(u_axis, v_axis) points
    along `normal`, which faces the same way as the assigned faces (area-weighted). Its texture
    is `resolution` = (W, H) texels of the plan's texel size.
    """

    normal: np.ndarray
    offset: float
    faces: np.ndarray
    corner: np.ndarray
    u_axis: np.ndarray
    v_axis: np.ndarray
    resolution: tuple[int, int]

    def world_to_plane(self, points) -> np.ndarray:
        """(..., 3) world points -> (..., 3) of (s, t, signed distance to the plane)."""
        rel = np.asarray(points, dtype=np.float64) - self.corner
        s = rel @ self.u_axis / (self.u_axis @ self.u_axis)
        t = rel @ self.v_axis / (self.v_axis @ self.v_axis)
        return np.stack([s, t, rel @ self.normal], axis=-1)

    def plane_to_world(self, coords) -> np.ndarray:
        """The inverse of `world_to_plane`: (..., 3) of (s, t, distance) -> world points."""
        c = np.asarray(coords, dtype=np.float64)
        return (self.corner + c[..., :1] * self.u_axis + c[..., 1:2] * self.v_axis
                + c[..., 2:3] * self.normal)


@dataclass(frozen=True, eq=False)
class BillboardCloudPlan:
    """The planes of a billboard cloud and which plane each triangle went to.

    `face_plane[f]` is the index of the plane of triangle f, -1 for the `skipped` ones (only
    when `max_planes` stopped the selection; `skipped_reason` says so). `epsilon` and
    `texel_size` are world lengths, `epsilon_fraction` the requested fraction of the diagonal.
    """

    planes: tuple[BillboardPlane, ...]
    epsilon: float
    epsilon_fraction: float
    texel_size: float
    face_plane: np.ndarray
    skipped: np.ndarray
    seconds: float
    skipped_reason: str | None = field(default=None)

    def summary(self) -> dict:
        """Plane and face counts, what was skipped and why, and texture size (not the time:
        the summary goes into the file, which depends only on the bake's inputs)."""
        return {
            "planes": len(self.planes),
            "faces_per_plane": [int(len(p.faces)) for p in self.planes],
            "skipped": int(len(self.skipped)),
            "skipped_reason": self.skipped_reason,
            "texels": int(sum(p.resolution[0] * p.resolution[1] for p in self.planes)),
        }


def build_billboard_cloud(mesh: RenderMesh, epsilon: float = 0.05, max_planes: int | None = None,
                          texel_size: float | None = None, progress=None, *,
                          direction_step: float | None = None, rho_step: float = 0.5,
                          penalty_weight: float = PENALTY_WEIGHT) -> BillboardCloudPlan:
    """Greedy billboard cloud of `mesh` with every face within epsilon of its plane.

    epsilon is a fraction of the bounding-box diagonal; texel_size (world) defaults to
    diagonal / 256. The plane-space resolution: direction bins `direction_step` radians apart
    (default 2 * epsilon, which moves a point at half a diagonal by about epsilon / 2 from the
    bin centre, kept in [0.03, 0.2]) and rho bins `rho_step` * world epsilon wide.
    `progress(done, total)` hears how many faces are assigned.
    """
    start = time.perf_counter()
    diag = _diagonal(mesh)
    _check(epsilon, max_planes, texel_size, direction_step, rho_step, penalty_weight)
    eps = float(epsilon) * diag
    texel = diag / 256 if texel_size is None else float(texel_size)
    step = min(max(2 * float(epsilon), 0.03), 0.2) if direction_step is None else direction_step
    faces = _Faces(mesh, eps)
    grid = _Grid(faces, _hemisphere_directions(step), step, diag, rho_step * eps, penalty_weight)
    selector = _Selector(faces, grid)
    total = faces.count
    owner = np.full(total, -1, dtype=np.int32)
    found: list[tuple[np.ndarray, float, np.ndarray]] = []
    reason = None
    _report(progress, 0, total)
    while True:
        remaining = np.flatnonzero(owner < 0)
        if not remaining.size:
            break
        if max_planes is not None and len(found) >= max_planes:
            reason = (f"max_planes={max_planes} reached with {remaining.size} of {total} "
                      "faces unassigned")
            break
        normal, rho, members = selector.next_plane(remaining, owner, found)
        if members is None:  # only degenerate faces left, each joined an existing plane
            continue
        owner[members] = len(found)
        found.append((normal, rho, members))
        grid.remove(members, np.flatnonzero(owner < 0))
        _report(progress, total - int((owner < 0).sum()), total)
    planes = tuple(_billboard(faces, n, rho, m, texel) for n, rho, m in found)
    skipped = np.flatnonzero(owner < 0)
    return BillboardCloudPlan(planes, eps, float(epsilon), texel, owner, skipped,
                              time.perf_counter() - start, reason)


def _report(progress: Callable | None, done: int, total: int) -> None:
    if progress is not None:
        progress(done, total)


def _diagonal(mesh: RenderMesh) -> float:
    low, high = mesh.bounds
    diag = float(np.linalg.norm(high - low))
    if not diag > 0:
        raise UsageError(f"{mesh.name}: the mesh has no extent (all vertices coincide); "
                         "a billboard cloud needs a mesh with some size")
    return diag


def _check(epsilon, max_planes, texel_size, direction_step, rho_step, penalty_weight) -> None:
    def number(x) -> bool:
        return isinstance(x, int | float | np.floating | np.integer) and not isinstance(x, bool) \
            and math.isfinite(x)

    if not number(epsilon) or not 0 < epsilon <= 0.5:
        raise UsageError(f"epsilon must be a fraction of the diagonal in (0, 0.5], got {epsilon!r}")
    if max_planes is not None and (not isinstance(max_planes, int | np.integer)
                                   or isinstance(max_planes, bool) or max_planes < 1):
        raise UsageError(f"max_planes must be None or an integer >= 1, got {max_planes!r}")
    if texel_size is not None and (not number(texel_size) or texel_size <= 0):
        raise UsageError(f"texel_size must be None or a world length > 0, got {texel_size!r}")
    if direction_step is not None and (not number(direction_step)
                                       or not 0 < direction_step <= 0.5):
        raise UsageError(f"direction_step must be in (0, 0.5] radians, got {direction_step!r}")
    if not number(rho_step) or not 0 < rho_step <= 1:
        raise UsageError(f"rho_step must be in (0, 1] (a fraction of epsilon), got {rho_step!r}")
    if not number(penalty_weight) or penalty_weight < 0:
        raise UsageError(f"penalty_weight must be a number >= 0, got {penalty_weight!r}")


class _Faces:
    """Triangles relative to the bounding-box centre (float64), with areas and unit normals."""

    def __init__(self, mesh: RenderMesh, eps: float) -> None:
        self.centre = mesh.center
        points = mesh.world_positions - self.centre
        self.points, self.corners = points, mesh.indices.astype(np.int64)
        self.tri = points[self.corners]                                   # (F, 3, 3)
        cross = np.cross(self.tri[:, 1] - self.tri[:, 0], self.tri[:, 2] - self.tri[:, 0])
        twice = np.linalg.norm(cross, axis=1)
        self.area = twice / 2
        self.degenerate = twice <= 1e-12 * float(np.abs(points).max()) ** 2
        self.normal = np.where(self.degenerate[:, None], 0.0,
                               cross / np.maximum(twice, 1e-300)[:, None])
        self.count = len(self.tri)
        self.eps = eps
        self.check_eps = eps * (1 - _SLACK)

    def extent(self, idx: np.ndarray, normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Min and max vertex projection of faces idx on one direction."""
        return _min_max(self.tri[idx] @ normal)

    def valid(self, idx: np.ndarray, normal: np.ndarray, rho: float) -> np.ndarray:
        """The faces of idx whose three vertices are within epsilon of the plane."""
        low, high = self.extent(idx, normal)
        return idx[(high - rho <= self.check_eps) & (rho - low <= self.check_eps)]


def _min_max(proj: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Row minima and maxima of (n, 3) projections (elementwise: a reduction over an axis of
    length 3 is several times slower)."""
    a, b, c = proj.T
    return np.minimum(np.minimum(a, b), c), np.maximum(np.maximum(a, b), c)


def _hemisphere_directions(step: float) -> np.ndarray:
    """Unit normals with z >= 0 about `step` radians apart, in rings of constant polar angle.

    The pole and the equator are rings, and the equator only spans [0, pi) in azimuth (the
    other half are the same planes flipped), so the three axes are directions exactly.
    """
    rings = max(1, math.ceil(math.pi / 2 / step))
    dirs = [np.array([[0.0, 0.0, 1.0]])]
    for i in range(1, rings + 1):
        theta = i * math.pi / 2 / rings
        if i < rings:
            count = max(1, round(2 * math.pi * math.sin(theta) / step))
            phi = np.arange(count) * 2 * math.pi / count
        else:
            count = 2 * max(1, round(math.pi / 2 / step))
            phi = np.arange(count) * math.pi / count
        dirs.append(np.stack([math.sin(theta) * np.cos(phi), math.sin(theta) * np.sin(phi),
                              np.full(count, math.cos(theta))], axis=1))
    return np.concatenate(dirs)


class _Grid:
    """The density over (direction, rho) bins, kept as per-direction difference arrays so that
    adding or removing a face is four increments per direction (`density.add_faces`) and
    finding the densest bin one cumsum.

    A bin holds the plane through its centre rho; a face counts in the bins whose centre lies
    in its valid range. The grid has a spare bin below and above every possible range, so no
    index ever needs clipping.
    """

    def __init__(self, faces: _Faces, dirs: np.ndarray, step: float, diag: float, width: float,
                 penalty: float) -> None:
        self.faces, self.dirs, self.step, self.penalty = faces, dirs, step, penalty
        self.width, self.half_diag = width, diag / 2
        self.start = -(diag / 2 + 2 * faces.eps) - width                  # rho of bin 0
        self.bins = math.ceil(-2 * self.start / width) + 2
        self.first_outer = math.ceil(-self.start / width)                 # first bin, rho >= 0
        self.diff = np.zeros((len(dirs), self.bins + 1))
        # vertices in bin units (float32: only which bins, and exactly the same bins on
        # removal, matter); their projections are measured from bin 0
        self.point_bins = (faces.points / width).astype(np.float32)
        self.dirs32 = dirs.astype(np.float32)
        self._update(np.arange(faces.count), 1.0)

    def rho(self, k: int) -> float:
        return self.start + k * self.width

    def densest(self) -> tuple[int, int, float]:
        density = np.cumsum(self.diff[:, :-1], axis=1)
        flat = int(np.argmax(density))
        d, k = divmod(flat, self.bins)
        return d, k, float(density[d, k])

    def remove(self, idx: np.ndarray, rest: np.ndarray) -> None:
        """Take faces idx out of the density; `rest` are the faces still in it afterwards.

        Whichever is cheaper: subtract idx, or rebuild from rest (nothing at all for the last
        plane); both are deterministic, and a rebuild also clears the rounding residue.
        """
        idx, rest = (i[~self.faces.degenerate[i]] for i in (idx, rest))
        if len(rest) < len(idx):
            self.diff[:] = 0.0
            self._update(rest, 1.0)
        else:
            self._update(idx, -1.0)

    def _update(self, idx: np.ndarray, sign: float) -> None:
        """Add ``sign`` x the increments of faces idx (`density.add_faces`). Each distinct
        vertex is projected once per direction (neighbouring faces share them)."""
        from .density import add_faces  # numba: slow to import

        idx = idx[~self.faces.degenerate[idx]]        # zero area: no density, no penalty
        if not idx.size:
            return
        f = self.faces
        used, where = np.unique(f.corners[idx], return_inverse=True)
        eps = np.float32(f.eps / self.width)
        add_faces(self.diff, self.point_bins[used], where.reshape(-1, 3).astype(np.int64),
                  f.normal[idx].astype(np.float32), f.area[idx].astype(np.float32),
                  self.dirs32, eps, np.float32(2 * eps), np.float32(-self.start / self.width),
                  np.float32(self.first_outer), np.float32(self.penalty), float(sign))


class _Selector:
    """Picks the next plane: the densest bin, refined, refitted; or a fallback."""

    def __init__(self, faces: _Faces, grid: _Grid) -> None:
        self.faces, self.grid = faces, grid
        self.min_density = 1e-9 * float(faces.area.sum())  # below it: rounding residue only

    def next_plane(self, remaining, owner, found):
        """(normal, rho, members) of a new plane, or (None, None, None) when the remaining
        faces were all degenerate and joined planes already found (appended in place)."""
        live = remaining[~self.faces.degenerate[remaining]]
        if not live.size:
            return self._degenerate(remaining, owner, found)
        d, k, density = self.grid.densest()
        if density > self.min_density:
            normal, rho, members = self._settle(remaining, *self._refine(live, d, k))
            if self._score(members)[0] > 0:
                return normal, rho, members
        # the discretized optimum validates nothing: a face is always valid for its own plane
        return self._settle(remaining, *self._own_plane(live))

    def _refine(self, live, d, k) -> tuple[np.ndarray, float]:
        """Search the bin's neighbourhood: directions within one bin of its centre (5 x 5),
        then within a quarter bin of the best (3 x 3), each with its best rho found exactly by
        a sweep; ties keep the earlier candidate, the bin centre first."""
        g, f = self.grid, self.faces
        best_dir, best_rho, best = g.dirs[d], g.rho(k), -np.inf
        window = (best_rho - 2 * g.width, best_rho + 2 * g.width)
        reach = 2 * g.width + 1.5 * g.step * g.half_diag + f.eps
        low, high = f.extent(live, best_dir)
        near = live[(high >= best_rho - reach) & (low <= best_rho + reach)]
        near = (f.tri[near], f.normal[near], f.area[near])     # gathered once for 34 sweeps
        for spacing, reach, half in ((g.step / 2, 2, g.width), (g.step / 4, 1, g.width / 2)):
            for cand in _around(best_dir, spacing, reach):
                value, rho = self._best_rho(near, cand, window)
                if value > best:
                    best, best_dir, best_rho = value, cand, rho
            window = (best_rho - half, best_rho + half)
        return best_dir, best_rho

    def _best_rho(self, near, normal, window) -> tuple[float, float]:
        """The highest penalized density along rho within window, and the middle of its run.

        near = (triangles, unit normals, areas). The density is piecewise constant in rho:
        +gain on each face's valid range [lo, hi], -penalty * gain on its outer miss band; a
        sorted sweep finds its maximum exactly. Only the steps inside the window are sorted
        (those below it are summed into the starting value, those above it never matter).
        """
        tri, normals, area = near
        eps = self.faces.eps
        low, high = _min_max(tri @ normal)
        lo, hi = high - eps, low + eps
        ok = lo < hi
        lo, hi = lo[ok], hi[ok]
        gain = area[ok] * np.abs(normals[ok] @ normal)
        miss = self.grid.penalty * gain
        pos, neg = lo > 0, hi < 0
        at = np.concatenate([lo, hi, np.maximum(lo - eps, 0)[pos], lo[pos], hi[neg],
                             np.minimum(hi + eps, 0)[neg]])
        step = np.concatenate([gain, -gain, -miss[pos], miss[pos], -miss[neg], miss[neg]])
        inside = (at > window[0]) & (at < window[1])
        start = step[at <= window[0]].sum()
        at = np.concatenate([[window[0]], at[inside], [window[1]]])
        step = np.concatenate([[start], step[inside], [0.0]])
        order = np.argsort(at, kind="stable")
        at, value = at[order], np.cumsum(step[order])[:-1]
        runs = np.flatnonzero(at[1:] > at[:-1])
        i = runs[int(np.argmax(value[runs]))]
        return float(value[i]), float((at[i] + at[i + 1]) / 2)

    def _settle(self, remaining, normal, rho):
        """Take the faces valid for the plane, refit the plane to them (area-weighted least
        squares normal, offset midway between their extremes) while that keeps as much area;
        every returned face is within epsilon of the returned plane."""
        members = self.faces.valid(remaining, normal, rho)
        for _ in range(3):
            if not members.size:
                break
            fit_normal, fit_rho = self._fit(members)
            refit = self.faces.valid(remaining, fit_normal, fit_rho)
            if self._score(refit) < self._score(members):
                break
            same = np.array_equal(refit, members)
            normal, rho, members = fit_normal, fit_rho, refit
            if same:
                break
        return normal, rho, members

    def _score(self, idx) -> tuple[float, int]:
        return float(self.faces.area[idx].sum()), len(idx)

    def _fit(self, idx) -> tuple[np.ndarray, float]:
        tri, area = self.faces.tri[idx], self.faces.area[idx]
        total = float(area.sum())
        if total > 0:  # exact second moment of the triangles: A/12 (sum v v^T + s s^T)
            s = tri.sum(axis=1)
            moment = (np.einsum("n,nij,nik->jk", area, tri, tri)
                      + np.einsum("n,nj,nk->jk", area, s, s)) / (12 * total)
            mean = area @ s / (3 * total)
            cov = moment - np.outer(mean, mean)
        else:
            pts = tri.reshape(-1, 3) - tri.reshape(-1, 3).mean(axis=0)
            cov = pts.T @ pts
        normal = _canonical(np.linalg.eigh(cov)[1][:, 0])
        proj = tri @ normal
        return normal, float(proj.min() + proj.max()) / 2

    def _own_plane(self, idx) -> tuple[np.ndarray, float]:
        """The plane of the largest face of idx (first on ties)."""
        f = self.faces
        i = idx[int(np.argmax(f.area[idx]))]
        normal = f.normal[i] if not f.degenerate[i] else _segment_normal(f.tri[i])
        normal = _canonical(normal)
        return normal, float(f.tri[i].mean(axis=0) @ normal)

    def _degenerate(self, remaining, owner, found):
        """Zero-area faces left over join the plane they are nearest to when within epsilon
        of it; only those near no plane get one of their own (unavoidable)."""
        f = self.faces
        if found:
            normals = np.stack([n for n, _, _ in found], axis=1)
            rhos = np.array([r for _, r, _ in found])
            dist = np.abs(f.tri[remaining] @ normals - rhos).max(axis=1)   # (n, planes)
            nearest = np.argmin(dist, axis=1)
            near = dist[np.arange(len(remaining)), nearest] <= f.check_eps
            for p in np.unique(nearest[near]):
                joining = remaining[near & (nearest == p)]
                n, r, m = found[p]
                found[p] = (n, r, np.concatenate([m, joining]))
                owner[joining] = p
            remaining = remaining[~near]
            if not remaining.size:
                return None, None, None
        return self._settle(remaining, *self._own_plane(remaining))


def _around(direction: np.ndarray, spacing: float, reach: int) -> list[np.ndarray]:
    """The direction first, then a square grid of tilts `spacing` apart, up to `reach` steps
    on each side of it (unit vectors)."""
    t1, t2 = plane_basis(direction)
    out = [direction]
    for i in range(-reach, reach + 1):
        for j in range(-reach, reach + 1):
            if i or j:
                c = direction + spacing * (i * t1 + j * t2)
                out.append(c / np.linalg.norm(c))
    return out


def _canonical(normal: np.ndarray) -> np.ndarray:
    """The representative of {n, -n} on the upper hemisphere (first nonzero of z, y, x > 0)."""
    for axis in (2, 1, 0):
        if normal[axis] != 0:
            return normal if normal[axis] > 0 else -normal
    return normal


def _segment_normal(tri: np.ndarray) -> np.ndarray:
    """A unit normal of a zero-area triangle: perpendicular to its longest edge."""
    edges = tri[[1, 2, 0]] - tri
    edge = edges[int(np.argmax(np.linalg.norm(edges, axis=1)))]
    if not np.any(edge):
        return np.array([0.0, 0.0, 1.0])
    axis = np.zeros(3)
    axis[int(np.argmin(np.abs(edge)))] = 1.0
    normal = np.cross(edge, axis)
    return normal / np.linalg.norm(normal)


def _billboard(faces: _Faces, normal, rho, members, texel) -> BillboardPlane:
    """The world plane of members facing their side, with its tight padded rectangle."""
    members = np.sort(members).astype(np.int64)
    if faces.area[members] @ (faces.normal[members] @ normal) < 0:
        normal, rho = -normal, -rho
    e1, e2 = plane_basis(normal)
    pts = faces.points[np.unique(faces.corners[members])]   # each vertex once, not ~6 times
    corner, u_dir, size = min_area_rectangle(np.stack([pts @ e1, pts @ e2], axis=1))
    v_dir = np.array([-u_dir[1], u_dir[0]])
    corner = corner - (u_dir + v_dir) * texel / 2     # half a texel of padding on every side
    size = size + texel
    to_3d = np.stack([e1, e2])                        # (2, 3): plane coordinates -> local
    return BillboardPlane(
        normal=normal.copy(),
        offset=float(rho + normal @ faces.centre),
        faces=members,
        corner=faces.centre + rho * normal + corner @ to_3d,
        u_axis=size[0] * (u_dir @ to_3d),
        v_axis=size[1] * (v_dir @ to_3d),
        resolution=tuple(max(1, math.ceil(x / texel - 1e-9)) for x in size),
    )
