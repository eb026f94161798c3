"""Check a front-to-back order of a shell's tetrahedra against exact rays, for tests and
benchmarks.

One ray per pixel (`Camera.pixel_rays`: from the near plane through the pixel centre). On
each ray, the tetrahedra it crosses (a length more than `TOL` of the shell's size) are
sorted by the exact float64 distance at which the ray enters them (ties by tetrahedron
index). Each pair
of consecutive tetrahedra on that list is one constraint: the nearer one must come first
in the order. A constraint whose two tetrahedra come the other way round in the order is a
violation.

The ray is the whole line through the pixel (entry distances are not clipped at the near
plane), as the brute-force reference in the tests does; the eye is assumed outside the
shell. Tetrahedra are binned by their screen rectangle (tiles of `TILE` pixels) so that
each ray tests only the tetrahedra whose projection may cover it; a tetrahedron with a
vertex at or behind the eye plane (perspective) goes into every tile.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np
from numba import njit

from ...errors import UsageError
from ...scene.camera import pixel_segments
from .binning import bin_by_tile, screen_boxes

#: A ray crosses a tetrahedron when its length inside is more than this times the shell's
#: size (relative: a shell of any scale is checked alike).
TOL = 1e-9

#: Side of the square screen tiles tetrahedra are binned into, in pixels.
TILE = 4

@dataclass(frozen=True)
class OrderCheck:
    """What `ordering_violations` found.

    violations : consecutive pairs of crossed tetrahedra, over all rays, whose ranks in the
        order are inverted (the farther one of the pair comes first). A ray crossing k
        tetrahedra contributes k - 1 pairs; only consecutive pairs are counted, not every
        pair on the ray.
    pairs : all those consecutive pairs, inverted or not (the constraints checked).
    rays : rays that cross at least two tetrahedra.
    bad_rays : rays with at least one violation.
    seconds : wall time of the check (rays, binning and the ray tests).
    """

    violations: int
    pairs: int
    rays: int
    bad_rays: int
    seconds: float


def ordering_violations(shell, camera, order, size=None) -> OrderCheck:
    """Count how often `order` (front to back, a permutation of `shell`'s tetrahedra) breaks
    the order in which `camera`'s pixel rays cross the tetrahedra (see the module docstring
    and `OrderCheck.violations` for exactly what is counted).

    size: (width, height) of the ray grid instead of `camera.size`, with the same view and
    projection matrices.
    """
    start = time.perf_counter()
    count = len(shell.tets)
    order = np.asarray(order)
    if order.shape != (count,) or not np.array_equal(np.sort(order), np.arange(count)):
        raise UsageError(f"order must be a permutation of the {count} tetrahedra")
    width, height = camera.size if size is None else size
    if int(width) != width or int(height) != height or width < 1 or height < 1:
        raise UsageError(f"size must be two positive integers, got {size!r}")
    width, height = int(width), int(height)
    grid = SimpleNamespace(view=camera.view, proj=camera.proj, size=(width, height))
    near, far = pixel_segments(grid)
    dirs = far - near
    dirs = dirs / np.linalg.norm(dirs, axis=-1, keepdims=True)  # as Camera.pixel_rays
    rank = np.empty(count, np.int64)
    rank[order.astype(np.int64)] = np.arange(count)
    lo_c, hi_c, lo_r, hi_r = screen_boxes(shell, camera, width, height)
    tiles_x, tiles_y = -(-width // TILE), -(-height // TILE)
    starts, items = bin_by_tile(lo_c, hi_c, lo_r, hi_r, tiles_x, tiles_y, TILE)
    violations, pairs, rays, bad_rays = _check(
        np.ascontiguousarray(shell.planes, dtype=np.float64), np.ascontiguousarray(near),
        np.ascontiguousarray(dirs), starts, items, np.stack([lo_c, hi_c, lo_r, hi_r], axis=1),
        rank, TILE, tiles_x, TOL * _size(shell))
    return OrderCheck(int(violations), int(pairs), int(rays), int(bad_rays),
                      time.perf_counter() - start)


def _size(shell) -> float:
    """The diagonal of the shell's bounding box (1 for a point)."""
    p = np.asarray(shell.positions, np.float64)
    return float(np.linalg.norm(p.max(axis=0) - p.min(axis=0))) or 1.0


@njit(cache=True)
def _check(planes, origins, dirs, starts, items, boxes, rank, tile, tiles_x, tol):
    """(violations, pairs, rays, bad rays) over every pixel ray (see `OrderCheck`)."""
    h, w = origins.shape[0], origins.shape[1]
    most = 0
    for k in range(starts.shape[0] - 1):
        most = max(most, starts[k + 1] - starts[k])
    enter_buf = np.empty(most)
    tet_buf = np.empty(most, np.int64)
    violations, pairs, rays, bad_rays = 0, 0, 0, 0
    for r in range(h):
        for c in range(w):
            k = (r // tile) * tiles_x + c // tile
            ox, oy, oz = origins[r, c, 0], origins[r, c, 1], origins[r, c, 2]
            dx, dy, dz = dirs[r, c, 0], dirs[r, c, 1], dirs[r, c, 2]
            n = 0
            for j in range(starts[k], starts[k + 1]):
                i = items[j]
                if c < boxes[i, 0] or c > boxes[i, 1] or r < boxes[i, 2] or r > boxes[i, 3]:
                    continue
                enter, leave, out = -np.inf, np.inf, False
                for f in range(4):
                    a, b, cc, d = planes[i, f, 0], planes[i, f, 1], planes[i, f, 2], planes[i, f, 3]
                    num = a * ox + b * oy + cc * oz + d  # > 0: outside that plane
                    den = a * dx + b * dy + cc * dz
                    if den < 0:
                        enter = max(enter, -num / den)
                    elif den > 0:
                        leave = min(leave, -num / den)
                    elif num > 0:
                        out = True
                if out or not leave - enter > tol:
                    continue
                # insertion by entry distance; equal entries keep increasing index
                m = n
                while m > 0 and enter_buf[m - 1] > enter:
                    enter_buf[m] = enter_buf[m - 1]
                    tet_buf[m] = tet_buf[m - 1]
                    m -= 1
                enter_buf[m] = enter
                tet_buf[m] = i
                n += 1
            if n < 2:
                continue
            rays += 1
            pairs += n - 1
            bad = 0
            for m in range(1, n):
                if rank[tet_buf[m]] < rank[tet_buf[m - 1]]:
                    bad += 1
            violations += bad
            if bad > 0:
                bad_rays += 1
    return violations, pairs, rays, bad_rays
