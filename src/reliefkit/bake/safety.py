"""Safety radii for the robust binary search of Baboud & Decoret (2006), sections 3.4-3.5.

Definition (the contract the renderer's robust walk relies on)
--------------------------------------------------------------
Texel coordinates, heights and the bilinear, border-clamped surface ``S`` are those of
:mod:`reliefkit.reference.heightfield`. Let a ray have projected direction ``(dx, dy)`` in
texel units. If ``|dx| >= |dy|`` it is *x-major*: its walk positions ``P`` are the points
where it crosses the vertical centerlines ``x = i + 0.5``; the texel of such a ``P`` is
``(i, j)`` with ``j = clamp(floor(y_P), 0, H - 1)``, its radius is ``r = safety[j, i]`` and
the walk jumps to the centerline ``x = i + 0.5 + sign(dx) * r``. A *y-major* ray
(``|dy| > |dx|``) is the same with the roles of x and y (rows and columns) swapped.

``safety[j, i]`` is the largest ``n <= max_radius`` such that, for every ray (every
projected direction, every vertical slope up or down, every crossing point ``P`` of that
texel's centerline segment, any height above the surface at ``P``) that is *unblocked*,
i.e. strictly above the surface at every point from its entry into the box up to ``P``,
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
Fix a projected line ``y = y_c + m x`` (x-major, ``0 <= m <= 1``, the other seven octants
come from flipping / transposing the heightfield), its profile ``f(x) = S(x, y_c + m x)``
(piecewise quadratic, breaks at both families of centerlines) and a walk position ``P``.
For a point ``a > x_P`` let ``T_a`` be the ray through ``(a, f(a) - tolerance)`` that is
tangent to the upper convex hull ``A`` of the profile between the box side and ``P`` (the
steepest ray through that point that clears ``A``). A violation resurfacing at ``b`` exists
iff ``T_a(b) > f(b)`` for some ``x_P < a < b`` (both necessary and sufficient). The upper
envelope of those rays is ``L_K`` with ``K`` the running maximum of the tangent slopes, so
one forward scan finds the first violation ``b*``; then ``n = ceil(b* - x_P) - 1``.

* exact (up to rounding): the forward profile (closed-form quadratics per piece), the
  running maximum of the tangent slopes (closed-form extrema per piece while the tangent
  vertex on ``A`` is constant; intervals are bisected where it changes) and the first
  point where ``L_K`` rises above the profile;
* conservative: ``A`` is the hull of profile samples (piece ends and the maxima of concave
  pieces), which lies below the true hull, so more rays count as unblocked;
* sampled: the projected directions (``directions`` per half-plane and major axis, uniform
  in angle, both diagonals and the axis included) and the crossing points ``P`` within a
  texel (``offsets`` parallel lines per texel and direction, evenly spaced in ``y``; the
  phase varies from column to column). A violation that exists only between samples can be
  missed; :func:`check_safety` looks for exactly such rays with continuous random
  parameters and brute-force extremal rays.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numba
import numpy as np
from numba import njit, prange

from ..errors import UsageError
from ..reference.heightfield import (
    _cell_quadratic,
    _as_height,
    _clip_box,
    _crossings,
    _first_hit_range,
    _max_below,
    _surface,
    _walk_segments,
)

__all__ = [
    "NUMERIC_FLOOR",
    "CHECK_FLOOR",
    "Violation",
    "safety_radii",
    "check_safety",
    "zero_radius_fraction",
]

NUMERIC_FLOOR = 1e-9
"""Depths (height units) at or below this are float noise: the baker never counts them."""

CHECK_FLOOR = 1e-7
"""The checker ignores crossing pairs whose depth exceeds the tolerance by at most this
(the resolution of float32 heights near 1; a GPU walk cannot see shallower dips)."""

_JIT = {"cache": True, "error_model": "numpy", "nogil": True}
_NEG_INF = -np.inf


# ---------------------------------------------------------------------------------------------
# small numeric helpers
# ---------------------------------------------------------------------------------------------
@njit(**_JIT)
def _qv(a, b, c, u):
    return (a * u + b) * u + c


@njit(**_JIT)
def _root_between(a, b, c, lo, hi):
    """Root of ``a u^2 + b u + c`` on ``[lo, hi]`` where its sign differs at the two ends."""
    flo = _qv(a, b, c, lo) > 0.0
    # closed form first (stable formula), then verify; bisection as the fallback
    if a == 0.0:
        if b != 0.0:
            r = -c / b
            if lo <= r <= hi:
                return r
    else:
        disc = b * b - 4.0 * a * c
        if disc >= 0.0:
            q = -0.5 * (b + math.copysign(math.sqrt(disc), b))
            cands = (q / a, c / q if q != 0.0 else np.inf)
            for r in cands:
                if lo <= r <= hi:
                    return r
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        if (_qv(a, b, c, mid) > 0.0) == flo:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


@njit(**_JIT)
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
@njit(**_JIT)
def _line_range(hh, ww, m, yc):
    """x-range of the line ``y = yc + m x`` inside the rectangle ``[0, W] x [0, H]``."""
    if m == 0.0:
        if yc < 0.0 or yc > hh:
            return 1.0, 0.0
        return 0.0, float(ww)
    return max(0.0, -yc / m), min(float(ww), (hh - yc) / m)


@njit(**_JIT)
def _line_pieces(height, m, yc, xlo, xstop, bx, c0s, c1s, c2s):
    """Split the profile ``f(x) = S(x, yc + m x)`` on ``[xlo, xstop]`` into quadratic pieces.

    Piece ``k`` is ``[bx[k], bx[k+1]]`` with ``f = c0 + c1 u + c2 u^2``, ``u = x - bx[k]``.
    Breakpoints are the vertical centerlines ``x = i + 0.5`` and the points where the line
    crosses a horizontal centerline. Returns the number of pieces.
    """
    hh, ww = height.shape
    n = 0
    bx[0] = xlo
    i = int(math.floor(xlo - 0.5)) + 1  # next vertical centerline strictly after xlo
    xi = i + 0.5
    if m > 0.0:
        j = int(math.floor(yc + m * xlo - 0.5)) + 1
        xj = (j + 0.5 - yc) / m
    else:
        xj = np.inf
    last = xlo
    while True:
        nxt = min(min(xi, xj), xstop)
        if nxt > last + 1e-12:
            n += 1
            bx[n] = nxt
            last = nxt
        if nxt >= xstop:
            break
        if xi <= nxt:
            i += 1
            xi = i + 0.5
        if xj <= nxt:
            j += 1
            xj = (j + 0.5 - yc) / m
    for k in range(n):
        x0 = bx[k]
        xm = 0.5 * (x0 + bx[k + 1])
        cx = min(max(int(math.floor(xm + 0.5)), 0), ww)
        cy = min(max(int(math.floor(yc + m * xm + 0.5)), 0), hh)
        i0 = min(max(cx - 1, 0), ww - 1)
        i1 = min(cx, ww - 1)
        j0 = min(max(cy - 1, 0), hh - 1)
        j1 = min(cy, hh - 1)
        a00 = height[j0, i0]
        e = height[j0, i1] - a00
        f = height[j1, i0] - a00
        g = height[j1, i1] - height[j0, i1] - height[j1, i0] + a00
        px = x0 - (cx - 0.5)
        py = yc + m * x0 - (cy - 0.5)
        c0s[k] = a00 + e * px + f * py + g * px * py
        c1s[k] = e + f * m + g * (px * m + py)
        c2s[k] = g * m
    return n


# ---------------------------------------------------------------------------------------------
# upper convex hull of the profile behind P
# ---------------------------------------------------------------------------------------------
@njit(**_JIT)
def _hull_push(hx, hz, nh, x, z):
    """Append a point (increasing x) to an upper hull kept as a stack; returns the new size."""
    if nh > 0 and x <= hx[nh - 1] + 1e-12:
        if z <= hz[nh - 1]:
            return nh
        nh -= 1
    while nh >= 2:
        dxa = hx[nh - 1] - hx[nh - 2]
        dza = hz[nh - 1] - hz[nh - 2]
        if dza * (x - hx[nh - 2]) <= (z - hz[nh - 2]) * dxa:
            nh -= 1
        else:
            break
    hx[nh] = x
    hz[nh] = z
    return nh + 1


@njit(**_JIT)
def _tangent_vertex(hx, hz, nh, a, z):
    """Hull vertex minimising the slope from it to ``(a, z)`` (``a`` right of the hull)."""
    lo = 0
    hi = nh - 1
    while lo < hi:
        mid = (lo + hi) // 2
        # slope(mid + 1) < slope(mid)  <=>  move right
        if (z - hz[mid + 1]) * (a - hx[mid]) < (z - hz[mid]) * (a - hx[mid + 1]):
            lo = mid + 1
        else:
            hi = mid
    return lo


@njit(**_JIT)
def _support_vertex(hx, hz, nh, k):
    """Hull vertex touched by the supporting line of slope ``k`` (maximises ``z - k x``)."""
    lo = 0
    hi = nh - 1
    while lo < hi:
        mid = (lo + hi) // 2
        if hz[mid + 1] - hz[mid] <= k * (hx[mid + 1] - hx[mid]):
            hi = mid
        else:
            lo = mid + 1
    return lo


# ---------------------------------------------------------------------------------------------
# forward scan from one walk position
# ---------------------------------------------------------------------------------------------
@njit(**_JIT)
def _phi(u, x0, c0, c1, c2, xt, zt, eps):
    """Slope of the ray from hull vertex ``(xt, zt)`` through ``(x0 + u, f - eps)``."""
    w = x0 + u - xt
    if w <= 0.0:
        return _NEG_INF if eps > 0.0 else c1
    return (_qv(c2, c1, c0, u) - eps - zt) / w


@njit(**_JIT)
def _vertex_at(u, x0, c0, c1, c2, hx, hz, nh, eps):
    """Tangent vertex of the ray through ``(x0 + u, f - eps)``, with the limit at ``P``."""
    a = x0 + u
    if a <= hx[nh - 1]:
        if eps > 0.0 or nh == 1:
            return nh - 1
        elast = (hz[nh - 1] - hz[nh - 2]) / (hx[nh - 1] - hx[nh - 2])
        return nh - 1 if c1 <= elast else nh - 2
    return _tangent_vertex(hx, hz, nh, a, _qv(c2, c1, c0, u) - eps)


@njit(**_JIT)
def _frozen_check(ua, ub, k, tk, x0, c0, c1, c2, hx, hz, nh, floor):
    """First ``u`` in ``[ua, ub]`` where the support ray of slope ``k`` is above ``f + floor``.

    ``tk`` is the hull vertex touched by that ray (``-1``: not known yet). Returns
    ``(u or inf, tk)``.
    """
    if k == _NEG_INF or ub < ua:
        return np.inf, tk
    if tk < 0:
        tk = _support_vertex(hx, hz, nh, k)
    base = hz[tk] + k * (x0 - hx[tk]) - c0 - floor
    return _first_positive(-c2, k - c1, base, ua, ub), tk


@njit(**_JIT)
def _process_interval(ua, ub, t, k, tk, x0, c0, c1, c2, hx, hz, nh, eps, floor):
    """Advance the running maximum ``k`` of the tangent slopes over ``[ua, ub]``.

    The tangent vertex ``t`` is constant on the interval, so the slope ``phi(u)`` of the ray
    through ``(x0 + u, f - eps)`` is unimodal there; while ``phi`` sets a new maximum no
    violation is possible, elsewhere the frozen support ray of slope ``k`` is tested.
    Returns ``(u_violation or inf, k, tk)``.
    """
    xt = hx[t]
    zt = hz[t]
    d = x0 - xt
    # N(u) has the sign of d phi / du; N' = 2 c2 (x - xt) with x >= xt, so N is monotone.
    na = c2
    nb = 2.0 * c2 * d
    nc = c1 * d - c0 + eps + zt
    ue = ub
    if (_qv(na, nb, nc, ua) > 0.0) != (_qv(na, nb, nc, ub) > 0.0):
        ue = min(max(_root_between(na, nb, nc, ua, ub), ua), ub)
    for seg in range(2):
        lo = ua if seg == 0 else ue
        hi = ue if seg == 0 else ub
        if hi <= lo:
            continue
        increasing = _qv(na, nb, nc, 0.5 * (lo + hi)) > 0.0
        plo = _phi(lo, x0, c0, c1, c2, xt, zt, eps)
        phi_hi = _phi(hi, x0, c0, c1, c2, xt, zt, eps)
        if not increasing:
            if plo > k:
                k = plo
                tk = -1
            v, tk = _frozen_check(lo, hi, k, tk, x0, c0, c1, c2, hx, hz, nh, floor)
            if v != np.inf:
                return v, k, tk
        elif phi_hi <= k:
            v, tk = _frozen_check(lo, hi, k, tk, x0, c0, c1, c2, hx, hz, nh, floor)
            if v != np.inf:
                return v, k, tk
        else:
            if plo < k:
                # phi(u) = k  <=>  c2 u^2 + (c1 - k) u + (c0 - eps - zt - k d) = 0
                ux = _root_between(c2, c1 - k, c0 - eps - zt - k * d, lo, hi)
                v, tk = _frozen_check(lo, ux, k, tk, x0, c0, c1, c2, hx, hz, nh, floor)
                if v != np.inf:
                    return v, k, tk
            k = phi_hi
            tk = -1
    return np.inf, k, tk


@njit(**_JIT)
def _edge_crossing(x0, c0, c1, c2, eps, hx, hz, t, slope, lo, hi, above):
    """First ``u`` in ``[lo, hi]`` where ``(x0 + u, f - eps)`` is strictly above (``above``)
    or strictly below the line of slope ``slope`` through hull vertex ``t``."""
    if lo > hi:
        return np.inf
    a = c2
    b = c1 - slope
    c = c0 - eps - hz[t] - slope * (x0 - hx[t])
    if not above:
        a = -a
        b = -b
        c = -c
    g = _qv(a, b, c, lo)
    if abs(g) <= 1e-13:
        # on the edge line at the start (e.g. P itself): decided by where it goes next
        if 2.0 * a * lo + b > 0.0 or (2.0 * a * lo + b == 0.0 and a > 0.0):
            return lo
        c -= g  # treat the start as exactly on the line
        if a != 0.0:
            uc = -b / (2.0 * a)
            if lo < uc < hi:
                return _first_positive(a, b, c, uc, hi)
        return _first_positive(a, b, c, hi, hi)
    return _first_positive(a, b, c, lo, hi)


@njit(**_JIT)
def _scan(bx, c0s, c1s, c2s, npieces, kp, xlimit, hx, hz, nh, eps, floor):
    """First violation ``b*`` (absolute x) after the walk position at piece ``kp``.

    Scans pieces until ``xlimit``; returns ``inf`` when there is no violation before it.
    Each piece is split where the tangent vertex on the hull changes: the vertex ``t`` is
    optimal while the moving point stays below the extension of the hull edge on its left
    and above the one on its right, so the switch points are roots of quadratics.
    """
    k = _NEG_INF
    tk = -1
    t = _vertex_at(0.0, bx[kp], c0s[kp], c1s[kp], c2s[kp], hx, hz, nh, eps)
    for kk in range(kp, npieces):
        x0 = bx[kk]
        if x0 >= xlimit:
            break
        length = min(bx[kk + 1], xlimit) - x0
        c0 = c0s[kk]
        c1 = c1s[kk]
        c2 = c2s[kk]
        u = 0.0
        came_from = -1
        for _ in range(4 * nh + 8):
            us = length
            tn = t
            if t > 0:
                # the edge just crossed cannot be crossed back at the same point
                lo = u + 1e-9 if came_from == t - 1 else u
                e = (hz[t] - hz[t - 1]) / (hx[t] - hx[t - 1])
                ul = _edge_crossing(x0, c0, c1, c2, eps, hx, hz, t, e, lo, length, True)
                if ul < us:
                    us = ul
                    tn = t - 1
            if t < nh - 1:
                lo = u + 1e-9 if came_from == t + 1 else u
                e = (hz[t + 1] - hz[t]) / (hx[t + 1] - hx[t])
                ur = _edge_crossing(x0, c0, c1, c2, eps, hx, hz, t, e, lo, length, False)
                if ur < us:
                    us = ur
                    tn = t + 1
            v, k, tk = _process_interval(u, us, t, k, tk, x0, c0, c1, c2, hx, hz, nh, eps,
                                         floor)
            if v != np.inf:
                return x0 + v
            if tn == t:
                break
            came_from = t
            t = tn
            u = us
    return np.inf


# ---------------------------------------------------------------------------------------------
# one direction (all parallel lines of one slope, in one of the eight octant frames)
# ---------------------------------------------------------------------------------------------
@njit(**_JIT)
def _to_original(ip, jp, wp, hp, transpose, flipx, flipy):
    i2 = wp - 1 - ip if flipx else ip
    j2 = hp - 1 - jp if flipy else jp
    if transpose:
        return i2, j2  # (row, col) in the original array
    return j2, i2


@njit(**_JIT)
def _current_bound(bufs, r, c):
    best = bufs[0, r, c]
    for b in range(1, bufs.shape[0]):
        best = min(best, bufs[b, r, c])
    return best


@njit(**_JIT)
def _rows_of(y0, hp):
    """Rows whose texel contains the centerline point at height ``y0`` (two on a border)."""
    j = min(max(int(math.floor(y0)), 0), hp - 1)
    j2 = j
    if y0 == math.floor(y0) and 0 < y0 < hp:
        j2 = j - 1
    return j, j2


@njit(**_JIT)
def _sweep_line(height, m, yc, eps, floor, margin, offsets, bufs, tid, transpose, flipx, flipy,
                work):
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
    # how far along the line does any walk position still need work?
    xstop = xlo
    for i in range(i_first, i_last + 1):
        xp = i + 0.5
        j, j2 = _rows_of(yc + m * xp, hp)
        r, c = _to_original(i, j, wp, hp, transpose, flipx, flipy)
        bound = _current_bound(bufs, r, c)
        if j2 != j:
            r2, c2 = _to_original(i, j2, wp, hp, transpose, flipx, flipy)
            bound = max(bound, _current_bound(bufs, r2, c2))
        if bound > 0:
            xstop = max(xstop, min(xend, xp + 2 * bound + margin))
    if not xstop > xlo:
        return
    bx = work[0]
    c0s = work[1]
    c1s = work[2]
    c2s = work[3]
    hx = work[4]
    hz = work[5]
    npieces = _line_pieces(height, m, yc, xlo, xstop, bx, c0s, c1s, c2s)
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
        while k < npieces and bx[k] <= xp + 1e-9:
            if k > 0 and c2s[k - 1] < 0.0:
                # maximum of a concave piece: a better (still conservative) hull sample
                uc = -c1s[k - 1] / (2.0 * c2s[k - 1])
                if 0.0 < uc < bx[k] - bx[k - 1]:
                    nh = _hull_push(hx, hz, nh, bx[k - 1] + uc,
                                    _qv(c2s[k - 1], c1s[k - 1], c0s[k - 1], uc))
            nh = _hull_push(hx, hz, nh, bx[k], c0s[k])
            k += 1
        if k == 0 or bx[k - 1] < xp - 1e-9:
            continue  # P is the end of the line: nothing after it
        j, j2 = _rows_of(yc + m * xp, hp)
        r, c = _to_original(i, j, wp, hp, transpose, flipx, flipy)
        r2, c2 = _to_original(i, j2, wp, hp, transpose, flipx, flipy)
        bound = max(_current_bound(bufs, r, c), _current_bound(bufs, r2, c2))
        if bound == 0:
            continue
        limit = min(xp + bound + margin, xstop)
        if known >= limit:
            continue
        # scan a little further than needed so that the next walk positions can be skipped
        reach = min(limit + bound, xstop)
        b = _scan(bx, c0s, c1s, c2s, npieces, k - 1, reach, hx, hz, nh, eps, floor)
        known = b if b != np.inf else reach
        if b <= limit:
            n = max(int(math.ceil(b - xp - margin)) - 1, 0)
            if n < bufs[tid, r, c]:
                bufs[tid, r, c] = n
            if n < bufs[tid, r2, c2]:
                bufs[tid, r2, c2] = n


@njit(parallel=True, **_JIT)
def _sweep_direction(height, m, offsets, eps, floor, margin, bufs, transpose, flipx, flipy):
    """All sample lines of slope ``m`` in one octant frame, in parallel.

    The lines are ``y = k / offsets + m x`` for every integer ``k`` that reaches the
    rectangle, plus (``m > 0``) one line per column entering the box exactly at that
    column's walk position (``P`` on the box side, where nothing behind ``P`` blocks).
    """
    hp, wp = height.shape
    k_lo = int(math.floor(-m * wp * offsets))
    k_hi = int(math.ceil(hp * offsets))
    nlines = k_hi - k_lo + 1
    nextra = wp if m > 0.0 else 0
    nthreads = bufs.shape[0]
    cap = hp + wp + 16
    works = np.empty((nthreads, 6, 3 * cap))
    for li in prange(nlines + nextra):
        tid = numba.get_thread_id()
        if li < nlines:
            yc = (k_lo + li) / offsets
        else:
            yc = -m * (li - nlines + 0.5)
        _sweep_line(height, m, yc, eps, floor, margin, offsets, bufs, tid, transpose, flipx, flipy,
                    works[tid])


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


def safety_radii(height, *, tolerance: float = 0.0, max_radius: int = 255,
                 directions: int = 64, offsets: int = 4, margin: float = 0.25,
                 progress: Callable[[int, int], None] | None = None) -> np.ndarray:
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
    progress : callable, optional
        ``progress(done, total)`` called after each (octant, direction) batch.

    Returns
    -------
    numpy.ndarray
        (H, W) radii in texels, uint8 or uint16.
    """
    h = _as_height(height)
    if not 0.0 <= float(tolerance) < np.inf:
        raise UsageError(f"tolerance must be a finite number >= 0, got {tolerance!r}")
    if not 0 <= int(max_radius) <= 65535:
        raise UsageError(f"max_radius must be in [0, 65535], got {max_radius!r}")
    if int(directions) < 2 or int(offsets) < 1:
        raise UsageError("directions must be >= 2 and offsets >= 1")
    dtype = np.uint8 if int(max_radius) <= 255 else np.uint16
    nthreads = numba.get_num_threads()
    bufs = np.full((nthreads,) + h.shape, int(max_radius), dtype=np.int32)
    slopes = _slopes(int(directions))
    frames = [_frame(h, *f) for f in _FRAMES]
    total = len(_FRAMES) * len(slopes)
    done = 0
    for si in _coarse_to_fine(len(slopes)):
        for (transpose, flipx, flipy), frame in zip(_FRAMES, frames):
            previous = numba.get_parallel_chunksize()
            numba.set_parallel_chunksize(1)
            try:
                _sweep_direction(frame, float(slopes[si]), int(offsets), float(tolerance),
                                 NUMERIC_FLOOR, float(margin), bufs, transpose, flipx, flipy)
            finally:
                numba.set_parallel_chunksize(previous)
            done += 1
            if progress is not None:
                progress(done, total)
    return bufs.min(axis=0).astype(dtype)


