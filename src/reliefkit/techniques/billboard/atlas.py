"""Packing the rectangles' texel blocks into a few square atlas pages (shelf packing).

A cloud is a handful of textures, not one per plane: blocks are sorted by height and laid
left to right on shelves; the page is the smallest power of two that holds them all, or, past
`MAX_PAGE`, several pages of that size. Every block keeps `GUTTER` empty texels around it.
"""

from __future__ import annotations

import numpy as np

from ...errors import UsageError
from .representation import GUTTER

MAX_PAGE = 4096   # texels per side of an atlas page (every GL 4 GPU has at least 16384)
MIN_PAGE = 16


def pack(sizes, max_page: int = MAX_PAGE) -> tuple[int, int, np.ndarray]:
    """Place blocks of (w, h) texels: returns (page side, page count, (P, 3) page, x, y).

    Deterministic: the order depends on the sizes only (taller first, then wider, then
    input order).
    """
    sizes = np.asarray(sizes, dtype=np.int64).reshape(-1, 2)
    if not len(sizes) or (sizes < 1).any():
        raise UsageError("atlas blocks must have at least one texel per side")
    padded = sizes + 2 * GUTTER
    largest = int(padded.max())
    if largest > max_page:
        raise UsageError(f"a rectangle needs {int(sizes.max())} texels on a side, more than an "
                         f"atlas page holds ({max_page - 2 * GUTTER}); bake with a larger "
                         "--texel-size")
    side = max(MIN_PAGE, 1 << (largest - 1).bit_length())
    while True:
        placed = _shelves(padded, side)
        if placed[:, 0].max() == 0 or side >= max_page:
            break
        side *= 2
    placed[:, 1:] += GUTTER
    return side, int(placed[:, 0].max()) + 1, placed


def _shelves(padded: np.ndarray, side: int) -> np.ndarray:
    """(P, 3) page, x, y of every padded block on pages of `side` texels."""
    order = sorted(range(len(padded)), key=lambda k: (-padded[k, 1], -padded[k, 0], k))
    placed = np.zeros((len(padded), 3), np.int64)
    page = x = y = shelf = 0
    for k in order:
        w, h = (int(v) for v in padded[k])
        if x + w > side:                     # next shelf
            x, y, shelf = 0, y + shelf, 0
        if y + h > side:                     # next page
            page, x, y, shelf = page + 1, 0, 0, 0
        placed[k] = page, x, y
        x += w
        shelf = max(shelf, h)
    return placed
