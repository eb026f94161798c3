"""Procedural displacement textures (periodic, so they tile and wrap): colour (H, W, 4) float32
linear + height (H, W) float32 in [0, 1]; and the terrain palette of heightmap inputs.

* ``fur``: tufts of hair on a jittered grid over a thin skin (height 0.12), each a cone of
  random height 0.55..1 (Fig. 1's furry donut).
* ``bumps``: smooth round bumps on a jittered grid, zero between them (the base shows).
* ``waves``: two crossing sine waves, heights 0.1..1.
"""

from __future__ import annotations

import numpy as np

from ...errors import UsageError


def _grid(res: int):
    s = (np.arange(res) + 0.5) / res
    return np.meshgrid(s, s)


def _periodic_distance(x, y, cx, cy):
    dx = np.abs(x - cx)
    dy = np.abs(y - cy)
    dx = np.minimum(dx, 1 - dx)
    dy = np.minimum(dy, 1 - dy)
    return np.hypot(dx, dy)


def _jittered(cells: int, seed: int):
    rng = np.random.default_rng(seed)
    j, i = np.meshgrid(np.arange(cells), np.arange(cells), indexing="ij")
    cx = (i.ravel() + 0.2 + 0.6 * rng.random(cells * cells)) / cells
    cy = (j.ravel() + 0.2 + 0.6 * rng.random(cells * cells)) / cells
    return cx, cy, rng


def fur(res: int = 64, seed: int = 1):
    x, y = _grid(res)
    cells = max(2, res // 6)
    cx, cy, rng = _jittered(cells, seed)
    tall = 0.55 + 0.45 * rng.random(len(cx))
    radius = 0.45 / cells
    height = np.full(x.shape, 0.12)
    for k in range(len(cx)):
        d = _periodic_distance(x, y, cx[k], cy[k])
        height = np.maximum(height, tall[k] * np.clip(1 - d / radius, 0, 1))
    shade = 0.35 + 0.65 * height
    color = np.stack([0.45 * shade, 0.27 * shade, 0.12 * shade, np.ones_like(x)], -1)
    return color.astype(np.float32), height.astype(np.float32)


def bumps(res: int = 64, seed: int = 2):
    x, y = _grid(res)
    cells = 4
    cx, cy, rng = _jittered(cells, seed)
    radius = 0.38 / cells
    height = np.zeros(x.shape)
    for k in range(len(cx)):
        d = _periodic_distance(x, y, cx[k], cy[k])
        r = (0.8 + 0.4 * rng.random()) * radius
        height = np.maximum(height, np.sqrt(np.clip(1 - (d / r) ** 2, 0, 1)))
    color = np.stack([0.2 + 0.6 * height, 0.35 + 0.2 * height, 0.7 - 0.4 * height,
                      np.ones_like(x)], -1)
    return color.astype(np.float32), height.astype(np.float32)


def waves(res: int = 64, seed: int = 0):
    x, y = _grid(res)
    height = 0.1 + 0.9 * (0.5 + 0.25 * np.sin(2 * np.pi * 2 * x) + 0.25 * np.sin(
        2 * np.pi * 3 * y))
    color = np.stack([0.1 + 0.3 * height, 0.3 + 0.4 * height, 0.5 + 0.4 * height,
                      np.ones_like(x)], -1)
    return color.astype(np.float32), np.clip(height, 0, 1).astype(np.float32)


TEXTURES = {"fur": fur, "bumps": bumps, "waves": waves}


def make_texture(name: str, res: int):
    if name not in TEXTURES:
        raise UsageError(f"unknown displacement texture {name!r} (choose from "
                         f"{', '.join(TEXTURES)}, or give a heightmap .png/.npy)")
    return TEXTURES[name](res=int(res))


_PALETTE = np.array([[0.0, 0.05, 0.18, 0.45], [0.15, 0.16, 0.38, 0.12],
                     [0.45, 0.35, 0.28, 0.15], [0.75, 0.45, 0.42, 0.40],
                     [1.0, 0.92, 0.92, 0.95]])  # height, linear r, g, b


def terrain_colors(height: np.ndarray) -> np.ndarray:
    """(H, W, 4) float32 linear colours of a terrain palette over heights in [0, 1]."""
    h = np.clip(np.asarray(height, np.float64), 0, 1)
    rgb = np.stack([np.interp(h, _PALETTE[:, 0], _PALETTE[:, c]) for c in (1, 2, 3)], -1)
    return np.concatenate([rgb, np.ones((*h.shape, 1))], -1).astype(np.float32)


def normalised_heights(heights: np.ndarray) -> np.ndarray:
    """Heights kept as they are when already in [0, 1], else rescaled to [0, 1]."""
    h = np.asarray(heights, np.float64)
    if h.ndim != 2 or min(h.shape) < 2:
        raise UsageError(f"a heightmap must be a 2D array of at least 2x2, got {h.shape}")
    if not np.isfinite(h).all():
        raise UsageError("the heightmap contains NaN or Inf values")
    if h.min() >= 0 and h.max() <= 1:
        return h.astype(np.float32)
    span = float(h.max() - h.min())
    return ((h - h.min()) / span if span > 0 else np.zeros_like(h)).astype(np.float32)
