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
from ...units import format_bytes

#: Texels generated at a time: the textures are made a band of rows at a time, so their
#: float64 temporaries stay this size whatever the resolution.
BAND_TEXELS = 1 << 20


def _banded(res: int, band):
    """(colour (res, res, 4) float32, height (res, res) float32) filled a band of rows at a
    time by ``band(x, y) -> (colour, height)`` of the texel centres x, y (rows, res)."""
    color = np.empty((res, res, 4), np.float32)
    height = np.empty((res, res), np.float32)
    s = (np.arange(res) + 0.5) / res
    rows = max(1, BAND_TEXELS // res)
    for r0 in range(0, res, rows):
        x, y = np.meshgrid(s, s[r0:r0 + rows])
        color[r0:r0 + rows], height[r0:r0 + rows] = band(x, y)
    return color, height


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
    cells = max(2, res // 6)
    cx, cy, rng = _jittered(cells, seed)
    tall = 0.55 + 0.45 * rng.random(len(cx))
    radius = 0.45 / cells  # a tuft (centre 0.2..0.8 into its cell) reaches the next cells only

    def band(x, y):
        height = np.full(x.shape, 0.12)
        i, j = np.floor(x * cells).astype(np.int64), np.floor(y * cells).astype(np.int64)
        for di in (-1, 0, 1):
            for dj in (-1, 0, 1):
                k = ((j + dj) % cells) * cells + (i + di) % cells
                d = _periodic_distance(x, y, cx[k], cy[k])
                height = np.maximum(height, tall[k] * np.clip(1 - d / radius, 0, 1))
        shade = 0.35 + 0.65 * height
        return np.stack([0.45 * shade, 0.27 * shade, 0.12 * shade, np.ones_like(x)], -1), height

    return _banded(res, band)


def bumps(res: int = 64, seed: int = 2):
    cells = 4
    cx, cy, rng = _jittered(cells, seed)
    radii = [(0.8 + 0.4 * rng.random()) * 0.38 / cells for _ in range(len(cx))]

    def band(x, y):
        height = np.zeros(x.shape)
        for k, r in enumerate(radii):
            d = _periodic_distance(x, y, cx[k], cy[k])
            height = np.maximum(height, np.sqrt(np.clip(1 - (d / r) ** 2, 0, 1)))
        return np.stack([0.2 + 0.6 * height, 0.35 + 0.2 * height, 0.7 - 0.4 * height,
                         np.ones_like(x)], -1), height

    return _banded(res, band)


def waves(res: int = 64, seed: int = 0):
    def band(x, y):
        height = 0.1 + 0.9 * (0.5 + 0.25 * np.sin(2 * np.pi * 2 * x) + 0.25 * np.sin(
            2 * np.pi * 3 * y))
        return np.stack([0.1 + 0.3 * height, 0.3 + 0.4 * height, 0.5 + 0.4 * height,
                         np.ones_like(x)], -1), np.clip(height, 0, 1)

    return _banded(res, band)


TEXTURES = {"fur": fur, "bumps": bumps, "waves": waves}
#: The largest procedural texture made: fur, the slowest, takes about `SECONDS_PER_MTEXEL`
#: per million texels (2.3 s measured at 2048² on a loaded 2-core machine, 2026-12-06), so
#: 4096² is about 40 s; the texture holds 20 bytes a texel (colour and height, float32).
MAX_TEXELS = 4096 * 4096
SECONDS_PER_MTEXEL = 2.5
TEXEL_BYTES = 20


def make_texture(name: str, res: int):
    """The procedural texture ``name`` at ``res`` texels per side, refused with its time and
    memory estimate above `MAX_TEXELS`."""
    if name not in TEXTURES:
        raise UsageError(f"unknown displacement texture {name!r} (choose from "
                         f"{', '.join(TEXTURES)}, or give a heightmap .png/.npy)")
    texels = int(res) ** 2
    if texels > MAX_TEXELS:
        minutes = SECONDS_PER_MTEXEL * texels / 1e6 / 60
        raise UsageError(f"a {name} texture of {res}x{res} texels would take up to about "
                         f"{minutes:.0f} minutes here and {format_bytes(TEXEL_BYTES * texels)} "
                         f"(the limit is {MAX_TEXELS ** 0.5:.0f}x{MAX_TEXELS ** 0.5:.0f}); use "
                         "a smaller --res, and --tile to repeat it")
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
