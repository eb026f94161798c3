"""Drawing impostors against exact references: a sphere (every frame the same disc) against
the ray-sphere intersection, and frames of one colour each against the CPU's choice of
frames and weights."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.ndimage import binary_dilation

from reliefkit.colorspace import srgb_decode
from reliefkit.render import render
from reliefkit.scene.camera import Camera
from reliefkit.scene.light import DirectionalLight
from reliefkit.scene.mesh import RenderMesh
from reliefkit.techniques.impostor import bake_impostor, octahedral
from reliefkit.techniques.impostor.analytic import sphere_impostor

CENTER = np.array([0.3, -0.2, 0.1])
FLAT = DirectionalLight(intensity=0.0, ambient=1.0, specular=0.0)  # colour = base colour


def _sphere_hits(camera, radius: float):
    """Exact first hits of each pixel's ray with the sphere: (mask, points, normals)."""
    origin, direction = camera.pixel_rays()
    rel = origin - CENTER
    b = np.einsum("hwc,hwc->hw", rel, direction)
    c = np.einsum("hwc,hwc->hw", rel, rel) - radius ** 2
    disc = b * b - c
    hit = disc >= 0
    t = -b - np.sqrt(np.where(hit, disc, 0.0))
    points = origin + t[..., None] * direction
    return hit, points, (points - CENTER) / radius


def _view_directions():
    """Views exactly on frames of the 6 x 6 full grid and between three (their centroid on
    the map), from above, the side and below; orthographic and far perspective."""
    for i, j, between in ((2, 3, False), (0, 2, False), (5, 5, False), (4, 1, False),
                          (2, 3, True), (0, 2, True), (4, 4, True), (3, 0, True)):
        point = octahedral.frame_point(i + between / 3, j + between / 3, 6)
        for ortho in (True, False):
            yield octahedral.decode(point, False), between, ortho


@pytest.mark.parametrize("direction,between,ortho", list(_view_directions()))
def test_a_sphere_is_exact_up_to_texel_quantization(gl, direction, between, ortho):
    """On a frame, the outline is right to a texel; between frames, each frame misses the
    outline's ring it cannot see (the rays that meet the sphere only where it faces away
    from the frame: closer than R cos(angle to the frame) to the centre, they do not); the
    surface point is right to the depth's quantization, the normal to a few degrees."""
    radius, frame = 1.0, 64
    rep = sphere_impostor(CENTER, radius, grid=6, frame=frame)
    distance = 3.0 if ortho else 30.0  # far: the frames' parallel rays stand for the pixel's
    camera = Camera(eye=tuple(CENTER + distance * direction), target=tuple(CENTER),
                    fov_deg=2 * np.degrees(np.arcsin(1.15 * radius / distance)),
                    size=(128, 128), ortho_height=1.15 * radius if ortho else None,
                    near=distance - 1.5, far=distance + 1.5)
    got = render(rep, camera)
    hit, points, normals = _sphere_hits(camera, radius)
    texel = 2 * rep.frame_radius / frame
    frames, weights = octahedral.blend_frames(direction, 6, False)
    assert (weights.max() == pytest.approx(1.0)) != between
    seen = octahedral.frame_directions(6, False)[frames[:, 1], frames[:, 0]][weights > 1e-9]
    inner = radius * np.min(seen @ direction) - 1.5 * texel
    origin, ray = camera.pixel_rays()
    rel = origin - CENTER
    closest = np.linalg.norm(rel - np.einsum("hwc,hwc->hw", rel, ray)[..., None] * ray,
                             axis=-1)
    wrong = got.mask != hit
    assert (closest[wrong] > inner).all() and (closest[wrong] < radius + 1.5 * texel).all()
    sure = got.mask & hit & (closest < inner - texel)
    gap = np.linalg.norm(got.position[sure] - points[sure], axis=-1)
    assert np.median(gap) < 2 * radius / 255  # a step of the uint8 depth
    # on a frame a texel at most; between, a walk of 8 steps misses the crossing on a few
    assert np.percentile(gap, 99 if between else 100) < 1.5 * texel
    cosine = np.einsum("nc,nc->n", got.normal[sure], normals[sure])
    assert np.degrees(np.arccos(np.clip(cosine, -1, 1))).mean() < 2.0


def test_parallax_puts_the_surface_where_the_frames_agree(gl):
    """Between frames of a sphere whose bounding sphere is twice its size, the lookup
    where each ray crosses each frame's plane is off the sphere's surface; parallax steps
    move it there (the position error drops)."""
    rep = sphere_impostor(CENTER, 0.5, grid=4, frame=64, bounding_radius=1.0)
    camera = Camera.orbit(CENTER, 37.0, 21.0, 3.0, size=(96, 96), ortho_height=0.6)
    hit, points, _ = _sphere_hits(camera, 0.5)
    errors = []
    for steps in (0, 4):
        got = render(rep, camera, parallax_steps=steps)
        both = got.mask & hit
        errors.append(np.linalg.norm(got.position[both] - points[both], axis=-1).mean())
    assert errors[1] < 0.5 * errors[0]


