"""The glTF fallback of octahedral impostors: one quad with the frame nearest the start view.
Checked against the frame's own orthographic camera (where the quad's corners must land, and
the frame it must reproduce texel for texel), the source mesh from the start view and views
a few degrees off it, and the impostor's own picture."""

from __future__ import annotations

import numpy as np
import pytest

from reliefkit.colorspace import srgb_decode
from reliefkit.core.transforms import transform_points
from reliefkit.io.inputs import load_mesh
from reliefkit.render import render
from reliefkit.scene.camera import Camera
from reliefkit.scene.light import DirectionalLight
from reliefkit.scene.views import DEFAULT_VIEW, orbit_bounds
from reliefkit.techniques.impostor import bake_impostor, octahedral
from reliefkit.techniques.impostor.analytic import sphere_impostor
from reliefkit.techniques.impostor.bake import frame_camera

FLAT = DirectionalLight(intensity=0.0, ambient=1.0, specular=0.0)  # colour = base colour
START_AZ, START_EL, _ = DEFAULT_VIEW


def nearest_direction(rep, towards) -> tuple[int, int, np.ndarray]:
    """(i, j, direction) of the grid frame at the smallest angle to ``towards``."""
    directions = octahedral.frame_directions(rep.grid, rep.hemi)
    angles = np.arccos(np.clip(directions @ towards, -1.0, 1.0))
    j, i = np.unravel_index(np.argmin(angles), angles.shape)
    return int(i), int(j), directions[j, i]


def start_towards(rep) -> np.ndarray:
    """From the impostor's centre towards the eye of `reliefkit render`'s default view."""
    eye = Camera.orbit(rep.center, START_AZ, START_EL, 1.0).eye
    towards = np.asarray(eye) - rep.center
    return towards / np.linalg.norm(towards)


@pytest.fixture(scope="module")
def vehicle():
    return load_mesh("demo:vehicle")


@pytest.fixture(scope="module")
def impostor(gl, vehicle):
    return bake_impostor(vehicle, grid=12, atlas_res=768)


def test_the_quad_is_the_nearest_frames_square_around_the_sphere(impostor):
    """Its corners, seen by the frame's own camera, are the frame's corners less its padding;
    it faces the start view within the grid's spacing; 2 triangles, MASK 0.5, double-sided."""
    rep = impostor
    mesh = rep.fallback_mesh()
    assert mesh.triangle_count == 2 and rep.fallback_mesh(triangles=1).triangle_count == 2
    i, j, direction = nearest_direction(rep, start_towards(rep))
    assert np.degrees(np.arccos(direction @ start_towards(rep))) < 180 / (rep.grid - 1)
    camera = frame_camera(rep.center, rep.radius, rep.frame_radius, direction, rep.frame)
    ndc = transform_points(camera.proj @ camera.view, mesh.world_positions)
    inner = 1.0 - 2.0 * rep.padding / rep.frame
    np.testing.assert_allclose(ndc[:, :2], inner * np.array([[-1, -1], [1, -1], [1, 1],
                                                              [-1, 1]]), atol=1e-5)
    np.testing.assert_allclose(mesh.normals, np.tile(direction, (4, 1)), atol=1e-6)
    np.testing.assert_array_equal(mesh.uvs, [[0, 0], [1, 0], [1, 1], [0, 1]])
    (material,) = mesh.materials
    assert (material.alpha_mode, material.alpha_cutoff, material.double_sided) == \
        ("MASK", 0.5, True)
    frame = rep.color[j * rep.frame:(j + 1) * rep.frame, i * rep.frame:(i + 1) * rep.frame]
    inside = slice(rep.padding, rep.frame - rep.padding)
    shown = frame[inside, inside, 3] > 0
    np.testing.assert_array_equal(material.texture[..., 3], frame[inside, inside, 3])
    np.testing.assert_array_equal(material.texture[shown], frame[inside, inside][shown])


