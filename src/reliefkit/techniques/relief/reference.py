"""Exact per-pixel hits of a relief texture seen by a camera (CPU), for tests and `compare`."""

from __future__ import annotations

import numpy as np

from .reference_heightfield import intersect_rays, surface_height
from .representation import ReliefObject, ReliefTexture

FLOOR_EPS = 1e-7


def _pixel_rays_in_box(relief: ReliefTexture, camera):
    """Box-space origins (near plane) and directions of every pixel ray, (H*W, 3) each."""
    origins, dirs = camera.pixel_rays()
    centre = np.asarray(relief.to_world(np.array([0.5, 0.5, 0.5])))
    reach = np.linalg.norm(centre - np.asarray(camera.eye))
    near = origins.reshape(-1, 3)
    a = relief.to_box(near)
    b = relief.to_box(near + reach * dirs.reshape(-1, 3))
    return a, b - a


def reference_hits(relief, camera) -> tuple[np.ndarray, np.ndarray]:
    """(mask (H, W), world positions (H, W, 3) NaN where no hit) of the exact first hits.

    The bottom face of the box is not a surface where the height is 0 (representation.py),
    so reference hits on the floor of empty texels count as misses.
    """
    parts = relief.parts if isinstance(relief, ReliefObject) else [relief]
    w, h = camera.size
    best_dist = np.full(w * h, np.inf)
    best_pos = np.full((w * h, 3), np.nan)
    eye = np.asarray(camera.eye)
    for part in parts:
        a, d = _pixel_rays_in_box(part, camera)
        t = intersect_rays(part.height, a, d)
        hit = np.isfinite(t)
        box = a[hit] + t[hit, None] * d[hit]
        height_w, height_h = part.height.shape[1], part.height.shape[0]
        on_floor = (box[:, 2] < FLOOR_EPS) & (
            surface_height(part.height, box[:, 0] * height_w, box[:, 1] * height_h)
            <= FLOOR_EPS)
        idx = np.flatnonzero(hit)[~on_floor]
        world = part.to_world(box[~on_floor])
        dist = np.linalg.norm(world - eye, axis=1)
        closer = dist < best_dist[idx]
        best_dist[idx[closer]] = dist[closer]
        best_pos[idx[closer]] = world[closer]
    mask = np.isfinite(best_dist)
    return mask.reshape(h, w), best_pos.reshape(h, w, 3)


def wrong_hits(frame, relief, camera, *, tolerance_texels: float = 1.0) -> dict:
    """Pixels where a rendering disagrees with the exact reference.

    A pixel is wrong if exactly one of them hits, or both hit more than
    ``tolerance_texels`` texels apart (measured in box texel units of the first part).
    """
    mask, position = reference_hits(relief, camera)
    part = relief.parts[0] if isinstance(relief, ReliefObject) else relief
    both = mask & frame.mask
    texel = np.array([part.height.shape[1], part.height.shape[0],
                      max(part.height.shape)], dtype=np.float64)
    far = np.zeros_like(mask)
    if both.any():
        delta = (part.to_box(frame.position[both]) - part.to_box(position[both])) * texel
        far[both] = np.linalg.norm(delta, axis=1) > tolerance_texels
    wrong = (mask != frame.mask) | far
    union = mask | frame.mask
    return {"wrong": wrong, "wrong_pixels": int(wrong.sum()),
            "wrong_fraction": float(wrong.sum() / max(union.sum(), 1)),
            "missed": int((mask & ~frame.mask).sum()), "extra": int((frame.mask & ~mask).sum()),
            "misplaced": int(far.sum()), "reference_pixels": int(mask.sum())}