def zero_radius_fraction(safety) -> float:
    """Fraction of texels whose safety radius is 0 (the renderer must clamp or step exactly)."""
    s = np.asarray(safety)
    if s.size == 0:
        raise UsageError("safety is empty")
    return float(np.count_nonzero(s == 0)) / s.size


# ---------------------------------------------------------------------------------------------
# public API: brute-force checker
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Violation:
    """A ray for which a safety radius does not hold.

    Attributes
    ----------
    row, col : int
        Texel of the walk position ``P`` (``safety[row, col]`` is the radius used).
    radius : int
        The radius that was checked.
    major : str
        ``"x"`` or ``"y"``: which centerlines the walk position lies on.
    origin, direction : tuple of float
        The ray in box coordinates; ``t = 0`` is ``P`` and ``t = radius`` the jump target.
    crossings : tuple of float
        Crossing parameters strictly between ``P`` and the target.
    depth : float
        Largest depth below the surface between a down and the next up crossing.
    """

    row: int
    col: int
    radius: int
    major: str
    origin: tuple
    direction: tuple
    crossings: tuple
    depth: float


@njit(**_JIT)
def _xy_range(o, d):
    """Parameter range of the ray's projection inside the unit square (z ignored)."""
    t0 = -np.inf
    t1 = np.inf
    for a in range(2):
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


