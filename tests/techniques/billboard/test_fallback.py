"""The glTF fallback of billboard clouds and DMBBCs: plain textured quads. Checked against
the rectangles' own parametrization (corners, the texels the representation's docstring
names), hand-computed tangent-space normals, box-filtered mip levels as a viewer builds
them, and the source mesh rendered from three views."""

from __future__ import annotations

import numpy as np
import pytest

from reliefkit.colorspace import srgb_decode
from reliefkit.errors import UsageError
from reliefkit.io.gltf.mesh import vertex_tangents
from reliefkit.io.inputs import load_mesh
from reliefkit.render import render
from reliefkit.scene.camera import Camera
from reliefkit.scene.light import DirectionalLight
from reliefkit.scene.views import orbit_bounds
from reliefkit.techniques.billboard import TECHNIQUE, bake_billboard_cloud, bake_boxes
from reliefkit.techniques.billboard.fallback import fallback_normal_texture
from reliefkit.techniques.billboard.representation import BillboardCloud


def fallback_tangents(rep):
    """The TANGENTs the glTF writer gives the fallback's vertices."""
    mesh = rep.fallback_mesh()
    return vertex_tangents(mesh.positions, mesh.normals, mesh.uvs, mesh.indices)


FLAT = DirectionalLight(intensity=0.0, ambient=1.0, specular=0.0)  # colour = base colour
VIEWS = ((30.0, 20.0), (150.0, -10.0), (270.0, 60.0))
ST = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float64)


def encode(n) -> np.ndarray:
    n = np.asarray(n, np.float64)
    return np.round((n / np.linalg.norm(n, axis=-1, keepdims=True) + 1.0) * 127.5)


def two_page_cloud() -> BillboardCloud:
    """Two tilted rectangles of unequal sides, one per atlas page, away from the origin."""
    color = np.zeros((2, 32, 32, 4), np.uint8)
    color[0, 3:13, 4:24] = (200, 60, 30, 255)
    color[1, 5:29, 2:10] = (30, 90, 210, 255)
    normal = np.full((2, 32, 32, 3), 128, np.uint8)
    u = np.array([[2.0, 0.0, -0.6], [0.0, 0.0, -1.0]])
    v = np.stack([np.cross(np.cross(u[0], [0.1, 1.0, 0.5]), u[0]), [0.0, 3.0, 0.0]])
    v[0] *= 1.5 / np.linalg.norm(v[0])
    return BillboardCloud(corners=[[10.0, 4.0, -3.0], [11.0, 3.0, -2.0]], u_axes=u, v_axes=v,
                          rects=[[0, 4, 3, 20, 10], [1, 2, 5, 8, 24]], color=color,
                          normal=normal, epsilon=0.01)


def test_the_quads_are_the_rectangles_with_the_texels_they_hold():
    """Corners at corner + s u + t v; uv (s, t) at the rectangle's texel edges, (x + s w) / W,
    (y + t h) / H, since texel (x + i, y + j) holds s = (i + 0.5) / w, t = (j + 0.5) / h;
    one MASK, double-sided material per page at the renderer's 0.5."""
    cloud = two_page_cloud()
    mesh = cloud.fallback_mesh()
    assert mesh.triangle_count == 2 * cloud.count
    assert cloud.fallback_mesh(triangles=1).triangle_count == 2 * cloud.count  # fixed count
    for p in range(cloud.count):
        page, x, y, w, h = cloud.rects[p]
        rows = np.flatnonzero(mesh.material == page)
        corners = mesh.indices[rows].ravel()
        expected = cloud.corners[p] + ST[:, :1] * cloud.u_axes[p] + ST[:, 1:] * cloud.v_axes[p]
        for k, (s, t) in enumerate(ST):
            vertex = [c for c in corners if np.allclose(mesh.world_positions[c], expected[k],
                                                        atol=1e-5)]
            assert vertex, f"rectangle {p} lost its corner {k}"
            np.testing.assert_allclose(mesh.uvs[vertex[0]], [(x + s * w) / 32, (y + t * h) / 32],
                                       atol=1e-7)
        plane = np.cross(cloud.u_axes[p], cloud.v_axes[p])
        np.testing.assert_allclose(mesh.normals[corners], np.broadcast_to(
            plane / np.linalg.norm(plane), (6, 3)), atol=1e-6)
        first, second = mesh.world_positions[mesh.indices[rows]]
        for a, b, c in (first, second):  # counter-clockwise seen from the plane's side
            assert np.dot(np.cross(b - a, c - a), plane) > 0
    assert [m.alpha_mode for m in mesh.materials] == ["MASK", "MASK"]
    assert all(m.alpha_cutoff == 0.5 and m.double_sided for m in mesh.materials)


