"""Slice polygons through a displacement volume (§3), as plain numpy geometry for GL to upload.

Conventions
-----------
A *box* is an affine parallelepiped ``world = box_to_world @ (u, v, h, 1)`` with box
coordinates (u, v, h) in [0, 1]^3, h being the displacement direction (see
`depth_images`, whose ``box_to_world[k]`` and ``cube_to_world`` are such boxes). The box may
be sheared and rotated; its 3x3 part must be invertible.

Two slicings are provided, each returning a `SliceStack`:

* `orthogonal_slices` (§3.2): planes q_a = const through the whole box for the box axis a
  whose slices are most perpendicular to the view, at the cell centres
  q_a = (i + 0.5) / count, full cross-sections (quads).
* `screen_slices` (§3.3, the exact variant): planes perpendicular to the view direction,
  intersected exactly with the box (convex polygons of 3..6 vertices). For a perspective
  `Camera` the planes are perpendicular to the direction from the eye to the box centre
  (not to the image plane, they are the same when the camera looks at the box centre),
  which keeps every slice facing the eye near the middle of the box.

The view direction ``f`` (from the viewer into the scene) is: ``target - eye`` for an
orthographic `Camera`, ``centre - eye`` for a perspective one, ``-view_dir`` for a
`MatrixCamera` (which shades as orthographic looking along ``-view_dir``).

Slices of a stack are indexed k = 0 .. K-1 in increasing ``plane_offset``; the triangles
are grouped by slice in that order (``first_triangle``), and ``front_to_back`` /
``back_to_front`` are the draw orders for the camera (nearest slice first / last). Polygons
are triangle fans, counter-clockwise as seen from the camera (i.e. counter-clockwise about
``plane_normal``, which points towards the viewer).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...core.transforms import transform_points
from ...errors import UsageError

#: The unit cube's corners, bit a of corner index i giving coordinate a.
CORNERS = np.array([[(i >> a) & 1 for a in range(3)] for i in range(8)], dtype=np.float64)
#: The cube's twelve edges as pairs of corner indices.
EDGES = np.array([(i, i | (1 << a)) for i in range(8) for a in range(3) if not i & (1 << a)],
                 dtype=np.intp)
#: Relative tolerance under which a corner counts as lying on a slicing plane.
ON_PLANE = 1e-12
#: Preference among axes when two are equally good for orthogonal slicing (h, then u, v):
#: the base-aligned direction needs the fewest slices (§3.4).
AXIS_PREFERENCE = (2, 0, 1)
#: Two axes whose |cos| with the view differs by less than this are a tie.
TIE = 1e-9


@dataclass(frozen=True, eq=False)
class SliceStack:
    """Slice polygons as an indexed triangle list.

    positions : (N, 3) float64 world positions of the vertices.
    box : (N, 3) float64 box coordinates (u, v, h) in [0, 1]^3 of the same vertices.
    triangles : (M, 3) int32 vertex indices, fans, grouped by slice in index order.
    slice_of_triangle : (M,) int32 the slice each triangle belongs to.
    first_triangle : (K + 1,) int32, slice k owns triangles first_triangle[k]:first_triangle[k+1]
        (empty for a plane that misses the box).
    plane_normal : (3,) float64 unit world normal of every slice plane (towards the viewer
        for camera-dependent stacks, along +h's gradient for surface slices).
    plane_offset : (K,) float64, slice k is the plane ``plane_normal . x = plane_offset[k]``.
    levels : (K,) float64, box coordinate q_axis of each slice (axis stacks), or for screen
        slices the fraction in (0, 1) of the way from the nearest to the farthest box corner.
    axis : the box axis sliced along (0 = u, 1 = v, 2 = h), None for screen slices.
    spacing : world distance between neighbouring planes (0 for a single slice).
    front_to_back : (K,) int32 slice indices, nearest to the viewer first.
    back_to_front : (K,) int32, the reverse.
    """

    positions: np.ndarray
    box: np.ndarray
    triangles: np.ndarray
    slice_of_triangle: np.ndarray
    first_triangle: np.ndarray
    plane_normal: np.ndarray
    plane_offset: np.ndarray
    levels: np.ndarray
    axis: int | None
    spacing: float
    front_to_back: np.ndarray
    back_to_front: np.ndarray

    @property
    def slice_count(self) -> int:
        return int(self.plane_offset.shape[0])

    def slice_triangles(self, k: int) -> np.ndarray:
        """(m, 3) int32 triangles of slice k."""
        return self.triangles[self.first_triangle[k]:self.first_triangle[k + 1]]

    def triangles_in_order(self, front_to_back: bool = True) -> np.ndarray:
        """(M, 3) int32 all triangles, slice by slice in draw order."""
        order = self.front_to_back if front_to_back else self.back_to_front
        if not len(order):
            return self.triangles[:0]
        return np.concatenate([self.slice_triangles(int(k)) for k in order])

    def slice_areas(self) -> np.ndarray:
        """(K,) float64 world area of each slice polygon."""
        tri = self.positions[self.triangles]
        area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]),
                                    axis=1)
        return np.bincount(self.slice_of_triangle, weights=area, minlength=self.slice_count)

    def area_pixels(self, camera) -> float:
        """Total projected area of all slices in pixels (the fill the stack costs), without
        clipping to the viewport or the near plane."""
        return projected_area(self.positions[self.triangles].reshape(-1, 3), camera)


def projected_area(corners: np.ndarray, camera) -> float:
    """Projected area in pixels of a triangle list given as (3M, 3) world corners, without
    clipping (the fragments slices cost)."""
    if not len(corners):
        return 0.0
    clip = np.c_[corners, np.ones(len(corners))] @ (np.asarray(camera.proj)
                                                     @ np.asarray(camera.view)).T
    w = np.where(np.abs(clip[:, 3:4]) > 1e-12, clip[:, 3:4], 1e-12)
    pix = (clip[:, :2] / w + 1.0) * 0.5 * np.asarray(camera.size, dtype=np.float64)
    t = pix.reshape(-1, 3, 2)
    d1, d2 = t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]
    return float(np.abs(0.5 * (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])).sum())


# --- validation -------------------------------------------------------------------------------

def _count(count, name: str = "slice count") -> int:
    if isinstance(count, bool) or not isinstance(count, (int, np.integer)):
        if isinstance(count, float) and count.is_integer():
            count = int(count)
        else:
            raise UsageError(f"{name} must be a positive integer, got {count!r}")
    if count < 1:
        raise UsageError(f"{name} must be at least 1, got {count}")
    return int(count)


def _box(box_to_world) -> tuple[np.ndarray, np.ndarray]:
    """(A, o): the box's 3x3 linear part (columns = u, v, h edges) and its origin corner."""
    m = np.asarray(box_to_world, dtype=np.float64)
    if m.shape != (4, 4) or not np.isfinite(m).all():
        raise UsageError(f"box_to_world must be a finite 4x4 matrix, got shape {m.shape}")
    if not np.allclose(m[3], [0.0, 0.0, 0.0, 1.0]):
        raise UsageError("box_to_world must be affine (last row 0 0 0 1)")
    a = m[:3, :3]
    scale = float(np.abs(a).max())
    if scale == 0 or abs(np.linalg.det(a)) <= 1e-12 * scale ** 3:
        raise UsageError("box_to_world is singular: the box must have a non-zero volume")
    return a, m[:3, 3].copy()


def view_direction(camera, centre) -> np.ndarray:
    """Unit world direction from the viewer into the scene (see the module docstring)."""
    if hasattr(camera, "view_dir"):
        f = -np.asarray(camera.view_dir, dtype=np.float64)
    elif camera.orthographic:
        f = np.asarray(camera.target, dtype=np.float64) - np.asarray(camera.eye, dtype=np.float64)
    else:
        f = np.asarray(centre, dtype=np.float64) - np.asarray(camera.eye, dtype=np.float64)
    norm = float(np.linalg.norm(f))
    if not np.isfinite(norm) or norm == 0:
        raise UsageError("no view direction: the eye is at the box centre (or the camera's "
                         "view direction is zero)")
    return f / norm


def _orders(plane_offset: np.ndarray, normal_towards_viewer: bool):
    """(front_to_back, back_to_front) of slices indexed by increasing ``plane_offset``."""
    ascending = np.arange(len(plane_offset), dtype=np.int32)
    # a larger offset along a normal that points towards the viewer is nearer
    front = ascending[::-1].copy() if normal_towards_viewer else ascending
    return front, front[::-1].copy()


# --- plane / box intersection -----------------------------------------------------------------

def _cut_unit_cube(m: np.ndarray, c: float) -> np.ndarray:
    """Box-coordinate points where the plane m . q = c meets the unit cube's edges (deduped)."""
    s = CORNERS @ m - c
    tol = ON_PLANE * max(float(np.abs(m).sum()) + abs(c), 1e-300)
    s = np.where(np.abs(s) <= tol, 0.0, s)
    i, j = EDGES[:, 0], EDGES[:, 1]
    cross = s[i] * s[j] < 0
    t = s[i][cross] / (s[i][cross] - s[j][cross])
    p = CORNERS[i[cross]] + t[:, None] * (CORNERS[j[cross]] - CORNERS[i[cross]])
    pts = np.clip(np.concatenate([CORNERS[s == 0], p]), 0.0, 1.0)
    keep: list[np.ndarray] = []
    for q in pts:
        if all(np.abs(q - r).max() > 1e-12 for r in keep):
            keep.append(q)
    return np.array(keep).reshape(-1, 3)


def _polygon(a, o, normal, d):
    """Exact convex polygon of the box and the plane normal . x = d, CCW about ``normal``:
    (box coords (n, 3), world (n, 3)), n = 0 where the plane misses (or only touches) it."""
    q = _cut_unit_cube(a.T @ normal, d - float(normal @ o))
    if len(q) < 3:
        return q[:0], q[:0]
    x = q @ a.T + o
    centre = x.mean(axis=0)
    e1 = np.cross(normal, [1.0, 0.0, 0.0])
    if np.linalg.norm(e1) < 0.5:
        e1 = np.cross(normal, [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(normal, e1)
    rel = x - centre
    order = np.argsort(np.arctan2(rel @ e2, rel @ e1), kind="stable")
    q, x = q[order], x[order]
    rel = x - x[0]
    twice_area = float(np.cross(rel[1:-1], rel[2:]).sum(axis=0) @ normal)
    if twice_area <= 1e-14 * float(np.abs(rel).max()) ** 2:
        return q[:0], q[:0]
    return q, x


def _assemble(polygons, normal, offsets, levels, axis, spacing, front, back) -> SliceStack:
    boxes, worlds, tris, owner = [], [], [], []
    first = [0]
    base = 0
    for k, (q, x) in enumerate(polygons):
        n = len(q)
        if n >= 3:
            fan = np.stack([np.zeros(n - 2, dtype=np.int64), np.arange(1, n - 1),
                            np.arange(2, n)], axis=1) + base
            boxes.append(q)
            worlds.append(x)
            tris.append(fan)
            owner.append(np.full(n - 2, k))
            base += n
        first.append(first[-1] + max(n - 2, 0))

    def cat(parts, shape):
        return np.concatenate(parts) if parts else np.zeros(shape)

    return SliceStack(
        positions=cat(worlds, (0, 3)).astype(np.float64),
        box=cat(boxes, (0, 3)).astype(np.float64),
        triangles=cat(tris, (0, 3)).astype(np.int32),
        slice_of_triangle=cat(owner, (0,)).astype(np.int32),
        first_triangle=np.asarray(first, dtype=np.int32),
        plane_normal=np.asarray(normal, dtype=np.float64),
        plane_offset=np.asarray(offsets, dtype=np.float64),
        levels=np.asarray(levels, dtype=np.float64),
        axis=axis, spacing=float(spacing),
        front_to_back=np.asarray(front, dtype=np.int32),
        back_to_front=np.asarray(back, dtype=np.int32))


# --- the three slicings -----------------------------------------------------------------------

def screen_slices(box_to_world, camera, count: int) -> SliceStack:
    """``count`` planes perpendicular to the view direction, cut exactly to the box (§3.3).

    The planes sit at the centres of ``count`` equal intervals between the nearest and the
    farthest box corner along the view direction (so none degenerates to a corner and
    sum(area) * spacing approximates the box's volume by the midpoint rule). As in every
    stack, slices are indexed by increasing ``plane_offset`` (here the farthest first);
    ``front_to_back`` gives the nearest first. ``plane_normal`` = -f points towards the
    viewer.
    """
    count = _count(count)
    a, o = _box(box_to_world)
    corners = CORNERS @ a.T + o
    f = view_direction(camera, corners.mean(axis=0))
    depth = corners @ f
    near, far = float(depth.min()), float(depth.max())
    spacing = (far - near) / count
    # index order: increasing plane_offset = -depth, i.e. the farthest plane is slice 0
    levels = (np.arange(count)[::-1] + 0.5) / count
    depths = near + levels * (far - near)
    normal = -f
    polygons = [_polygon(a, o, normal, -float(t)) for t in depths]
    front, back = _orders(-depths, True)
    return _assemble(polygons, normal, -depths, levels, None, spacing, front, back)


def axis_normals(box_to_world) -> np.ndarray:
    """(3, 3) unit world normals of the planes u, v, h = const (rows), i.e. the normalised
    gradients of the box coordinates; for a box without shear these are its edge directions."""
    a, _ = _box(box_to_world)
    g = np.linalg.inv(a)  # row a = gradient of q_a
    return g / np.linalg.norm(g, axis=1, keepdims=True)


def best_axis(box_to_world, camera) -> int:
    """The box axis whose slices are most perpendicular to the view (§3.2): the largest
    |cos| between the slice planes' normal and the view direction. Ties (within `TIE`, e.g.
    a view at 45 degrees between two axes) go to the axis first in `AXIS_PREFERENCE`
    (h, then u, then v)."""
    a, o = _box(box_to_world)
    centre = o + a.sum(axis=1) * 0.5
    f = view_direction(camera, centre)
    score = np.abs(axis_normals(box_to_world) @ f)
    top = score.max()
    return next(ax for ax in AXIS_PREFERENCE if score[ax] >= top - TIE)


def _axis_stack(a, o, axis, levels, normal_sign) -> SliceStack:
    """Full cross-sections q_axis = level, normal = normal_sign * grad(q_axis) (unit); slices
    indexed by increasing plane_offset, front_to_back = decreasing offset (the normal points
    towards the viewer, or towards +h for surface slices)."""
    g = np.linalg.inv(a)[axis]
    norm = float(np.linalg.norm(g))
    normal = normal_sign * g / norm
    # q_axis = level  <=>  g . x = level + g . (-o)
    offsets = normal_sign * (levels - float(g @ o)) / norm
    order = np.argsort(offsets, kind="stable")
    levels, offsets = levels[order], offsets[order]
    # the quad in box coordinates, CCW about +e_axis (the other axes in cyclic order); the
    # map a keeps that orientation about grad(q_axis) iff det(a) > 0
    b, c = (axis + 1) % 3, (axis + 2) % 3
    quad = np.zeros((4, 3))
    quad[:, b] = [0.0, 1.0, 1.0, 0.0]
    quad[:, c] = [0.0, 0.0, 1.0, 1.0]
    if (normal_sign < 0) != (np.linalg.det(a) < 0):
        quad = quad[::-1].copy()
    polygons = []
    for level in levels:
        q = quad.copy()
        q[:, axis] = level
        polygons.append((q, q @ a.T + o))
    spacing = (float(levels[1] - levels[0]) / norm) if len(levels) > 1 else 0.0
    front, back = _orders(offsets, True)
    return _assemble(polygons, normal, offsets, levels, axis, abs(spacing), front, back)


def orthogonal_slices(box_to_world, camera, count: int, axis: int | None = None) -> SliceStack:
    """``count`` full cross-sections q_axis = (i + 0.5) / count along the box axis most
    perpendicular to the view (`best_axis`, or ``axis`` if given), nearest first for the
    camera (§3.2). ``plane_normal`` points towards the viewer."""
    count = _count(count)
    a, o = _box(box_to_world)
    if axis is None:
        axis = best_axis(box_to_world, camera)
    elif axis not in (0, 1, 2):
        raise UsageError(f"slicing axis must be 0 (u), 1 (v) or 2 (h), got {axis!r}")
    centre = o + a.sum(axis=1) * 0.5
    f = view_direction(camera, centre)
    g = np.linalg.inv(a)[axis]
    sign = -1.0 if float(g @ f) >= 0 else 1.0  # normal towards the viewer
    levels = (np.arange(count) + 0.5) / count
    return _axis_stack(a, o, axis, levels, sign)


# --- how many slices --------------------------------------------------------------------------

#: Bounds of the automatic slice count.
AUTO_MIN, AUTO_MAX = 2, 2048


def pixel_world_size(camera, point) -> float:
    """World length that one pixel spans at ``point`` (in the image plane's vertical), from
    the camera's own matrices (so any camera kind)."""
    p = np.asarray(point, dtype=np.float64)
    view = np.asarray(camera.view, dtype=np.float64)
    eye_p = transform_points(view, p[None])[0]
    clip_of = np.asarray(camera.proj, dtype=np.float64)
    h = camera.size[1]

    def ndc_y(e):
        c = clip_of @ np.append(e, 1.0)
        return c[1] / c[3]

    step = max(abs(float(eye_p[2])), 1e-6) * 1e-3
    up = eye_p + np.array([0.0, step, 0.0])
    pixels = abs(ndc_y(up) - ndc_y(eye_p)) * 0.5 * h
    return step / pixels if pixels > 0 else math.inf


def auto_slice_count(thickness: float, camera, centre, finest: float,
                     maximum: int = AUTO_MAX) -> int:
    """The automatic slice count for a volume ``thickness`` deep along the slicing normal:
    slices one pixel apart at ``centre`` (the volume's size on screen decides), but never
    closer than ``finest`` (about a texel: closer slices add nothing), clamped to
    [`AUTO_MIN`, ``maximum``]."""
    spacing = max(pixel_world_size(camera, centre), float(finest))
    if not math.isfinite(spacing) or spacing <= 0:
        return AUTO_MIN
    return int(min(maximum, max(AUTO_MIN, math.ceil(thickness / spacing - 1e-9))))
