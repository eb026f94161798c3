"""Exact per-pixel hits of `BillboardBoxes` seen by a camera (CPU, float64), for tests and
`compare`'s wrong-hit metric.

The same logic as the shader's exact march (shaders/include/box_march.glsl), vectorized over
pixels: each pixel's segment from the near to the far plane is clipped to the box, then a 3D
DDA over the voxels (volumetric) or a 2D DDA over the texel columns with the exact interval
test in each (shells) finds the first point of the occupied set. Hits of several boxes are
ordered by their parameter along the pixel's world segment.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ...core.transforms import homogeneous, invert_box
from ...scene.camera import pixel_segments
from .box_render import drawn_box_to_world
from .boxes import BillboardBox, BillboardBoxes


class ReferenceHits(NamedTuple):
    """Per pixel (H, W): ``mask``; ``box`` index (-1: none); ``point`` (H, W, 3) the hit in
    that box's coordinates (u, v, w) (NaN: none); ``t`` its parameter along the pixel's
    segment from the near (0) to the far (1) plane (inf: none)."""

    mask: np.ndarray
    box: np.ndarray
    point: np.ndarray
    t: np.ndarray


def texel_intervals(box: BillboardBox, variant: str, thickness: float | None):
    """(lo, hi), (H, W) each: every texel's occupied interval in w (empty texels included)."""
    disp = box.displacement.astype(np.float64) / 65535.0
    if variant == "shell":
        return disp[..., 0] - 0.5 * thickness, disp[..., 0] + 0.5 * thickness
    return disp[..., 0], disp[..., 1]


def clip_to_box(world_to_box: np.ndarray, near: np.ndarray, far: np.ndarray):
    """Segments ``near -> far`` (N, 3) clipped to the unit cube of an affine box.

    Returns (a, b, valid, lo, hi): box coordinates of the clipped ends and their parameters
    along the world segment.
    """
    pa = homogeneous(near) @ world_to_box.T
    pb = homogeneous(far) @ world_to_box.T
    a, d = pa[:, :3], pb[:, :3] - pa[:, :3]
    lo, hi = np.zeros(len(a)), np.ones(len(a))
    with np.errstate(divide="ignore", invalid="ignore"):
        for k in range(3):
            t0, t1 = -a[:, k] / d[:, k], (1.0 - a[:, k]) / d[:, k]
            parallel = d[:, k] == 0
            inside = (a[:, k] >= 0) & (a[:, k] <= 1)
            t0 = np.where(parallel, np.where(inside, -np.inf, np.inf), t0)
            t1 = np.where(parallel, np.where(inside, np.inf, -np.inf), t1)
            lo = np.maximum(lo, np.minimum(t0, t1))
            hi = np.minimum(hi, np.maximum(t0, t1))
    valid = hi > lo
    lo, hi = np.where(valid, lo, 0.0), np.where(valid, hi, 0.0)
    pa_, pb_ = a + lo[:, None] * d, a + hi[:, None] * d
    return np.clip(pa_, 0.0, 1.0), np.clip(pb_, 0.0, 1.0), valid, lo, hi


def _cell_at(p: np.ndarray, d: np.ndarray, res: np.ndarray) -> np.ndarray:
    """The cell containing p, a point on a face belonging to the cell the ray enters."""
    cell = np.where(d < 0, np.ceil(p) - 1, np.floor(p))
    return np.clip(cell, 0, res - 1).astype(np.int64)


def march_exact(box: BillboardBox, variant: str, thickness, o: np.ndarray, d: np.ndarray):
    """The exact first hit of rays ``o + s d`` (voxel coordinates, s in [0, 1]).

    Returns (s, cell): s (N,) inf where the ray misses; cell (N, 3) the hit's (i, j, k)
    (k meaningful for volumetric boxes only).
    """
    res = np.array(box.resolution, np.float64)
    volumetric = variant == "volumetric"
    axes = 3 if volumetric else 2
    occupied = box.color[..., 3] >= 128
    if not volumetric:
        lo_w, hi_w = texel_intervals(box, variant, thickness)
        lo_w, hi_w = np.where(occupied, lo_w, 2.0), np.where(occupied, hi_w, -1.0)
    count = len(o)
    s = np.zeros(count)
    cell = _cell_at(o, d, res)
    hit_s, hit_cell = np.full(count, np.inf), np.full((count, 3), -1, np.int64)
    active = np.arange(count)
    step = np.where(d < 0, -1, 1)
    for _ in range(int(res[:axes].sum()) + 4):
        if not len(active):
            break
        c, oo, dd, ss = cell[active], o[active], d[active], s[active]
        bound = c[:, :axes] + (dd[:, :axes] >= 0)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.where(dd[:, :axes] != 0, (bound - oo[:, :axes]) / dd[:, :axes], np.inf)
        axis = np.argmin(t, axis=1)
        exit_s = t[np.arange(len(active)), axis]
        if volumetric:
            found = occupied[c[:, 2], c[:, 1], c[:, 0]]
            at = ss
        else:
            at = _first_in_interval(oo[:, 2] / res[2], dd[:, 2] / res[2], ss,
                                    np.minimum(exit_s, 1.0), lo_w[c[:, 1], c[:, 0]],
                                    hi_w[c[:, 1], c[:, 0]])
            found = np.isfinite(at)
        hit_s[active[found]] = at[found]
        hit_cell[active[found]] = c[found]
        go = ~found & (exit_s < 1.0)
        rows, axis, exit_s = active[go], axis[go], exit_s[go]
        s[rows] = np.maximum(s[rows], exit_s)
        cell[rows, axis] += step[rows, axis]
        inside = ((cell[rows, :axes] >= 0) & (cell[rows, :axes] < res[:axes])).all(axis=1)
        active = rows[inside]
    return hit_s, hit_cell


