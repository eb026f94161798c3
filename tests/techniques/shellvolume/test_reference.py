"""The CPU reference renderer of shell volumes against independent analytic expectations:
uniform media, two stacked media, the 0.5 opacity point, sampling error bounds, texture
wrapping, and ray/tetrahedron crossings against a brute-force numpy count."""

from __future__ import annotations

import numpy as np
import pytest
from shell_scenes import (
    HALF,
    grid_mesh,
    inside_grid,
    slab_camera,
    sphere_mesh,
    texture_from,
    uniform_texture,
)

from reliefkit.errors import UsageError
from reliefkit.scene.camera import Camera, pixel_segments
from reliefkit.techniques.shellvolume import textures
from reliefkit.techniques.shellvolume.filtering import mip_pyramid
from reliefkit.techniques.shellvolume.reference import (
    MIN_LENGTH,
    ReferenceImage,
    reference_render,
)
from reliefkit.techniques.shellvolume.shell import build_shell


def brute_crossings(shell, camera):
    """(H, W) tetrahedra each pixel ray crosses with positive length, by plain numpy; a ray
    lying in a face plane is inside when the normal's first clearly nonzero component is
    positive (the module docstring's tie-break)."""
    near, far = pixel_segments(camera)
    seg = (far - near).reshape(-1, 3)
    t_far = np.linalg.norm(seg, axis=1)
    d = seg / t_far[:, None]
    o = near.reshape(-1, 3)
    n, off = shell.planes[..., :3], shell.planes[..., 3]
    size = np.linalg.norm(shell.positions.max(axis=0) - shell.positions.min(axis=0))
    eps = MIN_LENGTH * size
    num = np.einsum("tfi,ri->rtf", n, o) + off
    den = np.einsum("tfi,ri->rtf", n, d)
    parallel = np.abs(den) <= 1e-12
    safe = np.where(parallel, 1.0, den)
    t = -num / safe
    enter = np.maximum(np.where(~parallel & (den < 0), t, -np.inf).max(axis=2), 0.0)
    leave = np.minimum(np.where(~parallel & (den > 0), t, np.inf).min(axis=2), t_far[:, None])
    big = np.abs(n) > 1e-6
    first = np.take_along_axis(n, np.argmax(big, axis=2)[..., None], axis=2)[..., 0]
    keeps = first > 0
    out = parallel & ((num > eps) | ((num >= -eps) & ~keeps))
    crossed = (leave - enter > eps) & ~out.any(axis=2)
    return crossed.sum(axis=1).reshape(camera.size[1], camera.size[0])


@pytest.mark.parametrize("theta, ortho", [(0.0, True), (40.0, True), (35.0, False)])
def test_uniform_medium(theta, ortho):
    a0, thickness = 0.6, 0.5
    shell = build_shell(grid_mesh(), thickness)
    camera = slab_camera(theta, ortho=ortho)
    img = reference_render(shell, uniform_texture(a0), camera)
    assert isinstance(img, ReferenceImage)
    assert img.color.shape == (32, 32, 4) and img.color.dtype == np.float32
    assert img.position.shape == (32, 32, 3) and img.crossings.dtype == np.int32
    inside, _, d = inside_grid(camera, thickness)
    assert inside.sum() > 300
    expected = 1 - (1 - a0) ** (thickness / np.abs(d[..., 2]))
    np.testing.assert_allclose(img.alpha[inside], expected[inside], atol=1e-4)
    medium = np.tile([0.2, 0.5, 0.7], (inside.sum(), 1))
    np.testing.assert_allclose(img.color[inside][:, :3], medium, atol=1e-5)
    assert (img.crossings[inside] >= 2).all()


def _quadrature(w_of_s, thickness, alpha_layers, rgb_layers, cells=200_000):
    """Exact (to O(1/cells^2)) front-to-back transfer along a vertical ray through a slab
    whose w profile is w_of_s(s), s = depth along the ray; texture layers along w with GL
    CLAMP_TO_EDGE linear filtering (np.interp clamps exactly so) of the optical density
    -ln(1 - alpha) and of the colour weighted by density + floor, as the transfer defines."""
    depth = len(alpha_layers)
    centres = (np.arange(depth) + 0.5) / depth
    ds = thickness / cells
    s = (np.arange(cells) + 0.5) * ds
    w = w_of_s(s)
    layer_density = -np.log1p(-np.asarray(alpha_layers, np.float64))
    density = np.interp(w, centres, layer_density)
    floor = 1e-3 / thickness
    weighted = rgb_layers * (layer_density + floor)[:, None]
    rgb = np.stack([np.interp(w, centres, weighted[:, k]) for k in range(3)], axis=1)
    rgb = rgb / (density + floor)[:, None]
    a = 1 - np.exp(-density * ds)
    trans = np.concatenate([[1.0], np.cumprod(1 - a)[:-1]])
    premult = (trans * a) @ rgb
    total = 1 - np.prod(1 - a)
    return premult / total, total