@pytest.mark.parametrize("hemi", [False, True])
def test_frames_and_weights_on_the_gpu_are_the_cpus(gl, rng, hemi):
    """Each frame a disc of its own colour: the drawn colour is the frames' colours blended
    by `octahedral.blend_frames`' weights."""
    grid, frame = 5, 16
    rep = sphere_impostor(CENTER, 1.0, grid=grid, frame=frame, hemi=hemi)
    codes = rng.integers(0, 256, size=(grid, grid, 3)).astype(np.uint8)
    cells = np.repeat(np.repeat(codes, frame, axis=0), frame, axis=1)
    rep.color[..., :3] = cells
    for _ in range(12):
        d = rng.normal(size=3)
        d /= np.linalg.norm(d)
        if hemi:
            d[1] = abs(d[1])
        camera = Camera(eye=tuple(CENTER + 3 * d), target=tuple(CENTER), size=(8, 8),
                        ortho_height=0.05)  # the disc's middle: every frame covers it
        got = render(rep, camera, light=FLAT)
        frames, weights = octahedral.blend_frames(d, grid, hemi)
        linear = srgb_decode(codes[frames[:, 1], frames[:, 0]] / 255.0)
        expected = weights @ linear
        np.testing.assert_allclose(got.color[4, 4, :3], expected, atol=3e-3)


def _two_plates() -> RenderMesh:
    """A small square plate 1 above a large one, both facing up."""
    positions, faces = [], []
    for half, y in ((1.0, 0.0), (0.35, 1.0)):
        base = len(positions)
        positions += [(-half, y, -half), (half, y, -half), (half, y, half), (-half, y, half)]
        faces += [(base, base + 2, base + 1), (base, base + 3, base + 2)]
    n = len(positions)
    return RenderMesh(np.array(positions), np.array(faces), np.tile([0, 1.0, 0], (n, 1)),
                      np.tile([0.8, 0.8, 0.8, 1.0], (n, 1)))


def test_shadows_fall_where_the_plate_hides_the_light(gl):
    """The upper plate shadows the lower one: the impostor shadows (nearly) every pixel the
    plate hides from the light, and nothing farther from that square than a frame between
    the light and its frames can thicken it: each frame is a height field, so a ray that
    passes beside the plate but behind it in a frame hits it there, up to the plates' gap
    times tan(angle to the frame) (docs/impostor.md, limits)."""
    mesh = _two_plates()
    rep = bake_impostor(mesh, grid=8, hemi=True, atlas_res=512)
    light = DirectionalLight.from_angles(20.0, 50.0)
    camera = Camera.orbit(mesh.center, 200.0, 60.0, 6.0, size=(128, 128), ortho_height=1.4)
    dark = render(rep, camera, light=light, shadows=True)
    bright = render(rep, camera, light=light)
    p = render(mesh, camera, light=light).position
    upper = (np.nan_to_num(p[..., 1]) > 0.5) | (np.nan_to_num(bright.position[..., 1]) > 0.5)
    # the lower plate, where both see it, away from the upper plate's outline (there the
    # frames disagree on which plate a pixel shows)
    lower = dark.mask & bright.mask & np.isfinite(p[..., 1]) \
        & ~binary_dilation(upper, iterations=3)
    shadowed = lower & (dark.color[..., 0] < 0.7 * bright.color[..., 0])
    toward = np.asarray(light.unit_direction)
    on_plate = p + (1.0 - p[..., 1:2]) / toward[1] * toward  # along the light to y = 1
    reach = np.nan_to_num(np.abs(on_plate[..., [0, 2]]), nan=9.0).max(axis=-1)
    hidden = lower & (reach < 0.35)
    frames, weights = octahedral.blend_frames(toward, 8, True)
    seen = octahedral.frame_directions(8, True)[frames[:, 1], frames[:, 0]][weights > 0]
    slack = np.tan(np.arccos(np.min(seen @ toward))) * 1.0 + 2 * rep.frame_radius / rep.frame
    assert hidden.sum() > 300
    assert (shadowed & hidden).sum() > 0.9 * hidden.sum()
    assert (reach[shadowed] < 0.35 + slack).all()


def test_far_from_the_origin_it_draws_as_at_the_origin(gl):
    """Georeferenced coordinates: the quad lives relative to the sphere's centre (the plan's
    origin), so 1e7 units away the same view gives the same picture."""
    offset = np.array([1e7, -3e6, 2e7])
    near = sphere_impostor(CENTER, 1.0, grid=6, frame=32)
    far = sphere_impostor(CENTER + offset, 1.0, grid=6, frame=32)
    frames = [render(rep, Camera.orbit(rep.center, 37.0, 21.0, 3.0, size=(64, 64)))
              for rep in (near, far)]
    np.testing.assert_array_equal(frames[0].mask, frames[1].mask)
    np.testing.assert_allclose(frames[0].color, frames[1].color, atol=1e-3)
    m = frames[0].mask
    np.testing.assert_allclose(frames[1].position[m] - offset, frames[0].position[m], atol=1e-4)