def _first_in_interval(w0, dw, s0, s1, lo, hi) -> np.ndarray:
    """The first s in [s0, s1] with w0 + s dw in [lo, hi]; inf where there is none."""
    with np.errstate(divide="ignore", invalid="ignore"):
        ta, tb = (lo - w0) / dw, (hi - w0) / dw
    flat = dw == 0
    first = np.where(flat, np.where((w0 >= lo) & (w0 <= hi), s0, np.inf),
                     np.maximum(s0, np.minimum(ta, tb)))
    last = np.where(flat, s1, np.minimum(s1, np.maximum(ta, tb)))
    ok = (lo <= hi) & (s0 <= s1) & (first <= last)
    return np.where(ok, first, np.inf)


def reference_trace(boxes: BillboardBoxes, camera, flatten: float = 1.0) -> dict:
    """`reference_hits` and more, flattened per pixel: ``cell`` (N, 3) the hit's voxel
    (texel for shells), ``world`` (N, 3) the hit in world coordinates, plus ``mask``,
    ``box``, ``point``, ``t`` (N,)."""
    near, far = (p.reshape(-1, 3) for p in pixel_segments(camera))
    count = len(near)
    out = {"t": np.full(count, np.inf), "box": np.full(count, -1),
           "point": np.full((count, 3), np.nan), "world": np.full((count, 3), np.nan),
           "cell": np.full((count, 3), -1, np.int64)}
    for index, box in enumerate(boxes.boxes):
        to_world = drawn_box_to_world(box.box_to_world, flatten)
        a, b, valid, lo, hi = clip_to_box(invert_box(to_world), near, far)
        rows = np.flatnonzero(valid)
        res = np.array(box.resolution, np.float64)
        s, cell = march_exact(box, boxes.variant, boxes.thickness, a[rows] * res,
                              (b[rows] - a[rows]) * res)
        hit = np.isfinite(s)
        rows, s, cell = rows[hit], s[hit], cell[hit]
        t = lo[rows] + s * (hi[rows] - lo[rows])
        closer = t < out["t"][rows]
        rows, s, cell, t = rows[closer], s[closer], cell[closer], t[closer]
        point = a[rows] + s[:, None] * (b[rows] - a[rows])
        out["t"][rows], out["box"][rows], out["cell"][rows] = t, index, cell
        out["point"][rows] = point
        out["world"][rows] = homogeneous(point) @ to_world[:3].T
    out["mask"] = np.isfinite(out["t"])
    return out


def reference_hits(boxes: BillboardBoxes, camera, flatten: float = 1.0) -> ReferenceHits:
    """The exact first hit of every pixel: see `ReferenceHits`."""
    w, h = camera.size
    ref = reference_trace(boxes, camera, flatten)
    return ReferenceHits(ref["mask"].reshape(h, w), ref["box"].reshape(h, w),
                         ref["point"].reshape(h, w, 3), ref["t"].reshape(h, w))


def wrong_hits(frame, boxes: BillboardBoxes, camera, *, flatten: float = 1.0,
               tolerance_voxels: float = 1.0) -> dict:
    """Pixels where a rendering disagrees with the exact reference: exactly one of them
    hits, or both hit more than ``tolerance_voxels`` apart in the voxel units of the box
    the reference hit lies in."""
    ref = reference_hits(boxes, camera, flatten)
    both = ref.mask & frame.mask
    far = np.zeros_like(ref.mask)
    for index, box in enumerate(boxes.boxes):
        here = both & (ref.box == index)
        if not here.any():
            continue
        world_to_box = invert_box(drawn_box_to_world(box.box_to_world, flatten))
        drawn = homogeneous(frame.position[here]) @ world_to_box[:3].T
        delta = (drawn - ref.point[here]) * np.array(box.resolution, np.float64)
        far[here] = np.linalg.norm(delta, axis=1) > tolerance_voxels
    wrong = (ref.mask != frame.mask) | far
    union = ref.mask | frame.mask
    return {"wrong": wrong, "wrong_pixels": int(wrong.sum()),
            "wrong_fraction": float(wrong.sum() / max(union.sum(), 1)),
            "missed": int((ref.mask & ~frame.mask).sum()),
            "extra": int((frame.mask & ~ref.mask).sum()), "misplaced": int(far.sum()),
            "reference_pixels": int(ref.mask.sum())}
