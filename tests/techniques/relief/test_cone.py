"""Relaxed cone maps against a fine, independent march of the rays they are defined by, and
cone stepping against the exact reference."""

import numpy as np
import pytest
from helpers import make_relief
from scipy.ndimage import gaussian_filter

from reliefkit.reference.heightfield import surface_height
from reliefkit.render import render
from reliefkit.scene.camera import Camera
from reliefkit.techniques.relief.cone import relaxed_cone_ratios
from reliefkit.techniques.relief.reference import wrong_hits


def field(n=24, sigma=1.5, seed=2):
    h = gaussian_filter(np.random.default_rng(seed).random((n, n)), sigma)
    return ((h - h.min()) / (h.max() - h.min()) * 0.8 + 0.1).astype(np.float32)


def exit_after(h, a, b, step=0.02):
    """Where the ray from the top above texel a through b's surface point leaves the solid
    after b (None: it sinks below a's height or leaves the field first)."""
    ha, hb = h[a[1], a[0]], h[b[1], b[0]]
    pa, pb = np.array(a) + 0.5, np.array(b) + 0.5
    r = np.linalg.norm(pb - pa)
    u = (pb - pa) / r
    slope = (1.0 - hb) / r
    for s in np.arange(step, 4 * max(h.shape), step):
        z = hb - slope * s
        p = pb + u * s
        if z <= ha or (p < 0).any() or p[0] > h.shape[1] or p[1] > h.shape[0]:
            return None
        if z > surface_height(h, np.array([p[0]]), np.array([p[1]]))[0]:
            return p, z
    return None


def test_no_exit_point_lies_inside_a_relaxed_cone():
    h = field()
    cones = relaxed_cone_ratios(h)
    rng = np.random.default_rng(0)
    checked = 0
    for _ in range(400):
        a = tuple(rng.integers(0, 24, 2))
        b = tuple(rng.integers(0, 24, 2))
        if a == b or h[b[1], b[0]] <= h[a[1], a[0]]:
            continue
        found = exit_after(h, a, b)
        if found is None:
            continue
        p, z = found
        checked += 1
        ha = h[a[1], a[0]]
        reach = cones[a[1], a[0]] * (z - ha)  # the cone's radius at the exit's height
        # the exit lies outside the cone, up to the search's half-texel march steps
        assert np.linalg.norm(p - (np.array(a) + 0.5)) >= reach - 1.0, (a, b)
    assert checked > 40


def test_a_flat_field_has_the_widest_cones_and_a_spike_narrows_its_neighbours():
    flat = np.full((16, 16), 0.3, np.float32)
    assert np.allclose(relaxed_cone_ratios(flat), 16)
    spike = flat.copy()
    spike[8, 8] = 0.9
    cones = relaxed_cone_ratios(spike)
    assert cones[8, 7] < cones[2, 2] and cones[8, 9] < 16


def test_cone_stepping_renders_close_to_the_reference_in_fewer_iterations(gl):
    from reliefkit.scene.assets import terrain_heights

    h = terrain_heights(128).astype(np.float32)
    h = (h - h.min()) / (h.max() - h.min()) * 0.9 + 0.05
    relief = make_relief(h)
    camera = Camera.orbit((0, 0.5, 0), 30, 45, 3.0, size=(64, 64))
    cone = render(relief, camera, method="cone", count_iterations=True)
    exact = render(relief, camera, method="exact", count_iterations=True)
    assert wrong_hits(cone, relief, camera)["wrong_fraction"] <= 0.05
    assert cone.stats["iterations_mean"] < 0.5 * exact.stats["iterations_mean"]


@pytest.mark.parametrize("steps", [4, 64])
def test_more_cone_steps_are_never_worse(gl, steps):
    relief = make_relief(field(32))
    camera = Camera.orbit((0, 0.5, 0), 120, 25, 3.0, size=(64, 64))
    few = wrong_hits(render(relief, camera, method="cone", cone_steps=steps), relief, camera)
    many = wrong_hits(render(relief, camera, method="cone", cone_steps=4 * steps), relief,
                      camera)
    assert many["wrong_fraction"] <= few["wrong_fraction"] + 1e-9