@njit(**_JIT)
def _lowest_clear_height(height, o, d, t0, t1):
    """Smallest ``o[2]`` keeping the ray on or above the surface on ``[t0, t1]`` (xy only)."""
    hh, ww = height.shape
    oz = o.copy()
    oz[2] = 0.0
    ts, cxs, cys, n = _walk_segments(hh, ww, oz, d, t0, t1)
    best = _surface(height, (o[0] + t1 * d[0]) * ww, (o[1] + t1 * d[1]) * hh) - t1 * d[2]
    for k in range(n):
        ta = ts[k]
        length = ts[k + 1] - ta
        a, b, c = _cell_quadratic(height, oz, d, cxs[k], cys[k], ta)
        best = max(best, -c, -((a * length + b) * length + c))
        if a != 0.0:
            sc = -b / (2.0 * a)
            if 0.0 < sc < length:
                best = max(best, -((a * sc + b) * sc + c))
    return best


@njit(**_JIT)
def _check_one(height, o, d, radius, tol):
    """(status, depth, crossings) of one ray: status 0 ok, 1 blocked/irrelevant, 2 violation."""
    t_in, t_out = _clip_box(o, d, -np.inf, np.inf)
    empty = np.empty(0)
    if t_in > t_out or radius <= 0:
        return 1, 0.0, empty
    if t_in <= 0.0:
        if _first_hit_range(height, o, d, t_in, min(0.0, t_out)) <= 0.0:
            return 1, 0.0, empty
    cr = _crossings(height, o, d, 0.0, float(radius))
    start = max(t_in, 0.0)
    # state at the start of the checked range
    x = (o[0] + start * d[0]) * height.shape[1]
    y = (o[1] + start * d[1]) * height.shape[0]
    below = o[2] + start * d[2] <= _surface(height, x, y)
    down = start if below else -1.0
    worst = 0.0
    status = 0
    for c in cr:
        if not below:
            down = c
            below = True
        else:
            below = False
            if down > 0.0 and c < radius:
                depth = _max_below(height, o, d, down, c)
                if depth > tol + CHECK_FLOOR and depth > worst:
                    worst = depth
                    status = 2
    return status, worst, cr


