"""The exact CPU reference of one-polygon displacement maps, and the compare metric.

A flat base polygon with constant normals and an affine uv map, tile (1, 1), displaced by a
clamped texture is a heightfield on a box (`DisplacementMap.one_polygon_box`): each pixel's
ray is clipped to the box and intersected exactly with the bilinear heightfield by
`reliefkit.reference.heightfield.intersect_rays` (the relief textures' reference). What
counts as a hit depends on the alpha test: the ``fill`` test (surface slicing's default, and
orthogonal and screen slicing's, which draw the base too) draws the base where the height is
0, so a hit on the box's floor counts where the colour's alpha is at least 0.5 (a projected
mesh's background is empty); for the ``bound`` test floor hits on zero texels are misses.
"""

from __future__ import annotations

import numpy as np

from ...core.transforms import homogeneous, invert_box
from ...errors import UsageError
from ...reference.heightfield import intersect_rays, surface_height
from ...scene.camera import pixel_segments
from .displacement import DisplacementMap

FLOOR_EPS = 1e-7


def _clip(fa, fb, lo, hi) -> None:
    both_out = (fa < 0) & (fb < 0)
    crossing = (fa < 0) != (fb < 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(crossing, fa / np.where(crossing, fa - fb, 1.0), 0.0)
    entering = crossing & (fa < 0)
    leaving = crossing & (fa >= 0)
    lo[entering] = np.maximum(lo[entering], t[entering])
    hi[leaving] = np.minimum(hi[leaving], t[leaving])
    lo[both_out], hi[both_out] = 1.0, 0.0


def reference_hits(rep: DisplacementMap, camera, *, floor: bool) -> tuple[np.ndarray,
                                                                          np.ndarray]:
    """(mask (H, W), world positions (H, W, 3), NaN where none) of the exact first hits;
    ``floor``: hits on the base where the height is 0 count (the fill test)."""
    box = rep.one_polygon_box()
    if box is None or rep.wrap:
        raise UsageError("the exact reference needs a one-polygon displacement map (a flat "
                         "base, constant normals, affine uvs, tile 1,1, not wrapped)")
    world_to_box = invert_box(box)
    w, h = camera.size
    near, far = (p.reshape(-1, 3) for p in pixel_segments(camera))
    a = homogeneous(near) @ world_to_box.T
    b = homogeneous(far) @ world_to_box.T
    lo, hi = np.zeros(len(a)), np.ones(len(a))
    for k in range(3):
        _clip(a[:, k], b[:, k], lo, hi)
        _clip(1.0 - a[:, k], 1.0 - b[:, k], lo, hi)
    rows = np.flatnonzero(hi > lo)
    p0 = np.clip(a[rows, :3] + lo[rows, None] * (b[rows, :3] - a[rows, :3]), 0, 1)
    p1 = np.clip(a[rows, :3] + hi[rows, None] * (b[rows, :3] - a[rows, :3]), 0, 1)
    height = rep.height.astype(np.float64)
    t = intersect_rays(height, p0, p1 - p0)
    hit = t <= 1.0 + 1e-9
    rows, t, p0, d = rows[hit], np.minimum(t[hit], 1.0), p0[hit], (p1 - p0)[hit]
    q = p0 + t[:, None] * d
    hh, ww = height.shape
    on_floor = (q[:, 2] < FLOOR_EPS) & (surface_height(height, q[:, 0] * ww,
                                                       q[:, 1] * hh) <= FLOOR_EPS)
    if floor:
        alpha = surface_height(rep.color[..., 3].astype(np.float64), q[:, 0] * ww, q[:, 1] * hh)
        on_floor &= alpha < 0.5
    rows, q = rows[~on_floor], q[~on_floor]
    mask = np.zeros(w * h, bool)
    mask[rows] = True
    pos = np.full((w * h, 3), np.nan)
    pos[rows] = q @ box[:3, :3].T + box[:3, 3]
    return mask.reshape(h, w), pos.reshape(h, w, 3)


def wrong_hits(frame, rep: DisplacementMap, camera, *, floor: bool | None = None,
               tolerance_texels: float = 1.0) -> dict:
    """Pixels where a slicing render disagrees with the exact reference: exactly one of them
    hits, or both hit more than ``tolerance_texels`` height texels apart (world distance
    over the world size of one texel). ``floor`` defaults to the frame's alpha test."""
    if floor is None:
        floor = frame.stats.get("alpha_test") == "fill"
    mask, position = reference_hits(rep, camera, floor=floor)
    box = rep.one_polygon_box()
    hh, ww = rep.height.shape
    texel = min(np.linalg.norm(box[:3, 0]) / ww, np.linalg.norm(box[:3, 1]) / hh)
    both = mask & frame.mask
    dist = np.full(mask.shape, np.nan)
    dist[both] = np.linalg.norm(frame.position[both] - position[both], axis=1) / texel
    far = np.zeros_like(mask)
    far[both] = dist[both] > tolerance_texels
    wrong = (mask != frame.mask) | far
    union = mask | frame.mask
    return {"wrong": wrong, "wrong_pixels": int(wrong.sum()),
            "wrong_fraction": float(wrong.sum() / max(union.sum(), 1)),
            "missed": int((mask & ~frame.mask).sum()), "extra": int((frame.mask & ~mask).sum()),
            "misplaced": int(far.sum()), "reference_pixels": int(mask.sum()),
            "depth_error_texels": float(np.nanmean(dist)) if both.any() else 0.0}


def one_polygon(rep) -> bool:
    return isinstance(rep, DisplacementMap) and not rep.wrap and \
        rep.one_polygon_box() is not None


def against_reference(frame, rep, camera):
    """The compare metric: ``reference_wrong`` (wrong-hit fraction, `wrong_hits`) and
    ``reference_depth_texels`` (mean distance of the hits in height texels) against the exact
    reference, for one-polygon maps (nothing for others)."""
    if not one_polygon(rep):
        return {}, None
    out = wrong_hits(frame, rep, camera)
    return ({"reference_wrong": out["wrong_fraction"],
             "reference_depth_texels": out["depth_error_texels"],
             "slices": frame.stats.get("slices", 0)}, out["wrong"])
