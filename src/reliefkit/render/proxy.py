"""Convex proxy geometry: the halfspaces of a (projective) box, an AABB, their intersection.

A proxy is a convex polyhedron in world space with outward counter-clockwise triangles
(float32 vertices relative to a float64 ``origin`` inside it, so far boxes stay exact),
rasterized so that a fragment shader can resolve the detail inside it. Shaders that rebuild
each pixel's ray from the window position accept any convex proxy that contains the visible
surface: a whole box (frustum), or a box cut to the object's bounds, which rasterizes fewer
fragments.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import UsageError
from .plan import Raster


@dataclass(frozen=True)
class Proxy:
    positions: np.ndarray   # (V, 3) float32 relative to origin
    triangles: np.ndarray   # (F, 3) uint32, outward CCW
    planes: np.ndarray      # (P, 4) world, inside where planes @ (x, y, z, 1) <= 0
    origin: np.ndarray      # (3,) float64 world point inside the proxy

    @property
    def world_positions(self) -> np.ndarray:
        """(V, 3) float64 world vertices."""
        return self.positions.astype(np.float64) + self.origin


#: How proxies are drawn: back faces culled (`cull_face` per view says which), depth
#: clamped instead of clipped at the near and far planes, and the test passing on equal
#: depths. A proxy may reach beyond the camera's near-far range, which hugs the object (a
#: reverse frustum baked without clipping is wider than its mesh): clipping would cut holes
#: where its drawn faces lie beyond far, although the surface inside is in range; a face
#: clamped to the far plane has the depth the Z-buffer is cleared to.
PROXY_RASTER = Raster(depth_func="<=", depth_clamp=True, cull="back")


def cull_face(proxy: Proxy, camera) -> str:
    """The faces to cull when drawing ``proxy``: "back", or "front" when it reaches in front
    of the near plane (the camera inside or close), where its front faces would be clipped;
    shaders that build each pixel's ray from the window position draw its back faces then."""
    corners = proxy.world_positions
    eye_z = np.c_[corners, np.ones(len(corners))] @ np.asarray(camera.view)[2]
    return "front" if eye_z.max() > -camera.near * 1.001 else "back"


def box_planes(world_to_box: np.ndarray) -> np.ndarray:
    """The six planes of the unit cube pulled back to world space (rows a, b, c, d)."""
    m = np.asarray(world_to_box, dtype=np.float64)
    centre = np.linalg.inv(m) @ [0.5, 0.5, 0.5, 1.0]
    if m[3] @ np.append(centre[:3] / centre[3], 1.0) < 0:
        m = -m  # keep the box centre on the w > 0 side
    w = m[3]
    planes = []
    for k in range(3):
        planes.append(-m[k])         # coordinate >= 0  ->  -row_k . X <= 0
        planes.append(m[k] - w)      # coordinate <= 1  ->  (row_k - w) . X <= 0
    return _normalise(np.array(planes))


def aabb_planes(bounds) -> np.ndarray:
    lo, hi = np.asarray(bounds, dtype=np.float64)
    planes = []
    for k in range(3):
        e = np.zeros(3)
        e[k] = 1.0
        planes.append(np.append(-e, lo[k]))
        planes.append(np.append(e, -hi[k]))
    return np.array(planes)


def _normalise(planes: np.ndarray) -> np.ndarray:
    return planes / np.linalg.norm(planes[:, :3], axis=1, keepdims=True)


def convex_proxy(planes: np.ndarray, near=(0.0, 0.0, 0.0)) -> Proxy:
    """Triangulated intersection of halfspaces ``planes @ (x, 1) <= 0``.

    Solved around ``near`` (a world point close to the region, e.g. a box's centre) and then
    around a point inside, in units of the planes' largest distance from ``near``: the
    solvers' tolerances are absolute, which far from the world origin would swamp the box,
    and for a tiny box (a mesh scaled by 1e-9) exceed it.
    """
    from scipy.spatial import ConvexHull, HalfspaceIntersection  # scipy: slow to import

    planes = _normalise(np.asarray(planes, dtype=np.float64))
    near = np.asarray(near, dtype=np.float64)
    around_near = _moved(planes, near)
    size = float(np.abs(around_near[:, 3]).max()) or 1.0
    origin = near + size * _interior_point(_scaled(around_near, size))
    unit = HalfspaceIntersection(_scaled(_moved(planes, origin), size),
                                 np.zeros(3)).intersections
    hull = ConvexHull(unit)
    tris = hull.simplices.copy()
    centre = unit[hull.vertices].mean(axis=0)
    a, b, c = (unit[tris[:, k]] for k in range(3))
    outward = np.einsum("ij,ij->i", np.cross(b - a, c - a), a - centre) > 0
    tris[~outward] = tris[~outward][:, ::-1]
    return Proxy((size * unit).astype(np.float32), tris.astype(np.uint32), planes, origin)


def _moved(planes: np.ndarray, origin: np.ndarray) -> np.ndarray:
    """The planes in coordinates relative to ``origin``."""
    return np.hstack([planes[:, :3], planes[:, 3:] + planes[:, :3] @ origin[:, None]])


def _scaled(planes: np.ndarray, size: float) -> np.ndarray:
    """The planes in coordinates divided by ``size``."""
    return np.hstack([planes[:, :3], planes[:, 3:] / size])


def _interior_point(planes: np.ndarray) -> np.ndarray:
    """Chebyshev centre of the halfspaces (a point strictly inside)."""
    from scipy.optimize import linprog

    norms = np.linalg.norm(planes[:, :3], axis=1)
    result = linprog(np.array([0, 0, 0, -1.0]), A_ub=np.hstack([planes[:, :3], norms[:, None]]),
                     b_ub=-planes[:, 3], bounds=[(None, None)] * 3 + [(0, None)])
    if not result.success or result.x[3] <= 0:
        raise UsageError("the proxy's halfspaces have an empty interior (a degenerate box)")
    return result.x[:3]