@njit(**_JIT)
def _profile(height, px, py, ddx, ddy, s0, s1, step):
    """Samples ``(s, S(P + s (ddx, ddy)))`` on ``[s0, s1]`` with about ``step`` spacing."""
    n = max(2, int(math.ceil((s1 - s0) / step)) + 1)
    ss = np.empty(n)
    ff = np.empty(n)
    for q in range(n):
        sv = s0 + (s1 - s0) * q / (n - 1)
        ss[q] = sv
        ff[q] = _surface(height, px + sv * ddx, py + sv * ddy)
    return ss, ff


@njit(**_JIT)
def _tangent_candidate(height, px, py, ddx, ddy, radius, tol, delta):
    """Brute-force extremal ray of Fig. 8 on a densely sampled profile.

    For every sampled point ``a`` after ``P`` the steepest ray through ``(a, f(a) - tol -
    delta)`` clearing the sampled profile behind ``P`` is built; the one that rises above the
    profile again first (before the jump target) is returned as ``(found, k, z_at_P)``.
    """
    hh, ww = height.shape
    # parameter range of the line inside the texture rectangle
    s_lo = -np.inf
    s_hi = np.inf
    for p0, dp, n in ((px, ddx, ww), (py, ddy, hh)):
        if dp != 0.0:
            ta = (0.0 - p0) / dp
            tb = (n - p0) / dp
            s_lo = max(s_lo, min(ta, tb))
            s_hi = min(s_hi, max(ta, tb))
    s_end = min(float(radius), s_hi)
    if not s_end > 0.0 or s_lo > 0.0:
        return False, 0.0, 0.0
    bs, bf = _profile(height, px, py, ddx, ddy, s_lo, 0.0, 0.125)
    hx = np.empty(bs.shape[0])
    hz = np.empty(bs.shape[0])
    nh = 0
    for q in range(bs.shape[0]):
        nh = _hull_push(hx, hz, nh, bs[q], bf[q])
    fs, ff = _profile(height, px, py, ddx, ddy, 0.0, s_end, max(1.0 / 16.0, s_end / 512.0))
    best_b = np.inf
    best_k = 0.0
    best_z = 0.0
    for q in range(1, fs.shape[0]):
        za = ff[q] - tol - delta
        t = _tangent_vertex(hx, hz, nh, fs[q], za)
        k = (za - hz[t]) / (fs[q] - hx[t])
        for r in range(q + 1, fs.shape[0]):
            if fs[r] >= best_b:
                break
            if za + k * (fs[r] - fs[q]) > ff[r]:
                best_b = fs[r]
                best_k = k
                best_z = za - k * fs[q]
                break
    if best_b == np.inf:
        return False, 0.0, 0.0
    return True, best_k, best_z


