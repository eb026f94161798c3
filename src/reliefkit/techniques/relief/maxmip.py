"""The maximum mipmap of a heightfield (Tevs, Ihrke & Seidel 2008) for the `maxmip` method.

Level 0 holds, per texel square [i, i+1] x [j, j+1] (texel coordinates), the largest height
the bilinear surface reaches over it: the surface there is made of the four bilinear cells
that meet at the texel's centre, whose corners are the texel and its eight neighbours
(clamped at the border), so the 3 x 3 maximum bounds it. The field is padded with zeros
(empty) to a power-of-two square; each further level takes the maximum of 2 x 2 nodes, up to
one node over everything. A ray that stays above a node's maximum cannot hit anything under
it, which is what the traversal in shaders/include/intersect.glsl skips.

A relief texture's draw plan carries the levels as one texture's mip chain (Tevs et al.
build it on the GPU for dynamic heightfields; a relief texture's field never changes).
"""

from __future__ import annotations

import numpy as np


def max_pyramid(height: np.ndarray) -> list[np.ndarray]:
    """[level 0 (P, P), ..., (1, 1)] float32, P the power of two >= the field's sides."""
    from scipy.ndimage import maximum_filter  # scipy: slow to import

    h = np.asarray(height, dtype=np.float32)
    base = maximum_filter(h, size=3, mode="nearest")
    side = pyramid_side(h.shape)
    level = np.zeros((side, side), np.float32)
    level[:h.shape[0], :h.shape[1]] = base
    levels = [level]
    while level.shape[0] > 1:
        n = level.shape[0] // 2
        level = level.reshape(n, 2, n, 2).max(axis=(1, 3))
        levels.append(level)
    return levels


def pyramid_side(shape) -> int:
    """Side of the pyramid's level 0: the power of two >= the field's sides."""
    return 1 << int(np.ceil(np.log2(max(shape))))

