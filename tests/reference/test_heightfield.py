"""The exact ray vs bilinear-patch heightfield intersection against brute force and analytic
answers (reliefkit.reference.heightfield: its kernels, one ray at a time)."""

from __future__ import annotations

import numpy as np
import pytest

from reliefkit.errors import UsageError
from reliefkit.reference.heightfield import (
    as_height,
    clip_box,
    crossings_between,
    first_hit_in,
    intersect_rays,
    max_depth_below,
    surface_height,
    walk_segments,
)

TOL = 1e-6


# ---------------------------------------------------------------------------------------------
# one ray through the kernels
# ---------------------------------------------------------------------------------------------
def _ray(origin, direction) -> tuple[np.ndarray, np.ndarray]:
    return np.asarray(origin, dtype=np.float64), np.asarray(direction, dtype=np.float64)


def intersect_ray(height, origin, direction) -> float:
    """The first hit of one ray (`intersect_rays`)."""
    return float(intersect_rays(height, [origin], [direction])[0])


def ray_crossings(height, origin, direction, t0, t1) -> np.ndarray:
    """Every crossing of one ray with the surface on [t0, t1] (`crossings_between`)."""
    return crossings_between(as_height(height), *_ray(origin, direction), float(t0), float(t1))


def max_penetration(height, origin, direction, t0, t1) -> float:
    """Largest depth of one ray below the surface on [t0, t1] (`max_depth_below`)."""
    return float(max_depth_below(as_height(height), *_ray(origin, direction), float(t0),
                                 float(t1)))


def cells_visited(height, origin, direction, t_max: float | None = None) -> int:
    """Cells the exact walk (`walk_segments`) visits from the box entry to the first hit,
    the box exit or ``t_max``."""
    h = as_height(height)
    o, d = _ray(origin, direction)
    t0, t1 = clip_box(o, d, 0.0, np.inf)
    if t0 > t1:
        return 0
    end = min(t1, first_hit_in(h, o, d, t0, t1), np.inf if t_max is None else float(t_max))
    if end == t0:
        return 1
    return int(walk_segments(*h.shape, o, d, t0, end)[3])


# ---------------------------------------------------------------------------------------------
# brute force: dense sampling of F = h - S along the ray, then bisection
# ---------------------------------------------------------------------------------------------
def _box_range(o, d):
    t0, t1 = 0.0, np.inf
    for a in range(3):
        if d[a] == 0.0:
            if not 0.0 <= o[a] <= 1.0:
                return None
        else:
            ta, tb = sorted(((0.0 - o[a]) / d[a], (1.0 - o[a]) / d[a]))
            t0, t1 = max(t0, ta), min(t1, tb)
    return (t0, t1) if t0 <= t1 else None


def _f(height, o, d, t):
    hh, ww = height.shape
    p = np.asarray(o)[None, :] + np.multiply.outer(np.atleast_1d(t), np.asarray(d))
    return p[:, 2] - surface_height(height, p[:, 0] * ww, p[:, 1] * hh)


def brute_force_hit(height, o, d, samples=100_000):
    """First t with h <= S by sampling 1e5 points of the clipped ray and bisecting."""
    o = np.asarray(o, float)
    d = np.asarray(d, float)
    r = _box_range(o, d)
    if r is None:
        return np.inf
    ts = np.linspace(r[0], r[1], samples)
    below = np.nonzero(_f(height, o, d, ts) <= 0.0)[0]
    if below.size == 0:
        return np.inf
    k = below[0]
    if k == 0:
        return ts[0]
    lo, hi = ts[k - 1], ts[k]
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if _f(height, o, d, mid)[0] <= 0.0:
            hi = mid
        else:
            lo = mid
    return hi


def _random_rays(rng, n):
    """Rays from above the box, from inside it, grazing ones and straight-down ones."""
    rays = []
    for k in range(n):
        kind = k % 4
        o = rng.random(3)
        d = rng.normal(size=3)
        if kind == 0:  # from above the box, going down
            o[2] = 1.0 + rng.random()
            d[2] = -abs(d[2]) - 0.05
        elif kind == 1:  # starting inside the box (possibly below the surface)
            pass
        elif kind == 2:  # grazing: almost horizontal
            o[2] = rng.uniform(0.3, 1.0)
            d[2] = -rng.uniform(1e-4, 2e-2) * np.hypot(d[0], d[1])
        else:  # straight down
            o[2] = 1.0
            d = np.array([0.0, 0.0, -1.0])
        rays.append((o, d))
    return rays