@njit(parallel=True, **_JIT)
def _check_batch(height, safety, rows, cols, majors, signs, offs, slopes, ks, lifts, modes, tol,
                 status, depth, origins, dirs):
    hh, ww = height.shape
    for r in prange(rows.shape[0]):
        j = rows[r]
        i = cols[r]
        if majors[r] == 0:
            px = i + 0.5
            py = j + offs[r]
            ddx = signs[r]
            ddy = signs[r] * slopes[r]
        else:
            px = i + offs[r]
            py = j + 0.5
            ddx = signs[r] * slopes[r]
            ddy = signs[r]
        o = np.empty(3)
        d = np.empty(3)
        o[0] = px / ww
        o[1] = py / hh
        d[0] = ddx / ww
        d[1] = ddy / hh
        d[2] = ks[r]
        radius = int(safety[j, i])
        status[r] = 1
        if modes[r] == 0:
            # plain ray at a random height above P
            o[2] = _surface(height, px, py) + lifts[r]
        else:
            if modes[r] == 2:
                found, k, z = _tangent_candidate(height, px, py, ddx, ddy, radius, tol,
                                                 lifts[r])
                if not found:
                    continue
                d[2] = k
                o[2] = z
            else:
                o[2] = -np.inf
            # never below the lowest ray that clears the surface up to P (extremal ray)
            t0, t1 = _xy_range(o, d)
            low = _lowest_clear_height(height, o, d, t0, 0.0)
            if o[2] <= low:
                o[2] = low + (lifts[r] if modes[r] == 1 else 1e-12 + 1e-12 * abs(low))
        s, dep, _ = _check_one(height, o, d, radius, tol)
        status[r] = s
        depth[r] = dep
        origins[r] = o
        dirs[r] = d


