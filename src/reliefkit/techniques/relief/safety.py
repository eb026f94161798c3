"""Safety radii for the robust binary search of Baboud & Decoret (2006), sections 3.4-3.5.

Definition (the contract the renderer's robust walk relies on)
--------------------------------------------------------------
Texel coordinates, heights and the bilinear, border-clamped surface ``S`` are those of
:mod:`reliefkit.reference.heightfield`. Let a ray have projected direction
``(dx, dy)`` in texel units. If ``|dx| >= |dy|`` it is *x-major*: its walk positions ``P``
are the points where it crosses the vertical centerlines ``x = i + 0.5``; the texel of such
a ``P`` is ``(i, j)`` with ``j = clamp(floor(y_P), 0, H - 1)``, its radius is ``r =
safety[j, i]`` and the walk jumps to the centerline ``x = i + 0.5 + sign(dx) * r``. A
*y-major* ray (``|dy| > |dx|``) is the same with the roles of x and y (rows and columns)
swapped.

``safety[j, i]`` is the largest ``n <= max_radius`` such that, for every ray (every
projected direction, every vertical slope up or down, every crossing point ``P`` of that
texel's centerline segment, any height above the surface at ``P``) that is *unblocked*,
i.e. strictly above the surface at every point from its entry into the box up to ``P``
(through a side, or through the bottom where the floor is open: where the height is 0 the
box's bottom face is no surface, and rays from below enter there, as the renderer and the
reference let them),
the ray has no *violating pair of crossings* strictly between ``P`` and the jump target
(the segment being cut where the ray leaves the box). A violating pair is a crossing down
below the surface followed by a crossing back above it, such that the largest depth
``S - h`` reached between the two exceeds ``tolerance`` (normalised height units). With
``tolerance = 0`` this is "at most one crossing" (Fig. 6); with ``tolerance > 0`` shallow
dips are ignored, which gives larger radii and bounded silhouette errors (Fig. 12).
Depths of at most :data:`NUMERIC_FLOOR` are float noise and never count. The radius is 0
when even ``n = 1`` fails (locally non-concave peaks, Fig. 7); the renderer then clamps it to
1 (or steps exactly).

How it is computed (what is exact, what is sampled)
---------------------------------------------------
Fix a projected line ``y = y_c + m x`` (x-major, ``0 <= m <= 1``; the other seven octants
come from flipping / transposing the heightfield), its profile ``f(x) = S(x, y_c + m x)``
(piecewise quadratic, breaking at both families of centerlines) and a walk position ``P``.
A ray is a line ``z(x)`` in that slice. For a point ``a > x_P`` let ``T_a`` be the steepest
ray through ``(a, f(a) - tolerance)`` that clears the upper convex hull ``A`` of the profile
between the box side and ``P`` (it is tangent to ``A``). A violation resurfacing at ``b``
exists iff ``T_a(b) > f(b)`` for some ``x_P < a < b`` (necessary and sufficient: a violating
ray can be rotated about its deepest point onto ``T_a``, and ``T_a`` lowered by a hair is a
violating ray). The upper envelope of the ``T_a`` is the support ray ``L_K`` of ``A`` whose
slope ``K`` is the running maximum of the tangent slopes, so one forward scan finds the
first violation ``b*`` (the first point where ``L_K`` rises more than
:data:`NUMERIC_FLOOR` above the profile) and the radius of that sample is
``ceil(b* - x_P - margin) - 1``. Along one line ``b*`` never decreases as ``P`` advances
(more surface behind ``P`` blocks more rays), so most walk positions are settled by the
scan of an earlier one.

* exact (up to rounding, double precision): the forward profile (closed-form quadratics
  per piece); the running maximum ``K`` (the tangent vertex of the moving point is followed
  exactly: it changes where the point crosses the extension of a hull edge, and the slope
  peaks where ``f'(a) = K``; both are roots of quadratics); the first point where ``L_K``
  rises above the profile;
* conservative: ``A`` is the hull of profile samples (piece ends and the maxima of concave
  pieces), which lies below the true hull, so more rays count as unblocked; it restarts at
  every sample where the profile is 0 (open floor: a ray entering the box there is not
  blocked by anything behind it; the profile is 0 only at piece ends, since a bilinear cell
  with corners >= 0 is 0 inside only when all its corners are);
* sampled: the projected directions (``directions`` per half-plane and major axis, uniform
  in angle, both axes and both diagonals included) and the walk positions within a texel
  (``offsets`` parallel lines per texel and direction, evenly spaced, the phase varying from
  column to column, plus for every column the line that enters the box exactly at its
  walk position, where nothing behind ``P`` blocks). To cover what lies between samples,
  a violation counts ``margin`` texels earlier than found (not for violations that start
  right after a vertical centerline, whose position does not depend on the samples), and
  the scan continues past the box exit (clamped surface) by ``margin`` plus up to two texels
  where the exit point moves between neighbouring lines. Violations that exist only between
  samples can still be missed; :func:`check_safety` looks for them with continuous random
  parameters and brute-force extremal rays. In our tests (tens of fields, millions of
  checker rays) the misses left were dips deeper than the tolerance by less than 1% of it
  (the baker uses a tolerance 1% smaller, :data:`TOLERANCE_SLACK`, which removes most of
  them) or by a few 1e-7 (see :data:`CHECK_FLOOR`), mostly at walk positions on a texel
  edge, the end of the sampled range.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numba
import numpy as np
from numba import njit, prange

from ...errors import UsageError
from ...reference.heightfield import JIT_OPTIONS, as_height

__all__ = [
    "NUMERIC_FLOOR",
    "TOLERANCE_SLACK",
    "WORK_COUNTERS",
    "safety_radii",
]

NUMERIC_FLOOR = 1e-9
"""Depths (height units) at or below this are float noise: the baker never counts them."""

TOLERANCE_SLACK = 0.01
"""The baker uses ``tolerance * (1 - TOLERANCE_SLACK)`` so that dips whose depth crosses the
tolerance between two sampled directions or walk positions are still counted."""

_NEG_INF = -np.inf

# work counters of the sweep (device-independent cost, reported by `safety_radii`'s ``work``)
_VISITS, _PIECES, _SCANS, _SCANNED = range(4)
WORK_COUNTERS = ("visits", "pieces", "scans", "scanned_pieces")
_COUNTS_STRIDE = 16  # int64s per thread: 128 bytes, so threads never share a cache line


# ---------------------------------------------------------------------------------------------
# small numeric helpers
# ---------------------------------------------------------------------------------------------
@njit(**JIT_OPTIONS)
def _qv(a, b, c, u):
    return (a * u + b) * u + c


@njit(**JIT_OPTIONS)
def _root_between(a, b, c, lo, hi):
    """Root of ``a u^2 + b u + c`` on ``[lo, hi]`` where its sign differs at the two ends."""
    flo = _qv(a, b, c, lo) > 0.0
    # closed form first (stable formula), then verify; bisection as the fallback
    slack = 1e-12 * (1.0 + abs(lo) + abs(hi))
    if a == 0.0:
        if b != 0.0:
            r = -c / b
            if lo - slack <= r <= hi + slack:
                return min(max(r, lo), hi)
    else:
        disc = b * b - 4.0 * a * c
        if disc >= 0.0:
            q = -0.5 * (b + math.copysign(math.sqrt(disc), b))
            cands = (q / a, c / q if q != 0.0 else np.inf)
            for r in cands:
                if lo - slack <= r <= hi + slack:
                    return min(max(r, lo), hi)
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        if (_qv(a, b, c, mid) > 0.0) == flo:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


@njit(**JIT_OPTIONS)
def _first_positive(a, b, c, lo, hi):
    """Smallest ``u`` in ``[lo, hi]`` where ``a u^2 + b u + c > 0`` (``inf`` if none)."""
    if _qv(a, b, c, lo) > 0.0:
        return lo
    if a != 0.0:
        uc = -b / (2.0 * a)
        if lo < uc < hi:
            if _qv(a, b, c, uc) > 0.0:
                return _root_between(a, b, c, lo, uc)
            lo = uc
    if _qv(a, b, c, hi) > 0.0:
        return _root_between(a, b, c, lo, hi)
    return np.inf


# ---------------------------------------------------------------------------------------------
# the profile of one projected line
# ---------------------------------------------------------------------------------------------
@njit(**JIT_OPTIONS)
def _line_range(hh, ww, m, yc):
    """x-range of the line ``y = yc + m x`` inside the rectangle ``[0, W] x [0, H]``."""
    if m == 0.0:
        if yc < 0.0 or yc > hh:
            return 1.0, 0.0
        return 0.0, float(ww)
    return max(0.0, -yc / m), min(float(ww), (hh - yc) / m)


@njit(**JIT_OPTIONS)
def _line_pieces(height, m, yc, xlo, xstop, work):
    """Split the profile ``f(x) = S(x, yc + m x)`` on ``[xlo, xstop]`` into quadratic pieces.

    Piece ``k`` is ``[work[0, k], work[0, k+1]]`` with ``f = c0 + c1 u + c2 u^2`` (``c0, c1,
    c2 = work[1:4, k]``) and ``u = x - work[0, k]``.
    Breakpoints are the vertical centerlines ``x = i + 0.5`` and the points where the line
    crosses a horizontal centerline. Returns the number of pieces.
    """
    hh, ww = height.shape
    n = 0
    work[0, 0] = xlo
    i = int(math.floor(xlo - 0.5)) + 1  # next vertical centerline strictly after xlo
    xi = i + 0.5
    if m > 0.0:
        j = int(math.floor(yc + m * xlo - 0.5)) + 1
        xj = (j + 0.5 - yc) / m
    else:
        j = int(math.floor(yc + 0.5))  # the row band the line stays in
        xj = np.inf
    last = xlo
    while True:
        nxt = min(min(xi, xj), xstop)
        if nxt > last + 1e-12:
            # the piece lies between centrelines i - 1/2 .. i + 1/2 and j - 1/2 .. j + 1/2:
            # its bilinear cell has corners (i - 1, i) x (j - 1, j), clamped at the border
            cx = min(max(i, 0), ww)
            cy = min(max(j, 0), hh)
            i0 = min(max(cx - 1, 0), ww - 1)
            i1 = min(cx, ww - 1)
            j0 = min(max(cy - 1, 0), hh - 1)
            j1 = min(cy, hh - 1)
            a00 = np.float64(height[j0, i0])
            a10 = np.float64(height[j0, i1])
            a01 = np.float64(height[j1, i0])
            e = a10 - a00
            f = a01 - a00
            g = np.float64(height[j1, i1]) - a10 - a01 + a00
            px = last - (cx - 0.5)
            py = yc + m * last - (cy - 0.5)
            work[1, n] = a00 + e * px + f * py + g * px * py
            work[2, n] = e + f * m + g * (px * m + py)
            work[3, n] = g * m
            n += 1
            work[0, n] = nxt
            last = nxt
        if nxt >= xstop:
            break
        if xi <= nxt:
            i += 1
            xi = i + 0.5
        if xj <= nxt:
            j += 1
            xj = (j + 0.5 - yc) / m
    return n


# ---------------------------------------------------------------------------------------------
# upper convex hull of the profile behind P
# ---------------------------------------------------------------------------------------------
@njit(inline="always", **JIT_OPTIONS)
def hull_push(work, nh, x, z):
    """Append a point (increasing x) to the upper hull kept as a stack in ``work[4]`` (x) and
    ``work[5]`` (z); returns the new size."""
    if nh > 0 and x <= work[4, nh - 1] + 1e-12:
        if z <= work[5, nh - 1]:
            return nh
        nh -= 1
    while nh >= 2:
        dxa = work[4, nh - 1] - work[4, nh - 2]
        dza = work[5, nh - 1] - work[5, nh - 2]
        if dza * (x - work[4, nh - 2]) <= (z - work[5, nh - 2]) * dxa:
            nh -= 1
        else:
            break
    work[4, nh] = x
    work[5, nh] = z
    return nh + 1


@njit(inline="always", **JIT_OPTIONS)
def tangent_vertex(work, nh, a, z):
    """Hull vertex minimising the slope from it to ``(a, z)`` (``a`` right of the hull)."""
    lo = 0
    hi = nh - 1
    while lo < hi:
        mid = (lo + hi) // 2
        # slope(mid + 1) < slope(mid)  <=>  move right
        left = (z - work[5, mid + 1]) * (a - work[4, mid])
        if left < (z - work[5, mid]) * (a - work[4, mid + 1]):
            lo = mid + 1
        else:
            hi = mid
    return lo


# ---------------------------------------------------------------------------------------------
# forward scan from one walk position
# ---------------------------------------------------------------------------------------------
_ZERO = 1e-13  # |value| below which a quadratic is "on" its threshold (decided by the slope)
_ZERO_SLOPE = 1e-11  # |slope| below which the curvature decides


@njit(**JIT_OPTIONS)
def _first_rise(a, b, c, lo, hi):
    """First ``u`` in ``[lo, hi]`` where ``a u^2 + b u + c`` becomes strictly positive.

    A start value within ``_ZERO`` of 0 counts as 0: it rises at ``lo`` only if its slope
    (or, for a zero slope, its curvature) is positive there. ``inf`` when it never rises.
    """
    if lo > hi:
        return np.inf
    g = _qv(a, b, c, lo)
    if abs(g) > _ZERO:
        return _first_positive(a, b, c, lo, hi)
    slope = 2.0 * a * lo + b
    if slope > _ZERO_SLOPE or (slope > -_ZERO_SLOPE and a > 0.0):
        return lo
    c -= g
    if a > 0.0:
        uc = -b / (2.0 * a)
        if lo < uc < hi:
            return _first_positive(a, b, c, uc, hi)
    return np.inf


@njit(**JIT_OPTIONS)
def _phi(u, x0, c0, c1, c2, xt, zt, eps):
    """Slope of the ray from hull vertex ``(xt, zt)`` through ``(x0 + u, f - eps)``."""
    w = x0 + u - xt
    if w <= 0.0:
        return _NEG_INF if eps > 0.0 else c1
    return (_qv(c2, c1, c0, u) - eps - zt) / w


@njit(inline="always", **JIT_OPTIONS)
def _vertex_at(u, x0, c0, c1, c2, work, nh, eps):
    """Tangent vertex of the ray through ``(x0 + u, f - eps)``, with the limit at ``P``."""
    a = x0 + u
    if a <= work[4, nh - 1]:
        if eps > 0.0 or nh == 1:
            return nh - 1
        elast = (work[5, nh - 1] - work[5, nh - 2]) / (work[4, nh - 1] - work[4, nh - 2])
        return nh - 1 if c1 <= elast else nh - 2
    return tangent_vertex(work, nh, a, _qv(c2, c1, c0, u) - eps)


@njit(inline="always", **JIT_OPTIONS)
def _next_switch(u, length, t, came_from, x0, c0, c1, c2, work, nh, eps):
    """Where the tangent vertex ``t`` stops being optimal in ``[u, length]``, and the next one.

    ``t`` is optimal while the moving point ``(x, f - eps)`` is not above the extension of
    the hull edge on the left of ``t`` and not below the one on its right.
    """
    us = np.inf
    tn = t
    if t > 0:
        e = (work[5, t] - work[5, t - 1]) / (work[4, t] - work[4, t - 1])
        base = c0 - eps - work[5, t] - e * (x0 - work[4, t])
        lo = u + 1e-9 if came_from == t - 1 else u
        ul = _first_rise(c2, c1 - e, base, lo, length)
        if ul < us:
            us = ul
            tn = t - 1
    if t < nh - 1:
        e = (work[5, t + 1] - work[5, t]) / (work[4, t + 1] - work[4, t])
        base = c0 - eps - work[5, t] - e * (x0 - work[4, t])
        lo = u + 1e-9 if came_from == t + 1 else u
        ur = _first_rise(-c2, e - c1, -base, lo, length)
        if ur < us:
            us = ur
            tn = t + 1
    return us, tn


@njit(inline="always", **JIT_OPTIONS)
def _scan(work, npieces, kp, xlimit, nh, eps, floor):
    """First violation ``b*`` (absolute x) after the walk position at piece ``kp``, and the
    number of pieces visited.

    ``b*`` is ``inf`` when there is none before ``xlimit``. ``K`` is the running maximum of
    the slope ``k(a)`` of the steepest ray through ``(a, f(a) - eps)`` that clears the hull.
    Two states alternate:

    * tracking (``k(a)`` is the running maximum and increasing): no violation is possible;
      on a convex or straight piece where ``k`` rises at the start it rises to the end (each
      slope ``g_v(a)`` from a hull vertex ``v`` is then decreasing-then-increasing, and one
      still decreasing lies above ``f'(a)``, above the rising minimiser), so such a piece is
      skipped whole and the tangent vertex found again by bisection where it is next needed;
      the tangent vertex ``t`` of the moving point is followed exactly (it switches where the
      point crosses a hull edge extension) and ``k(a) = phi_t(a)`` stops increasing where
      ``N_t(a) = f'(a)(a - x_t) - (f(a) - eps - z_t)`` reaches 0 (both are quadratics);
    * frozen: the envelope of all earlier tangent rays is the support ray ``L_K`` through the
      vertex ``tk``; a violation is the first point where ``L_K > f + floor``, and tracking
      resumes where ``f - eps`` rises above ``L_K`` (then ``k(a) > K`` again).
    """
    t = _vertex_at(0.0, work[0, kp], work[1, kp], work[2, kp], work[3, kp], work, nh, eps)
    tracking = True
    k = _NEG_INF
    tk = t
    came_from = -1
    visited = 0
    for kk in range(kp, npieces):
        x0 = work[0, kk]
        if x0 >= xlimit:
            break
        visited += 1
        length = min(work[0, kk + 1], xlimit) - x0
        c0 = work[1, kk]
        c1 = work[2, kk]
        c2 = work[3, kk]
        u = 0.0
        froze_at = -1.0
        resumed_at = -1.0
        done = False
        for _ in range(4 * nh + 16):
            if tracking:
                if t < 0:
                    t = _vertex_at(u, x0, c0, c1, c2, work, nh, eps)
                xt = work[4, t]
                zt = work[5, t]
                d = x0 - xt
                nc = c1 * d - c0 + eps + zt
                nu = _qv(c2, 2.0 * c2 * d, nc, u)
                surely_rising = nu > _ZERO or (nu > -_ZERO and c2 > 0.0)
                if surely_rising and c2 >= 0.0:
                    # convex or straight piece: k rises on to its end (see _scan); the
                    # tangent vertex is found again where it is next needed
                    t = -1
                    came_from = -1
                    done = True
                    break
                rising = surely_rising or resumed_at == u
                if not rising:
                    k = _phi(u, x0, c0, c1, c2, xt, zt, eps)
                    tk = t
                    tracking = False
                    froze_at = u
                    continue
                us, tn = _next_switch(u, length, t, came_from, x0, c0, c1, c2, work, nh,
                                      eps)
                ue = np.inf
                if c2 < 0.0:
                    # N decreases: k(a) peaks where N = 0
                    ue = _first_rise(-c2, -2.0 * c2 * d, -nc, u, length)
                if ue <= us and ue <= length:
                    k = _phi(ue, x0, c0, c1, c2, xt, zt, eps)
                    tk = t
                    tracking = False
                    u = ue
                    froze_at = ue
                    came_from = -1
                    continue
                if us <= length:
                    came_from = t
                    t = tn
                    u = us
                    continue
                done = True
                break
            else:
                # D(u) = L_K - f on this piece: a violation where D > floor, tracking
                # resumes where D < -eps; most pieces have neither (fast path)
                da = -c2
                db = k - c1
                dc = work[5, tk] + k * (x0 - work[4, tk]) - c0
                d0 = _qv(da, db, dc, u)
                d1 = _qv(da, db, dc, length)
                dmax = max(d0, d1)
                dmin = min(d0, d1)
                if da != 0.0:
                    uc = -db / (2.0 * da)
                    if u < uc < length:
                        dv = _qv(da, db, dc, uc)
                        dmax = max(dmax, dv)
                        dmin = min(dmin, dv)
                if dmax <= floor and dmin >= -eps - _ZERO:
                    done = True
                    break
                # resume strictly after the point where it froze (no ping-pong on ties)
                ur = _first_rise(c2, c1 - k, -dc - eps, u + 1e-9 if froze_at == u else u,
                                 length)
                uv = _first_positive(da, db, dc - floor, u, min(ur, length))
                if uv != np.inf:
                    return x0 + uv, visited
                if ur <= length:
                    tracking = True
                    t = tk
                    came_from = -1
                    u = ur
                    resumed_at = ur
                    continue
                done = True
                break
        if not done:
            # no progress (degenerate ties): report a violation, conservatively
            return x0 + u, visited
    return np.inf, visited


# ---------------------------------------------------------------------------------------------
# one direction (all parallel lines of one slope, in one of the eight octant frames)
# ---------------------------------------------------------------------------------------------
@njit(inline="always", **JIT_OPTIONS)
def _radius_from(dist, margin):
    """Largest radius ``n`` with ``n < dist - margin`` (the first violation is at ``dist``).

    A violation right after a vertical centerline (at an integer distance: a crease of the
    surface along the walk's own centerlines) does not move with the sampled offset or
    direction, so it gets no margin.
    """
    if dist - math.floor(dist) <= 1e-4:
        return int(math.ceil(dist)) - 1
    return int(math.ceil(dist - margin)) - 1


@njit(inline="always", **JIT_OPTIONS)
def _original_index(jp, ip, hp, wp, transpose, flipx, flipy):
    """(row, col) in the original array of texel (jp, ip) of a frame."""
    j2 = hp - 1 - jp if flipy else jp
    i2 = wp - 1 - ip if flipx else ip
    if transpose:
        return i2, j2
    return j2, i2


@njit(**JIT_OPTIONS)
def _seed_row(bounds, own, jp, transpose, flipx, flipy):
    nthreads, hp, wp = own.shape
    for ip in range(wp):
        r, c = _original_index(jp, ip, hp, wp, transpose, flipx, flipy)
        for t in range(nthreads):
            own[t, jp, ip] = bounds[r, c]


@njit(**JIT_OPTIONS)
def _merge_row(bounds, own, jp, transpose, flipx, flipy):
    nthreads, hp, wp = own.shape
    for ip in range(wp):
        r, c = _original_index(jp, ip, hp, wp, transpose, flipx, flipy)
        v = bounds[r, c]
        for t in range(nthreads):
            v = min(v, own[t, jp, ip])
        bounds[r, c] = v


@njit(parallel=True, **JIT_OPTIONS)
def _seed_bounds(bounds, own, transpose, flipx, flipy):
    """Copy the shared bounds (original layout) into every thread's buffer in the frame's
    layout, so that the walk along a line reads and writes its own buffer contiguously."""
    nthreads, hp, wp = own.shape
    for jp in prange(hp):
        _seed_row(bounds, own, np.int64(jp), transpose, flipx, flipy)


@njit(parallel=True, **JIT_OPTIONS)
def _merge_bounds(bounds, own, transpose, flipx, flipy):
    """The smallest bound of every thread's buffer, back into the shared bounds."""
    nthreads, hp, wp = own.shape
    for jp in prange(hp):
        _merge_row(bounds, own, np.int64(jp), transpose, flipx, flipy)


@njit(inline="always", **JIT_OPTIONS)
def _rows_of(y0, hp):
    """Rows whose texel contains the centerline point at height ``y0`` (two on a border)."""
    j = min(max(int(math.floor(y0)), 0), hp - 1)
    j2 = j
    if y0 == math.floor(y0) and 0 < y0 < hp:
        j2 = j - 1
    return j, j2


@njit(**JIT_OPTIONS)
def _sweep_line(height, m, yc, eps, floor, margin, offsets, bound_of, work, only_first,
                counts):
    """Scan every walk position of one sample line (only the first when ``only_first``),
    lowering the bounds ``bound_of`` (frame layout) where a violation is found; adds its
    work to ``counts`` (indexed by `_VISITS`, `_PIECES`, `_SCANS`, `_SCANNED`)."""
    hp, wp = height.shape
    xlo, xhi = _line_range(hp, wp, m, yc)
    if not xhi > xlo:
        return
    # Scan a little past the box exit (clamped surface): where the line leaves through a
    # side parallel to the offset spacing the exit moves between neighbouring sample lines.
    xend = xhi + margin
    if m > 0.0 and xhi < wp:
        xend += min(2.0, 1.0 / (offsets * m))
    i_first = max(0, int(math.ceil(xlo - 0.5)))
    i_last = min(wp - 1, int(math.floor(xhi - 0.5)))
    if only_first:
        i_last = min(i_last, i_first)
    # how far along the line does any walk position still need work? (scans stop at the
    # first violation; past the last position that needs work they are cut short)
    xstop = xlo
    for i in range(i_first, i_last + 1):
        xp = i + 0.5
        j, j2 = _rows_of(yc + m * xp, hp)
        bound = max(bound_of[j, i], bound_of[j2, i])
        if bound > 0:
            # a line that only serves its first position need not settle later ones
            reach = bound + margin + 1.0 if only_first else 4 * bound + margin + 8.0
            xstop = max(xstop, min(xend, xp + reach))
    if not xstop > xlo:
        return
    npieces = _line_pieces(height, m, yc, xlo, xstop, work)
    visits = scans = scanned = 0
    nh = 0
    k = 0
    # Along one line the first violation b*(P) never moves backwards as P advances (a later P
    # has more surface behind it, so fewer unblocked rays): ``known`` is a lower bound of
    # b* for every later P, and a P whose scan limit is below it cannot lower its radius.
    known = -np.inf
    for i in range(i_first, i_last + 1):
        xp = i + 0.5
        if xp > xstop:
            break
        while k < npieces and work[0, k] <= xp + 1e-9:
            if k > 0 and work[3, k - 1] < 0.0:
                # maximum of a concave piece: a better (still conservative) hull sample
                uc = -work[2, k - 1] / (2.0 * work[3, k - 1])
                if 0.0 < uc < work[0, k] - work[0, k - 1]:
                    nh = hull_push(work, nh, work[0, k - 1] + uc,
                                    _qv(work[3, k - 1], work[2, k - 1], work[1, k - 1], uc))
            if work[1, k] <= 0.0:
                nh = 0  # open floor: a ray may enter the box here, nothing behind blocks it
            nh = hull_push(work, nh, work[0, k], work[1, k])
            k += 1
        if k == 0 or work[0, k - 1] < xp - 1e-9:
            continue  # P is the end of the line: nothing after it
        visits += 1
        j, j2 = _rows_of(yc + m * xp, hp)
        bound = max(bound_of[j, i], bound_of[j2, i])
        if bound == 0:
            continue
        limit = min(xp + bound + margin, xstop)
        if known >= limit:
            continue
        # scan on to the first violation (or xstop), not just to ``limit``: the result settles
        # the following walk positions too
        b, visited = _scan(work, npieces, k - 1, xstop, nh, eps, floor)
        scans += 1
        scanned += visited
        known = b if b != np.inf else xstop
        if b <= limit:
            n = max(_radius_from(b - xp, margin), 0)
            bound_of[j, i] = min(bound_of[j, i], n)
            bound_of[j2, i] = min(bound_of[j2, i], n)
    counts[_VISITS] += visits
    counts[_PIECES] += npieces
    counts[_SCANS] += scans
    counts[_SCANNED] += scanned


@njit(parallel=True, **JIT_OPTIONS)
def _sweep_direction(height, m, offsets, eps, floor, margin, own, counts):
    """All sample lines of slope ``m`` in one octant frame, in parallel.

    The lines are ``y = k / offsets + m x`` for every integer ``k`` that reaches the
    rectangle, plus (``m > 0``) one line per column entering the box exactly at that
    column's walk position (``P`` on the box side, where nothing behind ``P`` blocks).
    ``own[t]`` is thread ``t``'s copy of the bounds in the frame's layout and ``counts[t]``
    its work counters.
    """
    hp, wp = height.shape
    k_lo = int(math.floor(-m * wp * offsets))
    k_hi = int(math.ceil(hp * offsets))
    nlines = k_hi - k_lo + 1
    nextra = wp if m > 0.0 else 0
    nthreads = own.shape[0]
    cap = hp + wp + 16
    works = np.empty((nthreads, 6, 3 * cap))
    for li in prange(nlines + nextra):
        tid = numba.get_thread_id()
        yc = (k_lo + li) / offsets if li < nlines else -m * (li - nlines + 0.5)
        _sweep_line(height, m, yc, eps, floor, margin, offsets, own[tid], works[tid],
                    li >= nlines, counts[tid])


# ---------------------------------------------------------------------------------------------
# public API: baking
# ---------------------------------------------------------------------------------------------
_FRAMES = tuple((t, fx, fy) for t in (False, True) for fx in (False, True) for fy in (False, True))


def _frame(height: np.ndarray, transpose: bool, flipx: bool, flipy: bool) -> np.ndarray:
    a = height.T if transpose else height
    if flipx:
        a = a[:, ::-1]
    if flipy:
        a = a[::-1, :]
    return np.ascontiguousarray(a)


def _slopes(directions: int) -> np.ndarray:
    """Slopes ``m = tan(theta)`` for ``theta`` uniform in [0, 45 deg], both ends included."""
    count = max(2, directions // 2 + 1)
    m = np.tan(np.linspace(0.0, np.pi / 4.0, count))
    m[0] = 0.0
    m[-1] = 1.0
    return m


def _coarse_to_fine(count: int) -> list[int]:
    """Indices ``0..count-1`` ordered so that every prefix spreads over the whole range."""
    order = [0, count - 1] if count > 1 else [0]
    seen = set(order)
    step = count - 1
    while step > 1:
        step //= 2
        for i in range(step, count, step):
            if i not in seen:
                seen.add(i)
                order.append(i)
    order += [i for i in range(count) if i not in seen]
    return order


def checked_height(height) -> np.ndarray:
    h = as_height(height)
    if h.min() < 0.0 or h.max() > 1.0:
        raise UsageError(f"height must be within [0, 1] (box units), got values in "
                         f"[{h.min():.4g}, {h.max():.4g}]; normalise the heightfield first")
    return h


def octant(x_major, major_sign, minor_sign) -> np.ndarray:
    """The octant (index into `_FRAMES`, 0..7) of projected directions, as the renderer
    picks it: x-major when ``|dx| >= |dy|``; the signs of the major and the minor component
    (a zero minor component counts as positive). The radii of octant k hold for every
    direction of that octant, its boundary directions included. Element-wise on arrays."""
    return (4 * ~np.asarray(x_major, dtype=bool) + 2 * (np.asarray(major_sign) < 0)
            + (np.asarray(minor_sign) < 0))


def safety_radii(height, *, tolerance: float = 0.0, max_radius: int = 255,
                 directions: int = 64, offsets: int = 4, margin: float = 0.25,
                 octants: bool = False,
                 progress: Callable[[int, int], None] | None = None,
                 work: dict | None = None) -> np.ndarray:
    """Conservative safety radius of every texel (see the module docstring for the definition).

    Parameters
    ----------
    height : (H, W) array_like
        Heightfield in [0, 1] (box units; the surface is the bilinear interpolation).
    tolerance : float
        Largest depth (normalised height units) of a dip between two crossings that is
        ignored; 0 gives the exact "at most one crossing" property.
    max_radius : int
        Cap of the radius; the result is uint8 when it is <= 255, otherwise uint16
        (at most 65535).
    directions : int
        Projected directions sampled per half-plane and major axis (over 90 degrees);
        ``directions // 2 + 1`` slopes per 45-degree octant, eight octants.
    offsets : int
        Parallel lines per texel and direction (crossing points ``P`` sampled per texel).
    margin : float
        Texels by which a found violation is moved closer to ``P`` (and the scan extended
        past the box exit) to cover violations between the samples; 0 disables it.
    octants : bool
        Direction-dependent radii: one radius per texel and projected-direction octant
        (45 degrees each, `octant`), shape (8, H, W), instead of the smallest over all
        directions. A rough field's radius is often limited by a few directions only.
    progress : callable, optional
        ``progress(done, total)`` called after each batch of work (one direction in one of
        the eight octant frames: ``total = 8 * (directions // 2 + 1)``), for a progress bar.
    work : dict, optional
        Filled with the sweep's work per texel, a device-independent cost for benchmarks:
        ``visits`` (walk positions looked at: directions x offsets, all but those past a
        line's last needed position), ``pieces`` (profile pieces built), ``scans``
        (forward scans run) and ``scanned_pieces`` (pieces those scans visited).

    Returns
    -------
    numpy.ndarray
        (H, W) radii in texels, uint8 or uint16; (8, H, W) with ``octants``.

    Raises
    ------
    reliefkit.errors.UsageError
        For a height array that is not 2D, not finite or outside [0, 1], or bad options.

    Notes
    -----
    The walk positions are processed by numba in parallel (all sample lines of one direction
    at a time); the cost grows with the texel count, the number of samples and the radii.
    """
    h = checked_height(height)
    if not 0.0 <= float(tolerance) < np.inf:
        raise UsageError(f"tolerance must be a finite number >= 0, got {tolerance!r}")
    if not 0 <= int(max_radius) <= 65535:
        raise UsageError(f"max_radius must be in [0, 65535], got {max_radius!r}")
    if int(directions) < 2 or int(offsets) < 1:
        raise UsageError("directions must be >= 2 and offsets >= 1")
    if not 0.0 <= float(margin) <= 4.0:
        raise UsageError(f"margin must be within [0, 4] texels, got {margin!r}")
    dtype = np.uint8 if int(max_radius) <= 255 else np.uint16
    nthreads = numba.get_num_threads()
    per_frame = len(_FRAMES) if octants else 1
    bounds = np.full((per_frame,) + h.shape, int(max_radius), dtype=np.int32)
    # per thread, in the layout of the frames (transposed or not)
    own = {t: np.empty((nthreads,) + (h.shape[::-1] if t else h.shape), np.int32)
           for t in (False, True)}
    slopes = _slopes(int(directions))
    # float32 when that holds the heights exactly: the same radii for half the frames' memory
    h32 = h.astype(np.float32)
    hf = h32 if np.array_equal(h32, h) else h
    frames = [_frame(hf, *f) for f in _FRAMES]
    eps = float(tolerance) * (1.0 - TOLERANCE_SLACK)
    counts = np.zeros((nthreads, _COUNTS_STRIDE), np.int64)
    total = len(_FRAMES) * len(slopes)
    done = 0
    for si in _coarse_to_fine(len(slopes)):
        for f, ((transpose, flipx, flipy), frame) in enumerate(zip(_FRAMES, frames,
                                                                    strict=True)):
            previous = numba.get_parallel_chunksize()
            numba.set_parallel_chunksize(1)
            try:
                layer = bounds[f if octants else 0]
                _seed_bounds(layer, own[transpose], transpose, flipx, flipy)
                _sweep_direction(frame, float(slopes[si]), int(offsets), eps,
                                 NUMERIC_FLOOR, float(margin), own[transpose], counts)
                _merge_bounds(layer, own[transpose], transpose, flipx, flipy)
            finally:
                numba.set_parallel_chunksize(previous)
            done += 1
            if progress is not None:
                progress(done, total)
    if work is not None:
        per_texel = counts[:, :len(WORK_COUNTERS)].sum(axis=0) / h.size
        work.update(zip(WORK_COUNTERS, per_texel.tolist(), strict=True))
    radii = bounds.astype(dtype)
    return radii if octants else radii[0]
