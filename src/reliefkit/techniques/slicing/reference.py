"""The exact CPU reference for image-based depth objects (§4): ray vs six depth images.

Reconstruction (what "exact" is exact for)
------------------------------------------
Each image is reconstructed *nearest-texel* (piecewise constant): texel (j, i) of face k
stands for the whole column of the cube over its square [i/N, (i+1)/N) x [j/N, (j+1)/N)
in that face's (u, v). Its volume in that column is the points whose distance from face k
is >= depth[k][j, i]; a texel with ``mask`` False contributes nothing (its column is
outside). So every image's volume, and the depth object (their intersection), is a union
of axis-aligned boxes; the six faces' texel grids are the three axis-aligned grids of the
cube, so inside each of the N^3 cube voxels the object is one axis-aligned box
[lo_x, hi_x] x [lo_y, hi_y] x [lo_z, hi_z] (see `DepthImages.column_bounds`).

`exact_intersection` walks each pixel's ray through those voxels (in the order it crosses
the grid planes) and intersects the ray with each voxel's box by slabs: the first hit it
reports is the exact first point of the nearest-texel object along the ray (up to float64
rounding), not a sample of it. Bilinear reconstruction (what the GPU's filtered lookups
would give) is not modelled; it differs from this by at most about one texel.

`inside` and `voxel_carve` are the crude, independent check: they test points one by one
through the faces' ``box_to_world`` matrices (not the column tables).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ...bake.project import axis_frame
from ...core.transforms import transform_points
from ...errors import UsageError
from ...reference.heightfield import clip_box
from ...scene.camera import pixel_segments
from .depth_images import FACE_INDEX, DepthImages

# the face whose outward normal is -a (lower bound of q_a) / +a (upper bound), per axis a
_LOWER_FACE = (1, 3, 5)
_UPPER_FACE = (0, 2, 4)


@njit(cache=True)
def _column(bounds, axis, v, n):
    """lo, hi of axis ``axis`` in voxel v = (ix, iy, iz)."""
    if axis == 0:
        b, c = v[1], v[2]
    elif axis == 1:
        b, c = v[0], v[2]
    else:
        b, c = v[0], v[1]
    return bounds[axis, 0, b, c], bounds[axis, 1, b, c]


@njit(cache=True)
def _trace(bounds, n, q0, dq, t_in, t_out, out_q):
    """First t in [t_in, t_out] where q0 + t dq enters the object; -1 if never.

    ``out_q`` receives the point and returns (t, face)."""
    big = 1e300
    next_t = np.empty(3)
    step_t = np.empty(3)
    v = np.empty(3, np.int64)
    for a in range(3):
        qa = q0[a] + t_in * dq[a]
        if dq[a] > 0:
            m = np.floor(qa * n) + 1.0
            next_t[a] = (m / n - q0[a]) / dq[a]
            step_t[a] = 1.0 / (n * dq[a])
        elif dq[a] < 0:
            m = np.ceil(qa * n) - 1.0
            next_t[a] = (m / n - q0[a]) / dq[a]
            step_t[a] = -1.0 / (n * dq[a])
        else:
            next_t[a] = big
            step_t[a] = big
    t = t_in
    for _ in range(3 * n + 8):
        if t >= t_out:
            break
        tn = min(next_t[0], next_t[1], next_t[2], t_out)
        if tn > t:
            mid = 0.5 * (t + tn)
            for a in range(3):
                i = int(np.floor((q0[a] + mid * dq[a]) * n))
                v[a] = min(max(i, 0), n - 1)
            lo_t = t
            hi_t = tn
            for a in range(3):
                lo, hi = _column(bounds, a, v, n)
                if lo > hi:
                    hi_t = -big
                    break
                if dq[a] == 0.0:
                    if q0[a] < lo or q0[a] > hi:
                        hi_t = -big
                        break
                else:
                    s1 = (lo - q0[a]) / dq[a]
                    s2 = (hi - q0[a]) / dq[a]
                    if s1 > s2:
                        s1, s2 = s2, s1
                    lo_t = max(lo_t, s1)
                    hi_t = min(hi_t, s2)
            if lo_t <= hi_t:
                best = big
                face = 0
                for a in range(3):
                    out_q[a] = q0[a] + lo_t * dq[a]
                for a in range(3):
                    lo, hi = _column(bounds, a, v, n)
                    if out_q[a] - lo < best:
                        best = out_q[a] - lo
                        face = 2 * a + 1
                    if hi - out_q[a] < best:
                        best = hi - out_q[a]
                        face = 2 * a
                return lo_t, face
        for a in range(3):
            if next_t[a] <= tn:
                next_t[a] += step_t[a]
        t = tn
    return -1.0, -1


@njit(cache=True)
def _trace_all(bounds, n, q_near, q_far, hit_t, hit_q, hit_face):
    rows, cols = q_near.shape[0], q_near.shape[1]
    q0 = np.empty(3)
    dq = np.empty(3)
    out_q = np.empty(3)
    for r in range(rows):
        for c in range(cols):
            for a in range(3):
                q0[a] = q_near[r, c, a]
                dq[a] = q_far[r, c, a] - q_near[r, c, a]
            t_in, t_out = clip_box(q0, dq, 0.0, 1.0)  # the segment inside the cube
            if t_in > t_out:
                continue
            t, face = _trace(bounds, n, q0, dq, t_in, t_out, out_q)
            if face >= 0:
                hit_t[r, c] = t
                hit_face[r, c] = face
                for a in range(3):
                    hit_q[r, c, a] = out_q[a]


def _check(images) -> None:
    if not isinstance(images, DepthImages):
        raise UsageError(f"expected DepthImages, got {type(images).__name__}")


def exact_intersection(images: DepthImages, camera):
    """First hit of every pixel's ray with the depth object (nearest-texel, exact).

    Returns ``(mask, position, face)``: (H, W) bool, (H, W, 3) float64 world points (NaN
    where there is no hit) and (H, W) int8 index into `CUBE_FACES` of the image whose
    surface the hit lies on: the one with the least slack ``distance from face - depth``
    at the hit (0 for the image whose depth plane the ray entered through; for a hit on the
    side wall of a texel column, the image seeing the nearest surface there), -1 where
    none. Pixel (r, c) is row r from the top, as in `pixel_segments`.
    """
    _check(images)
    near, far = pixel_segments(camera)
    world_to_cube = np.linalg.inv(images.cube_to_world)
    q_near = np.ascontiguousarray(transform_points(world_to_cube, near))
    q_far = np.ascontiguousarray(transform_points(world_to_cube, far))
    if not (np.isfinite(q_near).all() and np.isfinite(q_far).all()):
        raise UsageError("the camera's pixel rays are not finite (degenerate matrices?)")
    h, w = q_near.shape[:2]
    hit_t = np.full((h, w), -1.0)
    hit_q = np.full((h, w, 3), np.nan)
    hit_face = np.full((h, w), -1, np.int8)
    _trace_all(images.column_bounds(), images.resolution, q_near, q_far, hit_t, hit_q,
               hit_face)
    mask = hit_face >= 0
    position = np.full((h, w, 3), np.nan)
    position[mask] = transform_points(images.cube_to_world, hit_q[mask])
    return mask, position, hit_face


def inside(images: DepthImages, points) -> np.ndarray:
    """(...,) bool: which world ``points`` lie in all six volumes (nearest-texel), tested
    one image at a time through its ``box_to_world``; points outside the cube are outside."""
    _check(images)
    points = np.asarray(points, dtype=np.float64)
    n = images.resolution
    result = np.ones(points.shape[:-1], bool)
    for k in range(6):
        uvh = transform_points(np.linalg.inv(images.box_to_world[k]), points)
        in_cube = ((uvh >= 0) & (uvh <= 1)).all(axis=-1)
        i = np.clip(np.floor(uvh[..., 0] * n), 0, n - 1).astype(int)
        j = np.clip(np.floor(uvh[..., 1] * n), 0, n - 1).astype(int)
        covered = images.mask[k][j, i]
        result &= in_cube & covered & (1.0 - uvh[..., 2] >= images.depth[k][j, i])
    return result


def voxel_carve(images: DepthImages, n: int) -> np.ndarray:
    """(n, n, n) bool occupancy of the cube's voxel centres, indexed [z, y, x] in cube
    coordinates (the 3D-texture order [w, v, u]), carved by all six images (`inside`)."""
    _check(images)
    if isinstance(n, bool) or not isinstance(n, int | np.integer) or not 1 <= n <= 1024:
        raise UsageError(f"voxel_carve needs an integer grid size in [1, 1024], got {n!r}")
    centres = (np.arange(n) + 0.5) / n
    z, y, x = np.meshgrid(centres, centres, centres, indexing="ij")
    world = transform_points(images.cube_to_world, np.stack([x, y, z], axis=-1))
    return inside(images, world)


@njit(cache=True)
def _fits(bounds, axis, v, n) -> bool:
    """Whether the object's interval along ``axis`` at voxel v's column meets the voxel."""
    lo, hi = _column(bounds, axis, v, n)
    return max(lo, v[axis] / n) <= min(hi, (v[axis] + 1) / n)


@njit(cache=True)
def _occupied_columns(bounds, n, out):
    v = np.empty(3, np.int64)
    for a in range(3):
        p, q = (1, 2) if a == 0 else ((0, 2) if a == 1 else (0, 1))
        for i in range(n):
            for j in range(n):
                lo, hi = bounds[a, 0, i, j], bounds[a, 1, i, j]
                if lo > hi:
                    continue
                v[p], v[q] = i, j
                first = max(0, min(n - 1, int(np.floor(lo * n))))
                last = max(0, min(n - 1, int(np.ceil(hi * n))))
                for c in range(first, last + 1):
                    v[a] = c
                    if _fits(bounds, 0, v, n) and _fits(bounds, 1, v, n) and \
                            _fits(bounds, 2, v, n):
                        out[a, i, j] = True
                        break


def occupied_columns(images: DepthImages) -> np.ndarray:
    """(3, N, N) bool: per cube axis a, whether the column of voxels along a at the other
    two voxel indices (in increasing axis order) holds any voxel where the nearest-texel
    object is not empty (its box there meets the voxel, with a zero or positive extent on
    every axis); computed column by column (only the voxels within a's own interval), never
    as an N^3 array."""
    _check(images)
    n = images.resolution
    out = np.zeros((3, n, n), bool)
    _occupied_columns(images.column_bounds(), n, out)
    return out


def carved_fraction(images: DepthImages) -> np.ndarray:
    """(6,) per face: the fraction of its silhouette whose texel column holds no part of the
    object, i.e. what the other images carve away (open or paper-thin surfaces seen edge-on
    by them: a ground plane, a sheet). Closed solids give about 0."""
    occupied = occupied_columns(images)

    out = np.zeros(6)
    for face, k in FACE_INDEX.items():
        mask = images.mask[k]
        if not mask.any():
            continue
        axis = "xyz".index(face[-1])
        column = occupied[axis]  # indexed by the other two axes in order
        rows, cols = np.nonzero(mask)

        frame = axis_frame(face)
        corner = 0.5 - 0.5 * frame.sum(axis=0)
        u, v = (cols + 0.5) / images.resolution, (rows + 0.5) / images.resolution
        q = corner + u[:, None] * frame[0] + v[:, None] * frame[1]
        others = [a for a in range(3) if a != axis]
        ib = np.floor(q[:, others[0]] * images.resolution).astype(int)
        ic = np.floor(q[:, others[1]] * images.resolution).astype(int)
        out[k] = float((~column[ib, ic]).mean())
    return out
