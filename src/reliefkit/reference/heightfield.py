"""Exact CPU ray vs bilinear-patch heightfield intersection (the reference for every walk).

Conventions (docs/architecture.md, "Heightfields"; Baboud & Decoret 2006, section 3.1)
--------------------------------------------------------------------------------------
``height`` is an (H, W) array of values in [0, 1]. A ray is ``o + t * d`` in box coordinates
(u, v, h), restricted to the unit box ``[0, 1]^3`` and to ``t >= 0`` unless a function says
otherwise. Texel coordinates are ``x = u * W`` and ``y = v * H``; ``height[j, i]`` is the
sample at the texel centre ``(i + 0.5, j + 0.5)``. The surface ``S(x, y)`` is the bilinear
interpolation between texel centres, clamped at the border: ``S(x, y) = S(clamp(x, 0.5,
W - 0.5), clamp(y, 0.5, H - 0.5))``. The solid lies below the surface.

The *first hit* is the smallest ``t`` inside the box where ``h <= S`` (on or below the
surface); a ray that enters the box below the surface hits at its entry ``t``, and a ray that
reaches ``h = 0`` is below by definition (``S >= 0``).

Method
------
The projection of the ray is walked cell by cell (Amanatides & Woo in 2D) over the cells
``[i - 0.5, i + 0.5] x [j - 0.5, j + 0.5]`` between centerlines, including the clamped half
cells at the border (cell index ``cx`` runs over ``0 .. W``, cell ``0`` being ``[0, 0.5]`` and
cell ``W`` being ``[W - 0.5, W]``). Inside a cell the surface along the ray is a quadratic in
``t`` (linear or constant in the border cells), so ``F(t) = h(t) - S(t)`` is a quadratic
that is solved in closed form (numerically stable formula) in double precision. All
functions here are exact up to floating-point rounding.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from ..errors import UsageError

__all__ = [
    "JIT_OPTIONS",
    "as_height",
    "surface_at",
    "clip_box",
    "walk_segments",
    "cell_quadratic",
    "first_hit_in",
    "crossings_between",
    "max_depth_below",
    "surface_height",
    "intersect_rays",
]

JIT_OPTIONS = {"cache": True, "error_model": "numpy", "nogil": True}


# ---------------------------------------------------------------------------------------------
# scalar kernels
# ---------------------------------------------------------------------------------------------
@njit(**JIT_OPTIONS)
def surface_at(height, x, y):
    """Bilinear, border-clamped surface height at texel coordinates (x, y)."""
    hh, ww = height.shape
    xc = min(max(x, 0.5), ww - 0.5) - 0.5
    yc = min(max(y, 0.5), hh - 0.5) - 0.5
    i0 = min(int(math.floor(xc)), ww - 1)
    j0 = min(int(math.floor(yc)), hh - 1)
    i1 = min(i0 + 1, ww - 1)
    j1 = min(j0 + 1, hh - 1)
    fx = xc - i0
    fy = yc - j0
    top = height[j0, i0] * (1.0 - fx) + height[j0, i1] * fx
    bot = height[j1, i0] * (1.0 - fx) + height[j1, i1] * fx
    return top * (1.0 - fy) + bot * fy


@njit(**JIT_OPTIONS)
def clip_box(o, d, t_min, t_max, axes=3):
    """Clip the parameter range [t_min, t_max] of ``o + t d`` to the unit box (to the unit
    square of the first two coordinates when ``axes`` is 2).

    Returns ``(t0, t1)``; the ray misses when ``t0 > t1``.
    """
    t0 = t_min
    t1 = t_max
    for a in range(axes):
        if d[a] == 0.0:
            if o[a] < 0.0 or o[a] > 1.0:
                return 1.0, 0.0
        else:
            ta = (0.0 - o[a]) / d[a]
            tb = (1.0 - o[a]) / d[a]
            if ta > tb:
                ta, tb = tb, ta
            t0 = max(t0, ta)
            t1 = min(t1, tb)
    return t0, t1


@njit(**JIT_OPTIONS)
def _start_cell(pos, step):
    """Index of the cell (between centerlines) that contains ``pos`` when moving by ``step``."""
    if step < 0.0:
        return int(math.ceil(pos - 0.5))
    return int(math.floor(pos + 0.5))


@njit(**JIT_OPTIONS)
def _next_boundary_t(cell, n, o_a, d_a):
    """t of the next cell boundary along one axis (inf when there is none)."""
    if d_a > 0.0:
        if cell >= n:
            return np.inf
        return ((cell + 0.5) / n - o_a) / d_a
    if d_a < 0.0:
        if cell <= 0:
            return np.inf
        return ((cell - 0.5) / n - o_a) / d_a
    return np.inf


@njit(**JIT_OPTIONS)
def walk_segments(hh, ww, o, d, t0, t1):
    """Amanatides-Woo walk of the cells between centerlines crossed on ``[t0, t1]``.

    Returns ``(ts, cxs, cys, n)``: segment ``k`` is ``[ts[k], ts[k+1]]`` in cell
    ``(cxs[k], cys[k])``; cell indices run over ``0..W`` and ``0..H``. Zero-length segments
    are skipped.
    """
    cap = hh + ww + 8
    ts = np.empty(cap + 1)
    cxs = np.empty(cap, np.int64)
    cys = np.empty(cap, np.int64)
    n = 0
    ts[0] = t0
    if not t1 > t0:
        return ts, cxs, cys, 0
    dx = d[0] * ww
    dy = d[1] * hh
    cx = _start_cell((o[0] + t0 * d[0]) * ww, dx)
    cy = _start_cell((o[1] + t0 * d[1]) * hh, dy)
    cx = min(max(cx, 0), ww)
    cy = min(max(cy, 0), hh)
    sx = 1 if dx > 0.0 else -1
    sy = 1 if dy > 0.0 else -1
    t = t0
    for _ in range(2 * cap + 8):
        tnx = _next_boundary_t(cx, ww, o[0], d[0])
        tny = _next_boundary_t(cy, hh, o[1], d[1])
        tn = min(min(tnx, tny), t1)
        if tn > t and n < cap:
            cxs[n] = cx
            cys[n] = cy
            n += 1
            ts[n] = tn
            t = tn
        if tn >= t1:
            break
        if tnx <= tn:
            cx = min(max(cx + sx, 0), ww)
        if tny <= tn:
            cy = min(max(cy + sy, 0), hh)
    return ts, cxs, cys, n


@njit(**JIT_OPTIONS)
def cell_quadratic(height, o, d, cx, cy, ta):
    """Coefficients (A, B, C) of ``F(ta + s) = h - S = A s^2 + B s + C`` inside a cell."""
    hh, ww = height.shape
    i0 = min(max(cx - 1, 0), ww - 1)
    i1 = min(max(cx, 0), ww - 1)
    j0 = min(max(cy - 1, 0), hh - 1)
    j1 = min(max(cy, 0), hh - 1)
    a00 = height[j0, i0]
    a10 = height[j0, i1]
    a01 = height[j1, i0]
    a11 = height[j1, i1]
    e = a10 - a00
    f = a01 - a00
    g = a11 - a10 - a01 + a00
    px = (o[0] + ta * d[0]) * ww - (cx - 0.5)
    py = (o[1] + ta * d[1]) * hh - (cy - 0.5)
    qx = d[0] * ww
    qy = d[1] * hh
    s0 = a00 + e * px + f * py + g * px * py
    s1 = e * qx + f * qy + g * (px * qy + py * qx)
    s2 = g * qx * qy
    h0 = o[2] + ta * d[2]
    return -s2, d[2] - s1, h0 - s0


@njit(**JIT_OPTIONS)
def _quad(a, b, c, s):
    return (a * s + b) * s + c


@njit(**JIT_OPTIONS)
def _first_root(a, b, c, length):
    """Smallest ``s`` in ``[0, length]`` with ``a s^2 + b s + c <= 0``, given ``c > 0``.

    Closed form with the numerically stable quadratic formula; ``inf`` when there is none.
    """
    if a == 0.0:
        if b < 0.0:
            s = -c / b
            if s <= length:
                return max(s, 0.0)
        return np.inf
    disc = b * b - 4.0 * a * c
    if disc < 0.0:
        return np.inf
    q = -0.5 * (b + math.copysign(math.sqrt(disc), b))
    best = np.inf
    r1 = q / a
    if 0.0 <= r1 <= length:
        best = r1
    if q != 0.0:
        r2 = c / q
        if 0.0 <= r2 < best and r2 <= length:
            best = r2
    if best == np.inf and _quad(a, b, c, length) <= 0.0:
        # Rounding can push a root just past the end of the cell although F(length) <= 0.
        return _bisect_root(a, b, c, 0.0, length)
    return best


@njit(**JIT_OPTIONS)
def _bisect_root(a, b, c, lo, hi):
    """Root of a quadratic on ``[lo, hi]`` with ``F(lo) > 0 >= F(hi)`` (or the reverse)."""
    flo = _quad(a, b, c, lo) > 0.0
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        if (_quad(a, b, c, mid) > 0.0) == flo:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


@njit(**JIT_OPTIONS)
def first_hit_in(height, o, d, t_lo, t_hi):
    """First ``t`` in ``[t_lo, t_hi]`` (already clipped to the box) with ``h <= S``."""
    hh, ww = height.shape
    ts, cxs, cys, n = walk_segments(hh, ww, o, d, t_lo, t_hi)
    if n == 0:
        # Degenerate range (a single point): test it directly.
        if t_lo <= t_hi:
            x = (o[0] + t_lo * d[0]) * ww
            y = (o[1] + t_lo * d[1]) * hh
            if o[2] + t_lo * d[2] <= surface_at(height, x, y):
                return t_lo
        return np.inf
    for k in range(n):
        ta = ts[k]
        a, b, c = cell_quadratic(height, o, d, cxs[k], cys[k], ta)
        if c <= 0.0:
            return ta
        s = _first_root(a, b, c, ts[k + 1] - ta)
        if s != np.inf:
            return ta + s
    return np.inf


@njit(**JIT_OPTIONS)
def _intersect(height, o, d):
    t0, t1 = clip_box(o, d, 0.0, np.inf)
    if t0 > t1:
        return np.inf
    return first_hit_in(height, o, d, t0, t1)


@njit(**JIT_OPTIONS)
def crossings_between(height, o, d, t_lo, t_hi):
    """Every sign change of ``F = h - S`` on ``[t_lo, t_hi]`` clipped to the box.

    "Above" is ``F > 0``; a crossing is a change between above and on-or-below. Returns an
    array of the crossing parameters in increasing order.
    """
    hh, ww = height.shape
    out = np.empty(0)
    t0, t1 = clip_box(o, d, t_lo, t_hi)
    if t0 > t1:
        return out
    ts, cxs, cys, n = walk_segments(hh, ww, o, d, t0, t1)
    buf = np.empty(2 * n + 4)
    m = 0
    prev_above = False
    have_prev = False
    for k in range(n):
        ta = ts[k]
        length = ts[k + 1] - ta
        a, b, c = cell_quadratic(height, o, d, cxs[k], cys[k], ta)
        # Sample points: start, interior extremum, end; F is monotone between them.
        pts = np.empty(3)
        pts[0] = 0.0
        npts = 1
        if a != 0.0:
            sc = -b / (2.0 * a)
            if 0.0 < sc < length:
                pts[npts] = sc
                npts += 1
        pts[npts] = length
        npts += 1
        above0 = c > 0.0
        if have_prev and above0 != prev_above:
            buf[m] = ta
            m += 1
        prev = above0
        for p in range(1, npts):
            above = _quad(a, b, c, pts[p]) > 0.0
            if above != prev:
                buf[m] = ta + _bisect_root(a, b, c, pts[p - 1], pts[p])
                m += 1
            prev = above
        prev_above = prev
        have_prev = True
    return buf[:m].copy()


@njit(**JIT_OPTIONS)
def max_depth_below(height, o, d, t_lo, t_hi):
    """``max (S - h)`` over ``[t_lo, t_hi]`` clipped to the box (``-inf`` when empty)."""
    hh, ww = height.shape
    t0, t1 = clip_box(o, d, t_lo, t_hi)
    if t0 > t1:
        return -np.inf
    ts, cxs, cys, n = walk_segments(hh, ww, o, d, t0, t1)
    best = -np.inf
    if n == 0:
        x = (o[0] + t0 * d[0]) * ww
        y = (o[1] + t0 * d[1]) * hh
        return surface_at(height, x, y) - (o[2] + t0 * d[2])
    for k in range(n):
        ta = ts[k]
        length = ts[k + 1] - ta
        a, b, c = cell_quadratic(height, o, d, cxs[k], cys[k], ta)
        best = max(best, -c, -_quad(a, b, c, length))
        if a != 0.0:
            sc = -b / (2.0 * a)
            if 0.0 < sc < length:
                best = max(best, -_quad(a, b, c, sc))
    return best


@njit(parallel=True, **JIT_OPTIONS)
def _intersect_many(height, origins, directions, out):
    for r in prange(origins.shape[0]):
        out[r] = _intersect(height, origins[r], directions[r])


@njit(**JIT_OPTIONS)
def _surface_many(height, xs, ys, out):
    for k in range(xs.shape[0]):
        out[k] = surface_at(height, xs[k], ys[k])


# ---------------------------------------------------------------------------------------------
# public API
# ---------------------------------------------------------------------------------------------
def as_height(height) -> np.ndarray:
    arr = np.asarray(height)
    if arr.ndim != 2 or arr.shape[0] < 1 or arr.shape[1] < 1:
        raise UsageError(f"height must be a non-empty 2D array, got shape {arr.shape}")
    if not np.issubdtype(arr.dtype, np.number):
        raise UsageError(f"height must be numeric, got dtype {arr.dtype}")
    arr = np.ascontiguousarray(arr, dtype=np.float64)
    if not np.isfinite(arr).all():
        raise UsageError("height contains NaN or Inf values; clean the heightfield first")
    return arr


def surface_height(height, x, y):
    """Bilinear, border-clamped surface height at texel coordinates.

    Parameters
    ----------
    height : (H, W) array_like
        Heightfield; ``height[j, i]`` is the value at the texel centre ``(i + 0.5, j + 0.5)``.
    x, y : float or array_like
        Texel coordinates (``x = u * W``, ``y = v * H``); broadcast against each other.

    Returns
    -------
    float or numpy.ndarray
        ``S(x, y)``; a float for scalar input, otherwise an array of the broadcast shape.
    """
    h = as_height(height)
    xs, ys = np.broadcast_arrays(np.asarray(x, dtype=np.float64), np.asarray(y, dtype=np.float64))
    out = np.empty(xs.size)
    _surface_many(h, np.ascontiguousarray(xs).reshape(-1), np.ascontiguousarray(ys).reshape(-1),
                  out)
    if xs.ndim == 0:
        return float(out[0])
    return out.reshape(xs.shape)


def intersect_rays(height, origins, directions) -> np.ndarray:
    """Parameter ``t >= 0`` of the first hit of each ray ``origins[r] + t * directions[r]``
    with the surface (numba, parallel over rays).

    Parameters
    ----------
    height : (H, W) array_like
        Heightfield in [0, 1].
    origins, directions : (N, 3) array_like
        The rays in box coordinates (u, v, h); directions need not be normalised.

    Returns
    -------
    numpy.ndarray
        (N,) float64: per ray the smallest ``t >= 0`` inside the unit box where ``h <= S``
        (the entry ``t`` when the ray enters the box on or below the surface), ``inf`` for
        misses.
    """
    h = as_height(height)
    o = np.ascontiguousarray(np.asarray(origins, dtype=np.float64).reshape(-1, 3))
    d = np.ascontiguousarray(np.asarray(directions, dtype=np.float64).reshape(-1, 3))
    if o.shape != d.shape:
        raise UsageError(f"origins {o.shape} and directions {d.shape} must have the same shape")
    if not (np.isfinite(o).all() and np.isfinite(d).all()):
        raise UsageError("origins and directions must be finite")
    out = np.empty(o.shape[0])
    _intersect_many(h, o, d, out)
    return out
