"""The plane-space density's per-face increments, compiled (the generator's hot loop).

Every face adds to every direction of plane space (`cloud._Grid`): a plane search costs about
two passes over (faces x directions), 50-70 million pairs for a 100k-triangle mesh at epsilon
0.05. Done with numpy, each pair went through a dozen temporary arrays and a bincount; here
each direction is one thread's loop over the faces, writing its own row of the difference
array, so the rows never race and the sums do not depend on the thread count.

The arithmetic is numpy's: projections and bin bounds in float32 with the same operations
in the same order (a face's bins are bit-identical whichever call adds or removes it), and
the weights summed into the float64 rows.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ...reference.heightfield import JIT_OPTIONS


@njit(parallel=True, **JIT_OPTIONS)
def add_faces(diff, points, tris, normals, areas, dirs, eps, eps2, base, outer, penalty,
              sign):
    """Add ``sign`` x the increments of faces ``tris`` (indices into ``points``) to ``diff``.

    diff (D, bins + 1) float64, one row per direction; points (V, 3) float32 vertex
    positions in bin units; tris (F, 3) int64; normals (F, 3) and areas (F,) float32;
    dirs (D, 3) float32; eps and eps2 (= 2 eps), base (the bin coordinate of rho = 0) and
    outer (the first bin with rho >= 0) in bin units and penalty: float32; sign float64.

    Per (face, direction), where the face's extent fits in 2 eps: +gain (area x |cos|) on
    the bins of its valid range [high - eps, low + eps], -penalty x gain on its outer miss
    band ([low - eps, low) where rho >= 0, (high, high + eps] where rho < 0), written as
    four difference entries: band start, range start, range end, band end.
    """
    for j in prange(dirs.shape[0]):
        dx, dy, dz = dirs[j, 0], dirs[j, 1], dirs[j, 2]
        proj = np.empty(points.shape[0], np.float32)
        for v in range(points.shape[0]):
            proj[v] = points[v, 0] * dx + points[v, 1] * dy + points[v, 2] * dz
        row = diff[j]
        for f in range(tris.shape[0]):
            a, b, c = proj[tris[f, 0]], proj[tris[f, 1]], proj[tris[f, 2]]
            low = min(min(a, b), c) + base
            high = max(max(a, b), c) + base
            if not high - low <= eps2:
                continue
            gain = abs(normals[f, 0] * dx + normals[f, 1] * dy + normals[f, 2] * dz) * areas[f]
            miss = gain * penalty
            band_start = int(max(np.ceil(high - eps2), outer))
            start = int(np.ceil(high - eps))
            end = int(np.floor(low + eps)) + 1
            band_end = int(min(np.floor(low + eps2), outer - 1)) + 1
            m1 = miss if band_start < start else np.float32(0.0)
            m2 = miss if band_end > end else np.float32(0.0)
            if not start < end:
                gain = np.float32(0.0)
            row[band_start] += sign * np.float64(-m1)
            row[start] += sign * np.float64(gain + m1)
            row[end] += sign * np.float64(-(gain + m2))
            row[band_end] += sign * np.float64(m2)
