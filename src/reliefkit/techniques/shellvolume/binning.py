"""Screen-space binning of a shell's tetrahedra: which pixels each one's projection may
cover, and per tile of pixels the tetrahedra to test (CSR lists). Shared by the exact
checkers that cast one ray per pixel against every tetrahedron (`order_check`,
`reference`); it only prunes, so it never changes their results.
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: Pixels of slack around each projected bounding rectangle (rounding never drops a pixel).
MARGIN = 1.0


def screen_boxes(shell, camera, width: int, height: int):
    """Per tetrahedron the inclusive pixel column and row ranges its projection may cover
    (empty ranges when it is off screen; the whole screen when a vertex is behind the eye)."""
    m = np.asarray(camera.proj, dtype=np.float64) @ np.asarray(camera.view, dtype=np.float64)
    corners = shell.positions[shell.tets]  # (T, 4, 3)
    clip = corners @ m[:2, :3].T + m[:2, 3]
    w = corners @ m[3, :3] + m[3, 3]
    behind = (w <= 1e-12 * max(1.0, float(np.abs(w).max(initial=0.0)))).any(axis=1)
    w = np.where(behind[:, None], 1.0, w)
    x = (clip[..., 0] / w + 1.0) * 0.5 * width
    y = (1.0 - clip[..., 1] / w) * 0.5 * height
    # pixel c's sample is at c + 0.5
    lo_c = np.ceil(x.min(axis=1) - 0.5 - MARGIN)
    hi_c = np.floor(x.max(axis=1) - 0.5 + MARGIN)
    lo_r = np.ceil(y.min(axis=1) - 0.5 - MARGIN)
    hi_r = np.floor(y.max(axis=1) - 0.5 + MARGIN)
    lo_c = np.where(behind, 0, np.clip(lo_c, 0, width)).astype(np.int64)
    hi_c = np.where(behind, width - 1, np.clip(hi_c, -1, width - 1)).astype(np.int64)
    lo_r = np.where(behind, 0, np.clip(lo_r, 0, height)).astype(np.int64)
    hi_r = np.where(behind, height - 1, np.clip(hi_r, -1, height - 1)).astype(np.int64)
    return lo_c, hi_c, lo_r, hi_r


@njit(cache=True)
def bin_by_tile(lo_c, hi_c, lo_r, hi_r, tiles_x, tiles_y, tile):
    """CSR lists of tetrahedra per tile (row-major), each list in increasing index."""
    n = lo_c.shape[0]
    counts = np.zeros(tiles_x * tiles_y + 1, np.int64)
    for i in range(n):
        if lo_c[i] > hi_c[i] or lo_r[i] > hi_r[i]:
            continue
        for ty in range(lo_r[i] // tile, hi_r[i] // tile + 1):
            for tx in range(lo_c[i] // tile, hi_c[i] // tile + 1):
                counts[ty * tiles_x + tx + 1] += 1
    starts = np.cumsum(counts)
    fill = starts[:-1].copy()
    items = np.empty(starts[-1], np.int64)
    for i in range(n):
        if lo_c[i] > hi_c[i] or lo_r[i] > hi_r[i]:
            continue
        for ty in range(lo_r[i] // tile, hi_r[i] // tile + 1):
            for tx in range(lo_c[i] // tile, hi_c[i] // tile + 1):
                k = ty * tiles_x + tx
                items[fill[k]] = i
                fill[k] += 1
    return starts, items
