"""Brute-force checker of safety radii, built only on the exact heightfield reference.

It is independent of the baker (`safety.py`): rays are generated in the walk's own terms
and judged with `reliefkit.reference.heightfield`, so a radius that lets the robust walk skip a
violating pair of crossings is reported as a `Violation`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit, prange

from ...errors import UsageError
from ...reference.heightfield import (
    JIT_OPTIONS,
    cell_quadratic,
    clip_box,
    crossings_between,
    first_hit_in,
    max_depth_below,
    surface_at,
    walk_segments,
)
from .safety import checked_height, hull_push, octant, tangent_vertex

__all__ = ["CHECK_FLOOR", "Violation", "check_safety"]

CHECK_FLOOR = 1e-6
"""The checker ignores crossing pairs whose depth exceeds the tolerance by at most this.

Sampling the directions and walk positions can miss dips that exist only in a vanishingly
thin set of rays (typically grazing a crease with all but the same blocking); their depth
is then a few 1e-7, far below what a float32 walk with hardware bilinear filtering resolves.
"""



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


@njit(**JIT_OPTIONS)
def _xy_range(o, d):
    """Parameter range of the ray's projection inside the unit square (z ignored)."""
    return clip_box(o, d, -np.inf, np.inf, 2)


@njit(**JIT_OPTIONS)
def _lowest_clear_height(height, o, d, t0, t1):
    """Smallest ``o[2]`` keeping the ray on or above the surface on ``[t0, t1]`` (xy only)."""
    hh, ww = height.shape
    oz = o.copy()
    oz[2] = 0.0
    ts, cxs, cys, n = walk_segments(hh, ww, oz, d, t0, t1)
    best = surface_at(height, (o[0] + t1 * d[0]) * ww, (o[1] + t1 * d[1]) * hh) - t1 * d[2]
    for k in range(n):
        ta = ts[k]
        length = ts[k + 1] - ta
        a, b, c = cell_quadratic(height, oz, d, cxs[k], cys[k], ta)
        best = max(best, -c, -((a * length + b) * length + c))
        if a != 0.0:
            sc = -b / (2.0 * a)
            if 0.0 < sc < length:
                best = max(best, -((a * sc + b) * sc + c))
    return best


@njit(**JIT_OPTIONS)
def _check_one(height, o, d, radius, tol):
    """(status, depth, crossings) of one ray: status 0 ok, 1 blocked/irrelevant, 2 violation."""
    t_in, t_out = clip_box(o, d, -np.inf, np.inf)
    empty = np.empty(0)
    if t_in > t_out or radius <= 0:
        return 1, 0.0, empty
    if t_in <= 0.0 and first_hit_in(height, o, d, t_in, min(0.0, t_out)) <= 0.0:
        return 1, 0.0, empty
    cr = crossings_between(height, o, d, 0.0, float(radius))
    start = max(t_in, 0.0)
    # state at the start of the checked range
    x = (o[0] + start * d[0]) * height.shape[1]
    y = (o[1] + start * d[1]) * height.shape[0]
    below = o[2] + start * d[2] <= surface_at(height, x, y)
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
                depth = max_depth_below(height, o, d, down, c)
                if depth > tol + CHECK_FLOOR and depth > worst:
                    worst = depth
                    status = 2
    return status, worst, cr


@njit(**JIT_OPTIONS)
def _profile(height, px, py, ddx, ddy, s0, s1, step):
    """Samples ``(s, S(P + s (ddx, ddy)))`` on ``[s0, s1]`` with about ``step`` spacing."""
    n = max(2, int(math.ceil((s1 - s0) / step)) + 1)
    ss = np.empty(n)
    ff = np.empty(n)
    for q in range(n):
        sv = s0 + (s1 - s0) * q / (n - 1)
        ss[q] = sv
        ff[q] = surface_at(height, px + sv * ddx, py + sv * ddy)
    return ss, ff