def test_a_dmbbc_falls_back_to_the_quads_of_its_own_cloud():
    boxes = TECHNIQUE.samples()["dmbbc"]
    mine, its_cloud = boxes.fallback_mesh(), boxes.cloud.fallback_mesh()
    np.testing.assert_array_equal(mine.world_positions, its_cloud.world_positions)
    np.testing.assert_array_equal(mine.uvs, its_cloud.uvs)
    np.testing.assert_array_equal(mine.materials[0].texture, its_cloud.materials[0].texture)
    np.testing.assert_array_equal(fallback_normal_texture(boxes),
                                  fallback_normal_texture(boxes.cloud))


def box_mips(image: np.ndarray, levels: int) -> list[np.ndarray]:
    """Levels 1.. of ``image`` as a viewer builds them: each texel the mean of 2 x 2."""
    out = [np.asarray(image, np.float64)]
    for _ in range(levels):
        a = out[-1]
        out.append((a[0::2, 0::2] + a[1::2, 0::2] + a[0::2, 1::2] + a[1::2, 1::2]) / 4)
    return out[1:]


def test_every_mip_level_keeps_each_cards_colour():
    """The sample's red and green cards on black: a viewer's mip levels of the fallback's
    texture (box filtered, alpha ignored) keep each card's exact colour wherever their texel
    holds that card's texels, down to one texel per card (no black fringe)."""
    cloud = TECHNIQUE.samples()["billboard-cloud"]
    texture = cloud.fallback_mesh().materials[0].texture
    assert np.array_equal(texture[..., 3], cloud.color[0, ..., 3])
    covered = cloud.color[0, ..., 3] > 0
    assert np.array_equal(texture[covered], cloud.color[0][covered])
    cards = np.zeros(covered.shape, int)
    cards[2:14, 2:14], cards[2:14, 18:30] = 1, 2
    for level, rgb in enumerate(box_mips(texture[..., :3], 4), start=1):
        for k, colour in ((1, (200, 40, 40)), (2, (40, 200, 40))):
            holds = box_mips(cards == k, level)[-1] > 0
            np.testing.assert_array_equal(rgb[holds], np.broadcast_to(colour, rgb[holds].shape),
                                          err_msg=f"level {level}, card {k}")


def test_the_normal_map_is_tangent_space_along_u_and_v():
    """A card with u along -z, v along +y (its plane normal +x): a world normal n is stored
    as (n . T, n . B, n . N) with T = -z, B = +y, N = +x (glTF's +X right along u, +Y up along
    v, +Z out of the card), and every corner's TANGENT is (-z, w = +1)."""
    normal = np.zeros((1, 8, 8, 3), np.uint8)
    normal[0, :, :4] = encode([0.6, 0.8, 0.0])
    normal[0, :, 4:] = encode([0.0, 0.0, -1.0])
    color = np.full((1, 8, 8, 4), 255, np.uint8)
    cloud = BillboardCloud(corners=[[0.0, -1.0, 1.0]], u_axes=[[0.0, 0.0, -2.0]],
                           v_axes=[[0.0, 2.0, 0.0]], rects=[[0, 0, 0, 8, 8]], color=color,
                           normal=normal, epsilon=0.01)
    texture = fallback_normal_texture(cloud).astype(int)
    assert texture.shape == (8, 8, 4) and (texture[..., 3] == 255).all()
    assert np.abs(texture[:, :4, :3] - encode([0.0, 0.8, 0.6])).max() <= 1
    assert np.abs(texture[:, 4:, :3] - encode([1.0, 0.0, 0.0])).max() <= 1
    np.testing.assert_array_equal(fallback_tangents(cloud), np.tile([0, 0, -1, 1], (4, 1)))
    for page in (1, -1, True):
        with pytest.raises(UsageError, match="page must be an atlas page of the cloud, 0..0"):
            fallback_normal_texture(cloud, page)


@pytest.fixture(scope="module")
def vehicle():
    return load_mesh("demo:vehicle")


@pytest.fixture(scope="module")
def bakes(gl, vehicle):
    """The vehicle's cloud and volumetric DMBBC, epsilon 3% of its diagonal."""
    return {"billboard-cloud": bake_billboard_cloud(vehicle, epsilon=0.03),
            "dmbbc": bake_boxes(vehicle, "volumetric", epsilon=0.03)}