def _ray_parameters(shape, rays: int, rng, adversarial: bool):
    """Random walk positions, directions, slopes, heights and generator modes.

    Modes: 0 plain ray above ``P``; 1 extremal ray (lowest clearing ray, lifted by ``lift``);
    2 brute-force tangent ray (``lift`` is the extra depth below ``f - tolerance``).
    """
    hh, ww = shape
    n = int(rays)
    rows = rng.integers(0, hh, n)
    cols = rng.integers(0, ww, n)
    majors = rng.integers(0, 2, n)
    signs = rng.choice(np.array([-1.0, 1.0]), n)
    offs = rng.random(n)
    slopes = np.tan(rng.uniform(-np.pi / 4, np.pi / 4, n))
    ks = rng.choice(np.array([-1.0, 1.0]), n) * 10.0 ** rng.uniform(-4.0, 0.7, n)
    steep = rng.random(n) < 0.2
    ks[steep] = np.tan(rng.uniform(-1.5, 1.5, steep.sum()))
    lifts = 10.0 ** rng.uniform(-6.0, -0.3, n)
    modes = np.zeros(n, np.int64)
    if adversarial:
        special = rng.random(n) < 0.2
        offs[special] = rng.choice(np.array([0.0, 0.5, 1.0, 1e-9, 1.0 - 1e-9]), special.sum())
        rational = np.array([0.0, 1.0, -1.0, 0.5, -0.5, 1 / 3, -1 / 3, 2 / 3, -2 / 3, 0.25, -0.25])
        special = rng.random(n) < 0.2
        slopes[special] = rng.choice(rational, special.sum())
        flat = rng.random(n) < 0.15
        ks[flat] = rng.choice(np.array([-1.0, 1.0]), flat.sum()) * 10.0 ** rng.uniform(
            -7.0, -3.0, flat.sum())
        u = rng.random(n)
        modes[u < 0.8] = 1
        modes[u < 0.5] = 2
        lifts[modes == 1] = 10.0 ** rng.uniform(-10.0, -1.5, (modes == 1).sum())
        lifts[modes == 2] = 2.0 * CHECK_FLOOR + 10.0 ** rng.uniform(-8.0, -2.5, (modes == 2).sum())
    return rows, cols, majors, signs, offs, slopes, ks, lifts, modes


