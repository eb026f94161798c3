"""The sRGB transfer function (exact piecewise form, IEC 61966-2-1): the one copy of it."""

from __future__ import annotations

import numpy as np


def srgb_encode(linear) -> np.ndarray:
    """Linear [0, 1] -> sRGB-encoded [0, 1] (float32)."""
    x = np.clip(np.asarray(linear, dtype=np.float64), 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1.0 / 2.4) - 0.055).astype(
        np.float32)


def srgb_decode(encoded) -> np.ndarray:
    """sRGB-encoded [0, 1] -> linear [0, 1] (float64; values outside [0, 1] are clipped)."""
    x = np.clip(np.asarray(encoded, dtype=np.float64), 0.0, 1.0)
    return np.where(x <= 0.04045, x / 12.92, np.power((x + 0.055) / 1.055, 2.4))


def to_rgba8(color: np.ndarray) -> np.ndarray:
    """(H, W, 4) linear straight-alpha float -> (H, W, 4) uint8 sRGB with alpha."""
    rgb = srgb_encode(color[..., :3])
    alpha = np.clip(color[..., 3:4], 0.0, 1.0)
    return np.round(np.concatenate([rgb, alpha], axis=-1) * 255.0).astype(np.uint8)
