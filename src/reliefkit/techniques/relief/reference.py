"""Exact per-pixel hits of a relief texture seen by a camera (CPU), for tests and `compare`.

Each pixel's ray runs from the near to the far plane. It is clipped to the unit cube in
homogeneous box coordinates (0 <= x, y, z <= w, w > 0), exactly as the shader does
(core:include/raybox.glsl), because a reverse-perspective ``box_to_world`` is projective: a
finite world segment can cross its plane at infinity, and dividing by w first would fold
the segment back into the box.
"""

from __future__ import annotations

import numpy as np

from ...core.transforms import homogeneous
from ...reference.heightfield import intersect_rays, surface_height
from ...scene.camera import pixel_segments
from .representation import ReliefObject, ReliefTexture

FLOOR_EPS = 1e-7
FLOOR_STEP = 1e-6  # how far along its box segment a ray rising through the floor is resumed


def _clip(fa: np.ndarray, fb: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> None:
    """Clip the spans [lo, hi] of segments a + t (b - a) to the halfspaces f >= 0 (in place)."""
    both_out = (fa < 0) & (fb < 0)
    crossing = (fa < 0) != (fb < 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(crossing, fa / (fa - fb), 0.0)
    entering = crossing & (fa < 0)
    leaving = crossing & (fa >= 0)
    lo[entering] = np.maximum(lo[entering], t[entering])
    hi[leaving] = np.minimum(hi[leaving], t[leaving])
    lo[both_out], hi[both_out] = 1.0, 0.0


def box_segments(relief: ReliefTexture, near: np.ndarray, far: np.ndarray):
    """The world segments ``near -> far`` clipped to the relief's box, in box coordinates.

    Returns (origin, direction, valid, world_span): for valid rows the box segment is
    ``origin + t * direction`` for t in [0, 1], and ``world_span`` its [t0, t1] along the
    world segment (to order hits of several parts by world distance).
    """
    a = homogeneous(near) @ relief.world_to_box.T
    b = homogeneous(far) @ relief.world_to_box.T
    lo, hi = np.zeros(len(a)), np.ones(len(a))
    _clip(a[:, 3], b[:, 3], lo, hi)
    for k in range(3):
        _clip(a[:, k], b[:, k], lo, hi)
        _clip(a[:, 3] - a[:, k], b[:, 3] - b[:, k], lo, hi)
    valid = hi > lo
    h0 = a + lo[:, None] * (b - a)
    h1 = a + hi[:, None] * (b - a)
    safe = np.where(valid[:, None], 1.0, 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        p0 = np.clip(np.where(valid[:, None], h0[:, :3] / h0[:, 3:4], 0.0), 0.0, 1.0) * safe
        p1 = np.clip(np.where(valid[:, None], h1[:, :3] / h1[:, 3:4], 0.0), 0.0, 1.0) * safe
    return p0, p1 - p0, valid, np.stack([lo, hi], axis=1)


def _first_hits(height, origin, direction, rows):
    """(rows that hit, box hit points) of the segments ``origin + t direction``, t in [0, 1].

    A contact with the floor of an empty texel is no hit: a segment going down leaves the
    box there, one coming up through the floor (its entry) goes on, as in the shader.
    """
    hh, ww = height.shape

    def hits(start, rows):
        # the rest of each segment, from its parameter ``start`` on, as a segment of its own
        rest = direction[rows] * (1.0 - start)
        t = intersect_rays(height, origin[rows] + start * direction[rows], rest)
        hit = t <= 1.0 + 1e-9
        rows = rows[hit]
        box = origin[rows] + start * direction[rows] + np.minimum(t[hit], 1.0)[:, None] * rest[hit]
        on_floor = (box[:, 2] < FLOOR_EPS) & (
            surface_height(height, box[:, 0] * ww, box[:, 1] * hh) <= FLOOR_EPS)
        return rows, box, on_floor

    rows, box, on_floor = hits(0.0, rows)
    rising = on_floor & (direction[rows, 2] > 0.0)
    again, again_box, again_floor = hits(FLOOR_STEP, rows[rising])
    keep = ~on_floor
    return (np.concatenate([rows[keep], again[~again_floor]]),
            np.concatenate([box[keep], again_box[~again_floor]]))


def reference_hits(relief, camera) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(mask (H, W), world positions (H, W, 3) NaN where no hit, part index (H, W), -1 where
    none) of the exact first hits.

    The bottom face of the box is not a surface where the height is 0 (representation.py),
    so reference hits on the floor of empty texels count as misses. Hits of several parts
    are ordered by their parameter along the world segment, which is monotonic in distance
    for perspective and orthographic cameras alike.
    """
    parts = relief.parts if isinstance(relief, ReliefObject) else [relief]
    w, h = camera.size
    near, far = (p.reshape(-1, 3) for p in pixel_segments(camera))
    best = np.full(w * h, np.inf)
    best_pos = np.full((w * h, 3), np.nan)
    best_part = np.full(w * h, -1)
    for index, part in enumerate(parts):
        origin, direction, valid, span = box_segments(part, near, far)
        rows, box = _first_hits(part.height, origin, direction, np.flatnonzero(valid))
        world = part.to_world(box)
        # the hit's parameter along the world segment near -> far
        seg = far[rows] - near[rows]
        along = np.einsum("ij,ij->i", world - near[rows], seg) / np.einsum("ij,ij->i", seg, seg)
        closer = along < best[rows]
        best[rows[closer]] = along[closer]
        best_pos[rows[closer]] = world[closer]
        best_part[rows[closer]] = index
    mask = np.isfinite(best)
    return mask.reshape(h, w), best_pos.reshape(h, w, 3), best_part.reshape(h, w)


def wrong_hits(frame, relief, camera, *, tolerance_texels: float = 1.0) -> dict:
    """Pixels where a rendering disagrees with the exact reference.

    A pixel is wrong if exactly one of them hits, or both hit more than
    ``tolerance_texels`` texels apart, measured in the texel units of the part the
    reference hit lies in.
    """
    mask, position, part_of = reference_hits(relief, camera)
    parts = relief.parts if isinstance(relief, ReliefObject) else [relief]
    both = mask & frame.mask
    far = np.zeros_like(mask)
    for index, part in enumerate(parts):
        here = both & (part_of == index)
        if not here.any():
            continue
        texel = np.array([part.height.shape[1], part.height.shape[0],
                          max(part.height.shape)], dtype=np.float64)
        delta = (part.to_box(frame.position[here]) - part.to_box(position[here])) * texel
        far[here] = np.linalg.norm(delta, axis=1) > tolerance_texels
    wrong = (mask != frame.mask) | far
    union = mask | frame.mask
    return {"wrong": wrong, "wrong_pixels": int(wrong.sum()),
            "wrong_fraction": float(wrong.sum() / max(union.sum(), 1)),
            "missed": int((mask & ~frame.mask).sum()), "extra": int((frame.mask & ~mask).sum()),
            "misplaced": int(far.sum()), "reference_pixels": int(mask.sum())}