def check_safety(height, safety, *, tolerance: float = 0.0, rays: int = 20000, seed: int = 0,
                 adversarial: bool = True) -> list[Violation]:
    """Brute-force check of safety radii with the exact reference intersection.

    Rays are built in the walk's own terms: a texel, a walk position ``P`` on one of its
    centerline segments, a projected direction (x- or y-major, either sign) and a vertical
    slope. Three generators are mixed (the last two only when ``adversarial``):

    * plain rays at a random height above ``P``;
    * extremal rays (Fig. 8): for a random slope, the lowest ray that clears the surface
      from the box side up to ``P`` (exact), lifted by a tiny random amount; texel edges and
      centres as offsets, rational projected slopes (rays through texel centres) and
      near-horizontal slopes are over-sampled;
    * brute-force tangent rays: on a densely sampled profile of the line, the steepest ray
      through a point ``tolerance`` (plus a tiny margin) below the surface after ``P`` that
      clears the profile behind ``P``, choosing the one that resurfaces first.

    A ray is discarded when it is blocked (the exact first hit from its box entry is at or
    before ``P``). For the others every pair of crossings (down, then up) strictly between
    ``P`` and the jump target ``radius`` centerlines further (cut at the box boundary) whose
    largest depth exceeds ``tolerance + CHECK_FLOOR`` is a violation. Crossings, depths and
    blocking use only :mod:`reliefkit.reference.heightfield`, not the baker.

    Parameters
    ----------
    height : (H, W) array_like
    safety : (H, W) array_like of int
        Radii to check.
    tolerance : float
        The tolerance the radii were baked with.
    rays : int
        Number of rays.
    seed : int
        Seed of ``numpy.random.default_rng``.
    adversarial : bool
        Mix in the adversarial generators (otherwise plain random rays only).

    Returns
    -------
    list of Violation
        Empty when no violation was found.
    """
    h = _as_height(height)
    s = np.asarray(safety)
    if s.shape != h.shape:
        raise UsageError(f"safety shape {s.shape} does not match height shape {h.shape}")
    s = np.ascontiguousarray(s, dtype=np.int64)
    rng = np.random.default_rng(seed)
    params = _ray_parameters(h.shape, rays, rng, adversarial)
    rows, cols, majors = params[:3]
    n = rows.shape[0]
    status = np.zeros(n, np.int64)
    depth = np.zeros(n)
    origins = np.zeros((n, 3))
    dirs = np.zeros((n, 3))
    _check_batch(h, s, *params, float(tolerance), status, depth, origins, dirs)
    out = []
    for r in np.nonzero(status == 2)[0]:
        radius = int(s[rows[r], cols[r]])
        cr = _crossings(h, origins[r], dirs[r], 0.0, float(radius))
        out.append(Violation(int(rows[r]), int(cols[r]), radius, "xy"[int(majors[r])],
                             tuple(float(v) for v in origins[r]),
                             tuple(float(v) for v in dirs[r]),
                             tuple(float(c) for c in cr if 0.0 < c < radius),
                             float(depth[r])))
    return out
