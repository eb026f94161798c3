"""Relaxed cone maps (Policarpo & Oliveira, GPU Gems 3, ch. 18) for the `cone` method.

A texel's relaxed cone has its apex on the surface at the texel's centre and opens upward
with ratio ``c`` (horizontal texels per unit of height). It is the widest cone such that a
ray from the top of the box above the texel, through any other texel's surface point B,
does not leave the solid again (after entering at B) inside the cone: stepping along a ray
to where it meets the cone under it can cross into the solid but not out of it, so at most
one surface crossing lies in each step and a binary search at the end finds it (§18.3).

Computation (the chapter's listing marches every pair of texels, O(N^4) for N x N): for
texel A of height h_A, only texels B higher than A can give a constraint, and the exit point
P found after B lies at least as far from A as B and no higher than B, so B can lower the
ratio only if ``|B - A| / (h_B - h_A)`` is below the best ratio found so far. Texels B are
visited in square rings of growing radius k around A, and the search stops once ``k /
(h_max - h_A)`` reaches the best ratio (no texel of that ring or beyond can lower it). From
B the ray is marched half a texel at a time (on the bilinear surface of
:mod:`reliefkit.reference.heightfield`) until it rises above the surface (the exit P:
ratio ``|P - A| / (z_P - h_A)``), sinks below A's height, or leaves the field. Only a
window of `WINDOW` texels around A is searched, and the ratio is capped at ``WINDOW / (h_max
- h_A)`` so that nothing outside the window could lower it: a narrower cone is still a
relaxed cone (it takes more steps), so the cap trades iterations for precomputation time.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from ...reference.heightfield import as_height, surface_at

MARCH_STEP = 0.5  # texels


@njit(parallel=True, cache=True, error_model="numpy")
def _ratios(height, max_ratio, window):
    hh, ww = height.shape
    h_max = height.max()
    out = np.empty((hh, ww), np.float32)
    for j in prange(hh):
        for i in range(ww):
            ha = height[j, i]
            rise = h_max - ha
            # nothing beyond the window is looked at: the cone is kept narrow enough that
            # nothing there could matter (a narrower cone is always a safe one)
            best = min(max_ratio, window / rise) if rise > 1e-9 else max_ratio
            k = 1
            while rise > 1e-9 and k / rise < best and k <= window:
                for jb in range(j - k, j + k + 1):
                    if jb < 0 or jb >= hh:
                        continue
                    edge = jb == j - k or jb == j + k
                    step = 1 if edge else 2 * k
                    for ib in range(i - k, i + k + 1, step):
                        if ib < 0 or ib >= ww:
                            continue
                        hb = height[jb, ib]
                        if hb <= ha:
                            continue
                        dx, dy = float(ib - i), float(jb - j)
                        r = math.sqrt(dx * dx + dy * dy)
                        if r / (hb - ha) >= best:
                            continue
                        ux, uy = dx / r, dy / r
                        slope = (1.0 - hb) / r  # the ray from the top above A through B
                        s = MARCH_STEP
                        while s <= 2.0 * window:
                            z = hb - slope * s
                            if z <= ha:
                                break
                            px = ib + 0.5 + ux * s
                            py = jb + 0.5 + uy * s
                            if px < 0.0 or py < 0.0 or px > ww or py > hh:
                                break
                            if z > surface_at(height, px, py):  # left the solid at P
                                ex, ey = px - (i + 0.5), py - (j + 0.5)
                                ratio = math.sqrt(ex * ex + ey * ey) / (z - ha)
                                if ratio < best:
                                    best = ratio
                                break
                            s += MARCH_STEP
                k += 1
            out[j, i] = best
    return out


#: Texels around each texel the search looks at (`relaxed_cone_ratios`).
WINDOW = 24


def relaxed_cone_ratios(height, max_ratio: float | None = None,
                        window: int = WINDOW) -> np.ndarray:
    """(H, W) float32 relaxed cone ratios in texels per unit of height, at most
    ``max_ratio`` (default: the field's larger side, a 45-degree cone in the chapter's uv
    units) and at most ``window / (h_max - h)``, so that only texels within ``window`` of
    each texel need to be searched (the cost is O(N^2 window^3), not O(N^4))."""
    h = as_height(height)
    limit = float(max_ratio if max_ratio is not None else max(h.shape))
    return _ratios(h, limit, int(window))