@njit(**JIT_OPTIONS)
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
    hull = np.empty((6, bs.shape[0]))
    nh = 0
    for q in range(bs.shape[0]):
        nh = hull_push(hull, nh, bs[q], bf[q])
    fs, ff = _profile(height, px, py, ddx, ddy, 0.0, s_end, max(1.0 / 16.0, s_end / 512.0))
    best_b = np.inf
    best_k = 0.0
    best_z = 0.0
    for q in range(1, fs.shape[0]):
        za = ff[q] - tol - delta
        t = tangent_vertex(hull, nh, fs[q], za)
        k = (za - hull[5, t]) / (fs[q] - hull[4, t])
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


@njit(**JIT_OPTIONS)
def _check_one_ray(height, radius, j, i, major, sign, off, slope, kz, lift, mode, tol, o, d):
    """Build one checker ray (see :func:`check_safety`) into ``o, d``; returns its status
    (0 fine, 1 blocked or not generated, 2 violation) and the violating depth."""
    hh, ww = height.shape
    if major == 0:
        px = i + 0.5
        py = j + off
        ddx = sign
        ddy = sign * slope
    else:
        px = i + off
        py = j + 0.5
        ddx = sign * slope
        ddy = sign
    o[0] = px / ww
    o[1] = py / hh
    d[0] = ddx / ww
    d[1] = ddy / hh
    d[2] = kz
    if mode == 0:
        # plain ray at a random height above P
        o[2] = surface_at(height, px, py) + lift
    else:
        o[2] = -np.inf
        if mode == 2:
            found, k, z = _tangent_candidate(height, px, py, ddx, ddy, radius, tol, lift)
            if not found:
                return 1, 0.0
            d[2] = k
            o[2] = z
        # never below the lowest ray that clears the surface up to P (extremal ray)
        t0, _ = _xy_range(o, d)
        low = _lowest_clear_height(height, o, d, t0, 0.0)
        if o[2] <= low:
            o[2] = low + (lift if mode == 1 else 1e-12 + 1e-12 * abs(low))
    s, dep, _ = _check_one(height, o, d, radius, tol)
    return s, dep


@njit(parallel=True, **JIT_OPTIONS)
def _check_batch(height, radii, rows, cols, majors, signs, offs, slopes, ks, lifts, modes, tol,
                 status, depth, origins, dirs):
    for r in prange(rows.shape[0]):
        s, dep = _check_one_ray(height, int(radii[r]), rows[r], cols[r],
                                majors[r], signs[r], offs[r], slopes[r], ks[r], lifts[r],
                                modes[r], tol, origins[r], dirs[r])
        status[r] = s
        depth[r] = dep


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
        Radii to check; or (8, H, W), one per direction octant (`safety.octant`): each ray
        is checked against its own octant's radius.
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
    h = checked_height(height)
    s = np.asarray(safety)
    if s.shape not in (h.shape, (8, *h.shape)):
        raise UsageError(f"safety shape {s.shape} does not match height shape {h.shape} "
                         "(or (8, H, W) per direction octant)")
    s = np.ascontiguousarray(s, dtype=np.int64)
    rng = np.random.default_rng(seed)
    params = _ray_parameters(h.shape, rays, rng, adversarial)
    rows, cols, majors = params[:3]
    if s.ndim == 3:  # each ray checks the radius of its direction's octant
        signs, slopes = params[3], params[5]
        radii = s[octant(majors == 0, signs, signs * slopes), rows, cols]
    else:
        radii = s[rows, cols]
    n = rows.shape[0]
    status = np.zeros(n, np.int64)
    depth = np.zeros(n)
    origins = np.zeros((n, 3))
    dirs = np.zeros((n, 3))
    _check_batch(h, radii, *params, float(tolerance), status, depth, origins, dirs)
    out = []
    for r in np.nonzero(status == 2)[0]:
        radius = int(radii[r])
        cr = crossings_between(h, origins[r], dirs[r], 0.0, float(radius))
        out.append(Violation(int(rows[r]), int(cols[r]), radius, "xy"[int(majors[r])],
                             tuple(float(v) for v in origins[r]),
                             tuple(float(v) for v in dirs[r]),
                             tuple(float(c) for c in cr if 0.0 < c < radius),
                             float(depth[r])))
    return out