# ---------------------------------------------------------------------------------------------
# surface
# ---------------------------------------------------------------------------------------------
def test_surface_interpolates_centres_and_clamps():
    h = np.array([[0.0, 1.0], [0.5, 0.25]])
    assert surface_height(h, 0.5, 0.5) == 0.0
    assert surface_height(h, 1.5, 0.5) == 1.0
    assert surface_height(h, 0.5, 1.5) == 0.5
    assert surface_height(h, 1.0, 0.5) == pytest.approx(0.5)
    assert surface_height(h, 1.0, 1.0) == pytest.approx((0.0 + 1.0 + 0.5 + 0.25) / 4)
    # clamped half cells at the border: constant beyond the outer centerlines
    assert surface_height(h, 0.0, 0.0) == 0.0
    assert surface_height(h, 2.0, 0.1) == 1.0
    out = surface_height(h, np.array([0.2, 1.9]), 0.5)
    np.testing.assert_allclose(out, [0.0, 1.0])


def test_bad_input_is_a_usage_error():
    with pytest.raises(UsageError):
        intersect_rays(np.array([[np.nan]]), [[0, 0, 1]], [[0, 0, -1]])
    with pytest.raises(UsageError):
        intersect_rays(np.zeros(3), [[0, 0, 1]], [[0, 0, -1]])
    with pytest.raises(UsageError):
        intersect_rays(np.zeros((2, 2)), [[0, 0, 1], [0, 0, 1]], [[0, 0, -1]])
    with pytest.raises(UsageError):
        intersect_rays(np.zeros((2, 2)), [[0, 0, np.inf]], [[0, 0, -1]])


# ---------------------------------------------------------------------------------------------
# brute force comparisons
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("shape,smooth", [((7, 5), False), ((12, 16), True), ((1, 6), False)])
def test_matches_brute_force_on_random_fields(rng, shape, smooth):
    h = rng.random(shape)
    if smooth:
        h = 0.5 + 0.4 * np.sin(np.arange(shape[1]) / 2.0)[None, :] * np.cos(
            np.arange(shape[0]) / 3.0)[:, None]
    rays = _random_rays(rng, 48)
    got = intersect_rays(h, [o for o, _ in rays], [d for _, d in rays])
    for (o, d), t in zip(rays, got, strict=True):
        want = brute_force_hit(h, o, d)
        if np.isinf(want):
            assert np.isinf(t)
        else:
            assert abs(t - want) < TOL, (o, d, t, want)


def test_rays_that_miss(rng):
    h = rng.random((6, 6)) * 0.9
    assert intersect_ray(h, [0.5, 0.5, 1.5], [0.0, 0.0, 1.0]) == np.inf  # going up, above
    assert intersect_ray(h, [0.5, 0.5, 0.95], [1.0, 0.3, 0.0]) == np.inf  # above every height
    assert intersect_ray(h, [-0.5, 0.5, 0.5], [-1.0, 0.0, 0.0]) == np.inf  # away from the box
    assert intersect_ray(h, [0.5, 0.5, 0.95], [1.0, 0.0, -0.001]) == np.inf  # leaves by a side
    assert brute_force_hit(h, [0.5, 0.5, 0.95], [1.0, 0.0, -0.001]) == np.inf


def test_ray_starting_below_the_surface_hits_at_its_origin():
    h = np.full((4, 4), 0.6)
    assert intersect_ray(h, [0.3, 0.4, 0.2], [1.0, 0.0, 1.0]) == 0.0
    # entering the box from below: below the surface at entry
    t = intersect_ray(h, [0.5, 0.5, -0.5], [0.0, 0.0, 1.0])
    assert t == pytest.approx(0.5)


# ---------------------------------------------------------------------------------------------
# analytic answers
# ---------------------------------------------------------------------------------------------
def test_constant_plane_closed_form(rng):
    c = 0.37
    h = np.full((9, 5), c)
    for _ in range(20):
        o = np.array([rng.random(), rng.random(), 1.0])
        d = np.array([rng.normal() * 0.2, rng.normal() * 0.2, -rng.uniform(0.2, 1.0)])
        t = intersect_ray(h, o, d)
        uv = o[:2] + (1.0 - c) / -d[2] * d[:2]
        if np.all((uv >= 0) & (uv <= 1)):
            assert t == pytest.approx((1.0 - c) / -d[2], abs=TOL)
        else:
            assert t == np.inf


def test_tilted_plane_closed_form():
    w = 8
    x = np.arange(w) + 0.5
    h = np.tile(0.1 + 0.1 * x, (3, 1))  # h = 0.1 + 0.1 x inside [0.5, W - 0.5]
    o = np.array([0.9, 0.5, 1.0])
    d = np.array([-0.5, 0.0, -2.0])
    # h_ray(t) = 1 - 2 t ; S = 0.1 + 0.1 * 8 * (0.9 - 0.5 t) = 0.82 - 0.4 t (x = 6.75 at the hit)
    t = intersect_ray(h, o, d)
    assert t == pytest.approx((1.0 - 0.82) / 1.6, abs=TOL)
    # past the last centre the surface is clamped (constant): a shallow ray hits it there
    t = intersect_ray(h, o, [-0.5, 0.0, -0.5])
    assert t == pytest.approx(1.7, abs=TOL)  # x = 0.4, S = h(0.5) = 0.15 = 1 - 0.5 t


