"""Tight oriented rectangles around point sets in a plane: 2D convex hull + rotating calipers.

A billboard's texture covers the rectangle of its faces projected on its plane; the smallest
such rectangle wastes the fewest texels. The minimum-area rectangle around a convex polygon has
one side on a hull edge (Freeman & Shapira 1975), so trying every edge direction of the hull
(what rotating calipers enumerate) finds it exactly.
"""

from __future__ import annotations

import numpy as np

_EDGE_CHUNK = 2048  # hull edges tried at once (a chunk x hull-points matrix of projections)


def plane_basis(normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors e1, e2 spanning the plane, with cross(e1, e2) = normal (right-handed).

    e1 is built from the world axis least aligned with the normal, so it depends only on the
    normal (deterministic) and is never ill-conditioned.
    """
    n = np.asarray(normal, dtype=np.float64)
    axis = np.zeros(3)
    axis[int(np.argmin(np.abs(n)))] = 1.0
    e1 = np.cross(axis, n)
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(n, e1)


def convex_hull_2d(points: np.ndarray) -> np.ndarray:
    """(H, 2) hull vertices counter-clockwise (Andrew's monotone chain), collinear ones dropped.

    Fewer than three distinct points, or collinear ones, give the extreme points only (1 or 2).
    Points inside the quadrilateral of the four axis extremes are discarded first
    (Akl-Toussaint), which leaves the Python loop only the few points near the boundary.
    """
    pts = np.unique(np.asarray(points, dtype=np.float64), axis=0)  # sorted by x, then y
    if len(pts) <= 2:
        return pts
    pts = _drop_interior(pts)
    lower = _half_hull(pts)
    upper = _half_hull(pts[::-1])
    return np.array(lower[:-1] + upper[:-1])


def _drop_interior(pts: np.ndarray) -> np.ndarray:
    """Points strictly inside the convex polygon of the extremes along 8 directions (45 degrees
    apart, counter-clockwise) cannot be on the hull; an octagon leaves about a tenth of a
    round cloud to the Python loop, a quadrilateral over a third."""
    x, y = pts[:, 0], pts[:, 1]
    keys = (-x, -x - y, -y, x - y, x, x + y, y, y - x)     # maximised in turn
    extremes = [int(np.argmax(k)) for k in keys]
    corners = [c for i, c in enumerate(extremes) if c != extremes[i - 1]]  # drop repeats
    if len(set(corners)) < 3:    # a repeated corner would make a zero edge, nothing inside
        return pts
    polygon = pts[corners]
    inside = np.ones(len(pts), dtype=bool)
    for a, b in zip(polygon, np.roll(polygon, -1, axis=0), strict=True):
        inside &= _cross(a, b, pts) > 0
    return pts[~inside]  # unique + boolean mask keeps the sorted order


def _half_hull(pts: np.ndarray) -> list:
    chain: list = []
    for p in pts:
        while len(chain) >= 2 and _cross(chain[-2], chain[-1], p) <= 0:
            chain.pop()
        chain.append(p)
    return chain


def _cross(o, a, b) -> np.ndarray:
    """z of (a - o) x (b - o): positive when o -> a -> b turns left; b may be an (N, 2) array."""
    b = np.asarray(b)
    return (a[0] - o[0]) * (b[..., 1] - o[1]) - (a[1] - o[1]) * (b[..., 0] - o[0])


def min_area_rectangle(points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The minimum-area rectangle around 2D points as (corner, u_dir, size).

    The rectangle is corner + s*size[0]*u_dir + t*size[1]*v_dir for s, t in [0, 1], where
    u_dir is a unit vector and v_dir = (-u_dir[1], u_dir[0]) (so cross(u, v) > 0); a size is
    zero for a degenerate extent. Ties between hull edges go to the first one, so the result
    is deterministic.
    """
    hull = convex_hull_2d(points)
    if len(hull) < 3:  # a point or a segment: along the segment, zero width
        step = hull[-1] - hull[0]
        length = float(np.linalg.norm(step))
        return _aligned_rectangle(hull, step / length if length > 0 else np.array([1.0, 0.0]))
    edges = np.roll(hull, -1, axis=0) - hull
    directions = edges / np.linalg.norm(edges, axis=1)[:, None]  # hull vertices are distinct
    best_area, best_dir = np.inf, directions[0]
    for start in range(0, len(directions), _EDGE_CHUNK):
        d = directions[start:start + _EDGE_CHUNK]
        along = hull @ d.T                        # (H, E) coordinates along each edge
        across = hull @ np.stack([-d[:, 1], d[:, 0]], axis=1).T
        areas = np.ptp(along, axis=0) * np.ptp(across, axis=0)
        k = int(np.argmin(areas))
        if areas[k] < best_area:
            best_area, best_dir = areas[k], d[k]
    return _aligned_rectangle(hull, best_dir)


def _aligned_rectangle(points: np.ndarray, u_dir: np.ndarray):
    v_dir = np.array([-u_dir[1], u_dir[0]])
    along, across = points @ u_dir, points @ v_dir
    corner = along.min() * u_dir + across.min() * v_dir
    return corner, u_dir, np.array([np.ptp(along), np.ptp(across)])