def test_seen_along_its_frame_the_quad_is_the_frame_texel_for_texel(gl):
    """The frame's own orthographic camera at the frame's resolution: every pixel inside the
    padding shows its texel (a sphere's disc, painted with a gradient), covered exactly where
    the texel's coverage is."""
    rep = sphere_impostor([0.3, -0.2, 0.1], 1.0, grid=6, frame=24, padding=3,
                          bounding_radius=1.2)
    row, column = np.mgrid[:rep.color.shape[0], :rep.color.shape[1]]
    rep.color[..., 0], rep.color[..., 1] = (11 * column) % 256, (7 * row) % 256
    i, j, direction = nearest_direction(rep, start_towards(rep))
    camera = frame_camera(rep.center, rep.radius, rep.frame_radius, direction, rep.frame)
    got = render(rep.fallback_mesh(), camera, light=FLAT)
    frame = rep.color[j * rep.frame:(j + 1) * rep.frame, i * rep.frame:(i + 1) * rep.frame]
    texels = frame[::-1]  # frames have row 0 at the top, textures at v = 0
    inside = slice(rep.padding, rep.frame - rep.padding)
    expected = np.zeros(texels.shape[:2], bool)
    expected[inside, inside] = texels[inside, inside, 3] >= 128
    np.testing.assert_array_equal(got.mask, expected)
    np.testing.assert_allclose(got.color[got.mask, :3],
                               srgb_decode(texels[got.mask, :3] / 255.0), atol=2e-3)


def test_a_viewers_mip_levels_keep_the_frames_colour():
    """A disc of one colour on black texels: the texture the fallback exports is dilated, so
    every level a viewer box-filters from it keeps the disc's colour (no dark fringe)."""
    rep = sphere_impostor([0.0, 0.0, 0.0], 1.0, grid=4, frame=40, padding=4,
                          rgb=(0.7, 0.2, 0.5))
    rep.color[rep.color[..., 3] == 0, :3] = 0
    texture = rep.fallback_mesh().materials[0].texture.astype(np.float64)
    disc = rep.color[rep.color[..., 3] > 0][0, :3]
    for level in range(1, 6):
        size = 2 ** level
        blocks = texture[..., :3].reshape(32 // size, size, 32 // size, size, 3)
        np.testing.assert_array_equal(blocks.mean(axis=(1, 3)).reshape(-1, 3),
                                      np.broadcast_to(disc, ((32 // size) ** 2, 3)))


def views_near_the_start(size: int, bounds) -> list[tuple[str, Camera]]:
    """The start view as `reliefkit render` draws it and four 3 degrees off; the same five
    directions seen orthographically (from far away)."""
    out = []
    for d_az, d_el in ((0, 0), (3, 0), (-3, 0), (0, 3), (0, -3)):
        az, el = START_AZ + d_az, START_EL + d_el
        out.append((f"{az:g},{el:g}", orbit_bounds(bounds, az, el, None, (size, size))))
        far = orbit_bounds(bounds, az, el, 3.0, (size, size))
        radius = 0.5 * np.linalg.norm(bounds[1] - bounds[0])
        out.append((f"{az:g},{el:g} orthographic", Camera(
            eye=far.eye, target=far.target, size=(size, size), ortho_height=1.05 * radius,
            near=far.near, far=far.far)))
    return out


def test_the_quad_looks_like_the_mesh_and_the_impostor_near_the_start_view(impostor, vehicle):
    """Mask IoU against the vehicle >= 0.9 seen orthographically from the start view's
    direction and 3 degrees off, where one frame's picture can stand for the object; >= 0.85
    from the start view itself (the object 3.1 radii away: its near parts look larger than
    an orthographic frame draws them, which the impostor undoes pixel by pixel); its colour
    the impostor's own under a flat light."""
    mesh = impostor.fallback_mesh()
    for label, camera in views_near_the_start(128, vehicle.bounds):
        truth, drawn, itself = (render(x, camera, light=FLAT) for x in (vehicle, mesh,
                                                                          impostor))
        floor = 0.9 if camera.orthographic else 0.85
        assert iou(drawn.mask, truth.mask) >= floor, label
        both = drawn.mask & itself.mask
        gap = drawn.color[both, :3].mean(axis=0) - itself.color[both, :3].mean(axis=0)
        assert np.abs(gap).max() < 0.02, label


def iou(a: np.ndarray, b: np.ndarray) -> float:
    return float((a & b).sum() / (a | b).sum())