def test_single_bump_closed_form():
    h = np.zeros((5, 5))
    h[2, 2] = 1.0  # a tent on row y = 2.5 peaking at x = 2.5
    z = 0.3
    o = np.array([0.0, 2.5 / 5, z])
    d = np.array([1.0, 0.0, 0.0])
    t = intersect_ray(h, o, d)
    x_hit = 2.5 - (1.0 - z)  # rising flank: S = 1 - |x - 2.5|
    assert t * 5 == pytest.approx(x_hit, abs=TOL)
    cr = ray_crossings(h, o, d, 0.0, 1.0) * 5
    np.testing.assert_allclose(cr, [2.5 - (1 - z), 2.5 + (1 - z)], atol=TOL)


def test_saddle_inside_one_cell_fig3():
    """Fig. 3: both centerline points are above the surface, the patch between is not."""
    h = np.array([[1.0, 0.0], [0.0, 1.0]])
    # anti-diagonal of the only interior cell: S = 2 s (1 - s), 0 at both ends
    a = np.array([0.5, 1.5])
    b = np.array([1.5, 0.5])
    assert surface_height(h, *a) == 0.0 and surface_height(h, *b) == 0.0
    z = 0.3
    o = np.array([0.25 / 2, 1.75 / 2, z])
    d = np.array([0.5, -0.5, 0.0])  # texel x = 0.25 + t, y = 1.75 - t
    s_hit = (2.0 - np.sqrt(4.0 - 8.0 * z)) / 4.0
    assert intersect_ray(h, o, d) == pytest.approx(0.25 + s_hit, abs=TOL)
    cr = ray_crossings(h, o, d, 0.0, 2.0)
    np.testing.assert_allclose(cr, [0.25 + s_hit, 1.25 - s_hit], atol=TOL)
    assert max_penetration(h, o, d, cr[0], cr[1]) == pytest.approx(0.5 - z, abs=TOL)


def test_straight_down_is_one_minus_height(rng):
    h = rng.random((6, 7))
    for _ in range(10):
        u, v = rng.random(2)
        t = intersect_ray(h, [u, v, 1.0], [0.0, 0.0, -1.0])
        assert t == pytest.approx(1.0 - surface_height(h, u * 7, v * 6), abs=1e-12)
        assert cells_visited(h, [u, v, 1.0], [0.0, 0.0, -1.0]) == 1


def test_reaching_the_bottom_is_a_hit():
    h = np.zeros((3, 3))
    t = intersect_ray(h, [0.5, 0.5, 1.0], [0.1, 0.0, -1.0])
    assert t == pytest.approx(1.0)


# ---------------------------------------------------------------------------------------------
# crossings, penetration, walk counts
# ---------------------------------------------------------------------------------------------
def test_crossings_match_sign_changes(rng):
    h = rng.random((8, 8))
    for _ in range(20):
        o = np.array([rng.random(), rng.random(), rng.uniform(0.2, 0.9)])
        d = np.array([rng.normal(), rng.normal(), rng.normal() * 0.1])
        r = _box_range(o, d)
        if r is None:
            continue
        ts = np.linspace(r[0], r[1], 100_001)
        above = _f(h, o, d, ts) > 0.0
        changes = ts[1:][above[1:] != above[:-1]]
        cr = ray_crossings(h, o, d, r[0], r[1])
        assert np.all(np.diff(cr) >= 0.0)
        # every sampled sign change is a crossing; extra ones are thin dips between samples
        for c in changes:
            assert np.min(np.abs(cr - c)) < (r[1] - r[0]) / 1e5 + TOL
        first = intersect_ray(h, o, d)
        if cr.size and not above[0]:
            assert first == pytest.approx(r[0])
        elif cr.size:
            assert first == pytest.approx(cr[0], abs=TOL)


def test_max_penetration_matches_sampling(rng):
    h = rng.random((5, 5))
    o = np.array([0.0, 0.3, 0.5])
    d = np.array([1.0, 0.2, 0.0])
    ts = np.linspace(0.0, 1.0, 200_001)
    want = np.max(-_f(h, o, d, ts))
    assert max_penetration(h, o, d, 0.0, 1.0) == pytest.approx(want, abs=1e-6)


def test_cells_visited_counts_the_exact_walk():
    h = np.zeros((4, 8))
    # horizontal ray above everything crosses all cells between centerlines: W + 1 of them
    assert cells_visited(h, [0.0, 0.5, 0.5], [1.0, 0.0, 0.0]) == 9
    assert cells_visited(h, [0.0, 0.5, 0.5], [1.0, 0.0, 0.0], t_max=0.3) == 3
