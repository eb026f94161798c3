"""Triangulating one polygon by ear clipping, in its best-fit plane.

File readers split polygons into fans, which is right only for convex ones: a fan of a
concave polygon (a keyhole, an L, a star) covers area outside it twice and z-fights. Ear
clipping cuts off one corner at a time whose triangle holds no other corner, so the
triangles tile the polygon exactly. It is O(n^2) in the corner count, which real faces keep
small.
"""

from __future__ import annotations

import numpy as np


def triangulate_polygon(points: np.ndarray) -> np.ndarray:
    """(n - 2, 3) corner indices of triangles tiling a simple polygon given by (n, 3) points.

    The triangles keep the polygon's winding. Collinear and repeated corners are cut off as
    zero-area triangles once nothing else is left to cut, so every corner is used. A
    degenerate polygon (no area) becomes a fan.
    """
    n = len(points)
    if n < 3:
        return np.zeros((0, 3), np.int64)
    xy = _plane_coordinates(np.asarray(points, dtype=np.float64))
    if xy is None:
        return _fan(n)
    scale = np.ptp(xy, axis=0).max()
    return _clip_ears(xy, 1e-12 * scale * scale)


def _fan(n: int) -> np.ndarray:
    return np.column_stack([np.zeros(n - 2, np.int64), np.arange(1, n - 1), np.arange(2, n)])


def _plane_coordinates(points: np.ndarray) -> np.ndarray | None:
    """2D coordinates in the plane of Newell's normal, oriented so the polygon is CCW."""
    centered = points - points.mean(axis=0)
    following = np.roll(centered, -1, axis=0)
    normal = np.cross(centered, following).sum(axis=0)  # Newell: twice the vector area
    length = np.linalg.norm(normal)
    if length <= 1e-12 * max(float((centered**2).sum()), 1e-300):
        return None
    normal /= length
    helper = np.eye(3)[np.argmin(np.abs(normal))]
    u = np.cross(helper, normal)
    u /= np.linalg.norm(u)
    v = np.cross(normal, u)
    return np.column_stack([centered @ u, centered @ v])


def _cross(o: np.ndarray, a: np.ndarray, b: np.ndarray):
    """z of (a - o) x (b - o), for one point or arrays of points."""
    return (a[..., 0] - o[..., 0]) * (b[..., 1] - o[..., 1]) - (
        a[..., 1] - o[..., 1]) * (b[..., 0] - o[..., 0])


def _clip_ears(xy: np.ndarray, tolerance: float) -> np.ndarray:
    """Ear clipping of a counter-clockwise polygon; a linked ring of the corners left."""
    n = len(xy)
    prev = list(range(-1, n - 1))
    prev[0] = n - 1
    nxt = list(range(1, n + 1))
    nxt[-1] = 0
    alive = np.ones(n, bool)

    def turn(i: int) -> float:
        return float(_cross(xy[prev[i]], xy[i], xy[nxt[i]]))

    def is_ear(i: int) -> bool:
        a, b, c = prev[i], i, nxt[i]
        if turn(i) <= tolerance:
            return False
        others = alive.copy()
        others[[a, b, c]] = False
        p = xy[others]
        p = p[~(np.all(p == xy[a], axis=1) | np.all(p == xy[b], axis=1)
                | np.all(p == xy[c], axis=1))]  # repeated corners, e.g. of a bridge
        inside = ((_cross(xy[a], xy[b], p) >= -tolerance)
                  & (_cross(xy[b], xy[c], p) >= -tolerance)
                  & (_cross(xy[c], xy[a], p) >= -tolerance))
        return not inside.any()

    ears = [is_ear(i) for i in range(n)]
    triangles = []
    i, left = 0, n
    while left > 3:
        cut = _next_ear(i, ears, nxt, left)
        if cut is None:  # no proper ear: a collinear corner, else the least bad one
            ring = _ring(i, nxt, left)
            turns = [turn(k) for k in ring]
            flat = [k for k, t in zip(ring, turns, strict=True) if abs(t) <= tolerance]
            cut = flat[0] if flat else ring[int(np.argmax(turns))]
        a, c = prev[cut], nxt[cut]
        triangles.append((a, cut, c))
        nxt[a], prev[c] = c, a
        alive[cut] = False
        left -= 1
        ears[a], ears[c] = is_ear(a), is_ear(c)
        i = c
    a = i
    triangles.append((prev[a], a, nxt[a]))
    return np.array(triangles, dtype=np.int64)


def _next_ear(start: int, ears: list[bool], nxt: list[int], left: int) -> int | None:
    i = start
    for _ in range(left):
        if ears[i]:
            return i
        i = nxt[i]
    return None


def _ring(start: int, nxt: list[int], left: int) -> list[int]:
    ring, i = [], start
    for _ in range(left):
        ring.append(i)
        i = nxt[i]
    return ring