@pytest.mark.parametrize("below", [False, True])
def test_two_stacked_media(below):
    """Lower half of w red (alpha a1), upper half green (a2): green over red from above, red
    over green from below, as the exact transfer of the filtered profile and within the
    thin filter blend (1/64 of the thickness, 5e-3) of the ideal two-layer formula."""
    a1, a2, thickness, depth = 0.7, 0.4, 0.5, 64
    alpha_layers = np.where(np.arange(depth) < depth // 2, a1, a2)
    red, green = np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])
    rgb_layers = np.where((np.arange(depth) < depth // 2)[:, None], red, green)
    alpha = np.broadcast_to(alpha_layers[:, None, None], (depth, 2, 2))
    rgb = np.broadcast_to(rgb_layers[:, None, None, :], (depth, 2, 2, 3))
    shell = build_shell(grid_mesh(), thickness)
    camera = slab_camera(0.0, below=below)
    # fine steps: the blend zone (4 default steps wide) would leave a 1e-4 midpoint error
    img = reference_render(shell, texture_from(rgb, alpha), camera, step=thickness / 2048)
    inside, _, _ = inside_grid(camera, thickness)
    assert inside.sum() > 300

    def w_of_s(s):
        return s / thickness if below else 1 - s / thickness

    colour, total = _quadrature(w_of_s, thickness, alpha_layers, rgb_layers)
    np.testing.assert_allclose(img.alpha[inside], total, atol=1e-4)
    np.testing.assert_allclose(img.color[inside][:, :3], np.tile(colour, (inside.sum(), 1)),
                               atol=1e-4)
    # the ideal two-layer formula: front layer over back layer
    layer_r, layer_g = 1 - (1 - a1) ** (thickness / 2), 1 - (1 - a2) ** (thickness / 2)
    (front, fc), (back, bc) = ((layer_r, red), (layer_g, green)) if below else \
        ((layer_g, green), (layer_r, red))
    ideal_a = front + (1 - front) * back
    ideal_c = (front * fc + (1 - front) * back * bc) / ideal_a
    np.testing.assert_allclose(img.alpha[inside], ideal_a, atol=5e-3)
    np.testing.assert_allclose(img.color[inside][:, :3], np.tile(ideal_c, (inside.sum(), 1)),
                               atol=5e-3)
    # the order matters: the other layer in front would give a clearly different colour
    swapped_c = (back * bc + (1 - back) * front * fc) / ideal_a
    assert np.abs(img.color[inside][:, :3] - swapped_c).max(axis=1).min() > 0.05


@pytest.mark.parametrize("theta", [0.0, 30.0])
def test_half_opacity_position(theta):
    a0, thickness = 0.95, 0.5
    step = thickness / 1000
    shell = build_shell(grid_mesh(), thickness)
    camera = slab_camera(theta)
    img = reference_render(shell, uniform_texture(a0), camera, step=step)
    inside, o, d = inside_grid(camera, thickness)
    s_half = np.log(0.5) / np.log(1 - a0)  # path length at which the opacity is 0.5
    assert s_half < thickness
    t_top = (thickness - o[..., 2]) / d[..., 2]
    expected = o + (t_top + s_half)[..., None] * d
    err = np.linalg.norm(img.position - expected, axis=-1)
    assert np.isfinite(img.position[inside]).all()
    assert err[inside].max() <= step / 2 + 1e-9


@pytest.mark.parametrize("theta", [0.0, 30.0])
def test_fixed_samples_within_midpoint_bound(theta):
    """samples=N against dense sampling on alpha linear in w (0.2 -> 0.8 between the layer
    centres w = 1/4, 3/4): the optical depth's midpoint error is at most
    sum L^3 max|f''| / (24 N^2) + sum_kinks |jump f'| (L/N)^2 / 8, f = -ln(1 - alpha(s))."""
    lo, hi, thickness, n = 0.2, 0.8, 0.5, 8
    alpha = np.broadcast_to(np.array([lo, hi])[:, None, None], (2, 2, 2))
    texture = texture_from((0.3, 0.6, 0.9), alpha)
    shell = build_shell(grid_mesh(), thickness)
    camera = slab_camera(theta)
    fixed = reference_render(shell, texture, camera, samples=n)
    dense = reference_render(shell, texture, camera, step=thickness / 2000)
    inside, _, d = inside_grid(camera, thickness)
    cos = np.abs(d[..., 2])[inside]
    slope = (hi - lo) / 0.5 * cos / thickness  # d alpha / ds inside the linear part
    f2 = slope**2 / (1 - hi) ** 2
    kinks = slope / (1 - lo) + slope / (1 - hi)
    corners = shell.tetrahedra()
    diam = max(np.linalg.norm(corners[:, i] - corners[:, j], axis=1).max()
               for i in range(4) for j in range(i))
    path = thickness / cos

    def bound(h):
        return h**2 * (path * f2 / 24 + kinks / 8)

    err = np.abs(fixed.alpha[inside] - dense.alpha[inside])
    assert (err <= bound(diam / n) + bound(thickness / 2000) + 1e-6).all()
    assert err.max() > 0  # the two modes do sample differently
    np.testing.assert_allclose(fixed.color[inside][:, :3], np.tile([0.3, 0.6, 0.9],
                               (inside.sum(), 1)), atol=1e-5)
    # and N = 1 is visibly worse than N = 8
    coarse = reference_render(shell, texture, camera, samples=1)
    assert np.abs(coarse.alpha[inside] - dense.alpha[inside]).mean() > err.mean()


def test_halving_step_on_clouds():
    shell = build_shell(grid_mesh(), 0.3)
    camera = slab_camera(30.0, size=(48, 48), ortho=False)
    tex = textures.make_clouds()
    base = reference_render(shell, tex, camera)
    half = reference_render(shell, tex, camera, step=0.3 / 512)
    inside, _, _ = inside_grid(camera, 0.3)
    assert inside.sum() > 500
    assert np.abs(base.alpha - half.alpha).max() <= 0.005
    assert base.alpha[inside].min() > 0.99  # clouds' base layer is opaque


def test_repeat_wrapping_and_tile():
    """Colour varying only in u (red) and v (green), alpha constant: a vertical ray keeps
    (u, v), so its colour is the GL-filtered texel row at (u U, v V), wrapped."""
    reds, greens = np.array([0.0, 1.0, 0.5, 0.25]), np.array([0.9, 0.1, 0.6])
    depth = 2
    rgb = np.zeros((depth, 3, 4, 3))
    rgb[..., 0] = reds[None, None, :]
    rgb[..., 1] = greens[None, :, None]
    tile = (2, 3)
    thickness = 0.2
    texture = texture_from(rgb, np.full((depth, 3, 4), 0.5), tile=tile)
    shell = build_shell(grid_mesh(uv=(0.1, 0.9)), thickness)
    camera = slab_camera(0.0, size=(40, 40))
    img = reference_render(shell, texture, camera)
    inside, o, d = inside_grid(camera, thickness)
    x, y = o[..., 0], o[..., 1]
    u = 0.1 + 0.8 * (x + HALF) / (2 * HALF)
    v = 0.1 + 0.8 * (y + HALF) / (2 * HALF)

    def repeat(s, values):
        n = len(values)
        pos = (s - np.floor(s)) * n - 0.5
        return np.interp(pos, np.arange(-1, n + 1), np.concatenate([values[-1:], values,
                                                                     values[:1]]))

    np.testing.assert_allclose(img.color[..., 0][inside], repeat(u * tile[0], reds)[inside],
                               atol=1e-5)
    np.testing.assert_allclose(img.color[..., 1][inside], repeat(v * tile[1], greens)[inside],
                               atol=1e-5)


@pytest.fixture(scope="module")
def sphere_shell():
    return build_shell(sphere_mesh(), 0.15)


def test_crossings_through_sphere_centre(sphere_shell):
    tex = uniform_texture(0.3)
    full_cam = Camera(eye=(0.0, 0.0, 4.0), target=(0.0, 0.0, 0.0), size=(33, 33), near=0.5,
                      far=10.0, fov_deg=40.0)
    back_cam = Camera(eye=(0.0, 0.0, 4.0), target=(0.0, 0.0, 0.0), size=(33, 33), near=4.0,
                      far=10.0, fov_deg=40.0)  # the near plane through the centre
    full = reference_render(sphere_shell, tex, full_cam, samples=4)
    back = reference_render(sphere_shell, tex, back_cam, samples=4)
    o, _ = back_cam.pixel_rays()
    np.testing.assert_allclose(o[16, 16], 0.0, atol=1e-9)
    far_side = back.crossings[16, 16]
    near_side = full.crossings[16, 16] - far_side
    assert far_side > 0 and near_side > 0
    np.testing.assert_array_equal(full.crossings, brute_crossings(sphere_shell, full_cam))
    np.testing.assert_array_equal(back.crossings, brute_crossings(sphere_shell, back_cam))
    # the uniform medium's opacity through both sides: 2 x 0.15 x (inradius .. 1)
    assert 1 - 0.7 ** (0.3 * 0.9) < full.alpha[16, 16] <= 1 - 0.7 ** 0.3 + 1e-6


def test_crossings_with_eye_inside_shell(sphere_shell):
    """Tetrahedra around and behind the eye go to every tile: still the brute-force count."""
    camera = Camera(eye=(0.0, 0.0, 1.07), target=(1.0, 0.3, 1.07), size=(32, 32), near=0.01,
                    far=10.0, fov_deg=70.0)
    img = reference_render(sphere_shell, uniform_texture(0.3), camera, samples=2)
    expected = brute_crossings(sphere_shell, camera)
    assert expected.max() > 0
    np.testing.assert_array_equal(img.crossings, expected)


def test_rays_missing_the_shell():
    shell = build_shell(grid_mesh(), 0.3)
    away = Camera(eye=(0.0, 0.0, 3.0), target=(0.0, 0.0, 6.0), size=(32, 32), near=0.5,
                  far=10.0)
    img = reference_render(shell, uniform_texture(0.9), away)
    assert (img.alpha == 0).all() and (img.color == 0).all()
    assert np.isnan(img.position).all() and (img.crossings == 0).all()
    # a wide orthographic view: pixels beyond the grid get nothing, those on it something
    wide = Camera(eye=(0.0, 0.0, 3.0), target=(0.0, 0.0, 0.0), size=(32, 32), near=0.5,
                  far=10.0, ortho_height=2.0)
    img = reference_render(shell, uniform_texture(0.99), wide)
    o, _ = wide.pixel_rays()
    off = (np.abs(o[..., :2]) > HALF + 1e-3).any(axis=-1)
    on = (np.abs(o[..., :2]) < HALF - 1e-3).all(axis=-1)
    assert off.any() and on.any()
    assert (img.alpha[off] == 0).all() and np.isnan(img.position[off]).all()
    assert (img.crossings[off] == 0).all()
    assert (img.alpha[on] > 0).all() and np.isfinite(img.position[on]).all()


def test_level_and_rgba_override():
    shell = build_shell(grid_mesh(n=4), 0.3)
    camera = slab_camera(20.0, size=(24, 24))
    tex = textures.make_clouds(size=(16, 16, 8))
    mip = mip_pyramid(tex, 2, 0.3)[1]
    by_level = reference_render(shell, tex, camera, samples=6, level=1)
    by_rgba = reference_render(shell, tex, camera, samples=6, rgba=mip)
    np.testing.assert_array_equal(by_level.color, by_rgba.color)
    level0 = reference_render(shell, tex, camera, samples=6, level=0)
    plain = reference_render(shell, tex, camera, samples=6)
    np.testing.assert_array_equal(level0.color, plain.color)
    assert not np.array_equal(plain.color, by_level.color)


@pytest.mark.parametrize("kwargs", [dict(step=0.01, samples=4), dict(samples=0),
                                    dict(samples=2.5), dict(step=-1.0), dict(step=np.nan),
                                    dict(level=0, rgba=np.zeros((2, 2, 2, 4))),
                                    dict(level=-1), dict(rgba=np.zeros((2, 2, 4)))])
def test_bad_arguments(kwargs):
    shell = build_shell(grid_mesh(n=2), 0.3)
    with pytest.raises(UsageError):
        reference_render(shell, uniform_texture(0.5), slab_camera(size=(8, 8)), **kwargs)


def test_speed(sphere_shell):
    """About 10k tetrahedra at 128 x 128 (after compilation: the first call warms up)."""
    shell = build_shell(sphere_mesh(4), 0.1)
    camera = Camera.orbit((0.0, 0.0, 0.0), 30.0, 20.0, 4.0, size=(128, 128))
    tex = textures.make_clouds()
    reference_render(sphere_shell, tex, camera, samples=2)
    img = reference_render(shell, tex, camera, samples=10)
    assert len(shell.tets) > 10_000
    assert img.seconds < 2.0