def test_the_normal_map_and_tangents_give_back_every_stored_normal(bakes):
    """glTF's rule on a bake: n = normalize(x T + y w (N x T) + z N) from the map, the
    TANGENTs and the quad's normal is the stored world normal, to its 8-bit quantization."""
    cloud = bakes["billboard-cloud"]
    mesh, tangents = cloud.fallback_mesh(), fallback_tangents(cloud)
    texture = fallback_normal_texture(cloud)[..., :3] * (2.0 / 255.0) - 1.0
    worst = 0.0
    for p, (page, x, y, w, h) in enumerate(cloud.rects):
        assert page == 0
        shown = cloud.color[0, y:y + h, x:x + w, 3] > 0
        if not shown.any():  # a plane whose faces it sees edge-on
            continue
        corner = mesh.indices[2 * p, 0]
        t, sign = tangents[corner, :3].astype(np.float64), float(tangents[corner, 3])
        n = mesh.normals[corner].astype(np.float64)
        local = texture[y:y + h, x:x + w][shown]
        rebuilt = local[:, :1] * t + local[:, 1:2] * sign * np.cross(n, t) + local[:, 2:] * n
        rebuilt /= np.linalg.norm(rebuilt, axis=1, keepdims=True)
        stored = cloud.normal[0, y:y + h, x:x + w][shown] * (2.0 / 255.0) - 1.0
        stored /= np.linalg.norm(stored, axis=1, keepdims=True)
        worst = max(worst, float(np.degrees(np.arccos(np.clip(
            np.sum(rebuilt * stored, axis=1), -1, 1))).max()))
    assert worst < 1.5


@pytest.mark.parametrize("kind", ["billboard-cloud", "dmbbc"])
def test_the_fallback_looks_like_the_mesh_from_three_views(bakes, vehicle, kind):
    """Mask IoU >= 0.9 against the vehicle from three views, the same picture as the cloud
    draws itself (its alpha test on the base level, the fallback's on the mip level a viewer
    picks), the mesh's colour; 2 triangles per rectangle, within the 20k budget."""
    rep = bakes[kind]
    cloud = rep.cloud if kind == "dmbbc" else rep
    mesh = rep.fallback_mesh()
    assert mesh.triangle_count == 2 * cloud.count <= 20_000
    for azimuth, elevation in VIEWS:
        camera = orbit_bounds(vehicle.bounds, azimuth, elevation, None, (128, 128))
        truth, drawn, itself = (render(x, camera, light=FLAT) for x in (vehicle, mesh, cloud))
        view = f"view {azimuth:g},{elevation:g}"
        assert iou(drawn.mask, truth.mask) >= 0.9, view
        assert iou(drawn.mask, itself.mask) >= 0.98, view
        both = drawn.mask & truth.mask
        gap = drawn.color[both, :3].mean(axis=0) - truth.color[both, :3].mean(axis=0)
        assert np.abs(gap).max() < 0.02, view


def test_a_viewer_sees_the_atlas_colour_where_a_quad_faces_it(gl):
    """Straight on, pixel for texel: the rendered fallback shows the stored sRGB colour."""
    color = np.zeros((1, 16, 16, 4), np.uint8)
    j, i = np.mgrid[:16, :16]
    color[0, ..., 0], color[0, ..., 1], color[0, ..., 2] = 16 * i, 16 * j, 90
    color[0, ..., 3] = np.where((i - 7.5) ** 2 + (j - 7.5) ** 2 < 36, 255, 0)
    cloud = BillboardCloud(corners=[[-1.0, -1.0, 0.0]], u_axes=[[2.0, 0, 0]],
                           v_axes=[[0, 2.0, 0]], rects=[[0, 0, 0, 16, 16]], color=color,
                           normal=np.full((1, 16, 16, 3), 128, np.uint8), epsilon=0.01)
    camera = Camera(eye=(0.0, 0.0, 3.0), target=(0.0, 0.0, 0.0), size=(16, 16),
                    ortho_height=1.0, near=1.0, far=5.0)
    frame = render(cloud.fallback_mesh(), camera, light=FLAT)
    texels = color[0, ::-1]  # frames have row 0 at the top, textures at v = 0
    np.testing.assert_array_equal(frame.mask, texels[..., 3] >= 128)
    np.testing.assert_allclose(frame.color[frame.mask, :3],
                               srgb_decode(texels[frame.mask, :3] / 255.0), atol=2e-3)


def iou(a: np.ndarray, b: np.ndarray) -> float:
    return float((a & b).sum() / (a | b).sum())
