"""Renders of depth objects measured against the exact CPU reference (reference.py)."""

from __future__ import annotations

import numpy as np

from .reference import exact_intersection


def against_reference(frame, images, camera, *, tolerance_texels: float = 1.0,
                      reference=None) -> dict:
    """Mask IoU, depth error and wrong pixels of ``frame`` against the exact intersection.

    A pixel is wrong where exactly one of the two hits, or both hit more than
    ``tolerance_texels`` texels apart; ``wrong_fraction`` is over the pixels either hits.
    ``depth_rms_texels`` is the RMS distance between the two hit points where both hit, in
    texels of the images. ``reference`` reuses an earlier `exact_intersection` result.
    """
    ref_mask, ref_pos, _ = reference if reference is not None else \
        exact_intersection(images, camera)
    got = frame.mask & np.isfinite(frame.position).all(axis=-1)
    both = got & ref_mask
    union = got | ref_mask
    error = np.zeros(got.shape)
    error[both] = np.linalg.norm(frame.position[both] - ref_pos[both], axis=-1) / images.texel
    wrong = (got != ref_mask) | (both & (error > tolerance_texels))
    n_union = max(int(union.sum()), 1)
    return {"iou": float(both.sum() / n_union),
            "depth_rms_texels": float(np.sqrt((error[both] ** 2).mean())) if both.any() else 0.0,
            "wrong_fraction": float(wrong.sum() / n_union), "wrong": wrong,
            "missed": int((ref_mask & ~got).sum()), "extra": int((got & ~ref_mask).sum()),
            "reference_pixels": int(ref_mask.sum())}
