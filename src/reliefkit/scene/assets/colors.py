"""Colour helpers of the assets: 8-bit sRGB picks as linear RGB, mixing and smooth steps."""

from __future__ import annotations

import numpy as np

from ...colorspace import srgb_decode


def rgb(r: int, g: int, b: int) -> np.ndarray:
    """Linear RGB of an 8-bit sRGB colour."""
    return srgb_decode(np.array([r, g, b], dtype=np.float64) / 255.0)


def mix(a, b, t) -> np.ndarray:
    """Linear interpolation ``a + (b - a) * t`` with `t` broadcast over colour channels."""
    t = np.asarray(t, dtype=np.float64)
    if t.ndim:
        t = t[..., None]
    return np.asarray(a) + (np.asarray(b) - np.asarray(a)) * t


def smoothstep(edge0: float, edge1: float, x) -> np.ndarray:
    """Hermite step from 0 at `edge0` to 1 at `edge1` (``edge0 > edge1`` gives a falling step)."""
    t = np.clip((np.asarray(x, dtype=np.float64) - edge0) / (edge1 - edge0), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)
