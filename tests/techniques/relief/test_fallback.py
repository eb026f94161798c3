"""The relief kinds' glTF fallback meshes: the source mesh's silhouette from three views, the
triangle budget, the colour, the box mapping (projective too) and the clip box."""

import numpy as np
import pytest
from helpers import BOX, FALLBACK_VIEWS, fallback_ious, make_relief, terrain_block

import reliefkit as rk
from reliefkit.io.inputs import load_mesh
from reliefkit.metrics import mask_iou
from reliefkit.render import render
from reliefkit.scene.assets import terrain_heights
from reliefkit.scene.light import DirectionalLight
from reliefkit.scene.views import orbit_bounds
from reliefkit.techniques.relief.frustum import frustum_matrix
from reliefkit.techniques.relief.representation import ReliefTexture

UNLIT = DirectionalLight(intensity=0.0, ambient=1.0, specular=0.0)  # colour = base colour



@pytest.fixture(scope="module")
def terrain_relief(gl):
    mesh = terrain_block()
    return mesh, rk.bake(mesh, "relief", depth_res=96)


def test_relief_fallback_covers_its_mesh_from_three_views(terrain_relief):
    mesh, relief = terrain_relief
    fallback = relief.fallback_mesh()
    assert fallback.triangle_count <= 20_000
    assert min(fallback_ious(mesh, fallback)) >= 0.9


def test_relief_fallback_takes_the_mesh_colour(terrain_relief):
    mesh, relief = terrain_relief
    fallback = relief.fallback_mesh()
    assert fallback.materials[0].texture is relief.color and fallback.uvs is not None
    for az, el in [(30.0, 20.0), (150.0, 35.0), (270.0, 60.0)]:  # from below: the texels
        camera = orbit_bounds(mesh.bounds, az, el, size=(96, 96))
        got, want = render(fallback, camera, light=UNLIT), render(mesh, camera, light=UNLIT)
        # the top, per pixel (a mirrored uv would keep the mean); a relief colours its walls
        # by the top's texels, the block's skirts are coloured by their own height
        both = got.mask & want.mask & (want.normal[..., 1] > 0.5)
        error = np.abs(got.color[both][:, :3] - want.color[both][:, :3])
        assert np.median(error) < 0.02 and np.percentile(error, 90) < 0.08, (az, el)


@pytest.mark.parametrize("budget", [50, 999, 5000, 20_000])
def test_relief_fallback_stays_within_its_budget_and_uses_it(terrain_relief, budget):
    _, relief = terrain_relief
    fallback = relief.fallback_mesh(budget)
    assert fallback.triangle_count <= budget
    # the empty ring is left out; the footprint fills most of the box
    assert fallback.triangle_count >= 0.6 * min(budget, 2 * 96 * 96)


def test_relief_fallback_leaves_out_cells_over_empty_texels(terrain_relief):
    _, relief = terrain_relief
    fallback = relief.fallback_mesh()
    h = relief.to_box(fallback.world_positions)[:, 2]
    assert (h[fallback.indices] > 1e-6).any(axis=1).all()  # no triangle lies on the floor
    assert (h[fallback.indices] < 1e-6).any()  # the walls at the footprint's edge are kept


def test_fallback_vertices_are_the_projective_box_at_their_heights(gl):
    """A reverse-perspective frustum: each vertex is box_to_world of (u, v, bilinear height
    at u, v), computed here in homogeneous coordinates, clamped at the border."""
    rng = np.random.default_rng(3)
    height = rng.uniform(0.2, 1.0, (12, 17)).astype(np.float32)
    box_to_world = frustum_matrix((0.1, -2.0, 0.3), np.array([[1.0, 0, 0], [0, 0, 1.0],
                                                               [0, 1.0, 0]]),
                                  0.4, 0.3, 1.0, 3.0)
    relief = make_relief(height, box_to_world)
    fallback = relief.fallback_mesh(10_000)
    uv = fallback.uvs.astype(np.float64)
    # no more cells than texels, and the walls under the border down to h = 0
    assert fallback.triangle_count == 2 * 17 * 12 + 2 * 2 * (17 + 12)
    x = np.clip(uv[:, 0] * 17 - 0.5, 0, 16)
    y = np.clip(uv[:, 1] * 12 - 0.5, 0, 11)
    i, j = np.minimum(x.astype(int), 15), np.minimum(y.astype(int), 10)
    fx, fy = x - i, y - j
    h = ((height[j, i] * (1 - fx) + height[j, i + 1] * fx) * (1 - fy)
         + (height[j + 1, i] * (1 - fx) + height[j + 1, i + 1] * fx) * fy)
    errors = []
    for level in (h, np.zeros_like(h)):  # on the surface, or at a wall's foot
        world = np.c_[uv, level, np.ones(len(h))] @ box_to_world.T
        errors.append(np.abs(fallback.world_positions - world[:, :3] / world[:, 3:]).max(1))
    on_top = errors[0] < 2e-6
    assert (on_top | (errors[1] < 2e-6)).all() and on_top.sum() >= 18 * 13
    # front faces away from the apex (outwards, towards +h)
    tops = on_top[fallback.indices].all(axis=1)
    corners = fallback.world_positions[fallback.indices[tops]]
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    outward = corners.mean(axis=1) - (0.1, -2.0, 0.3)
    assert tops.sum() >= 2 * 17 * 12 and ((normal * outward).sum(axis=1) > 0).all()


def test_heightmap_fallback_has_the_sides_the_relief_draws(gl):
    """A heightmap fills its box: the relief draws the box's sides under the border."""
    relief = rk.relief_from_heights(terrain_heights(48))
    fallback = relief.fallback_mesh()
    for az, el in FALLBACK_VIEWS:
        camera = orbit_bounds(relief.bounds, az, el, size=(96, 96))
        assert mask_iou(render(fallback, camera), render(relief, camera)) >= 0.97, (az, el)


def test_relief_fallback_is_cut_to_the_clip_box(gl):
    """A plateau at y = 0.6 whose texel centres span 29 / 16 in x and z, cut to x in
    [-0.6, 0.3]: its top keeps exactly 0.9 x 29 / 16 of area, within the clip box."""
    height = np.full((32, 32), 0.6, np.float32)
    height[[0, -1], :] = height[:, [0, -1]] = 0.0
    plain = make_relief(height)
    clip = np.array([[-0.6, -1.0, -2.0], [0.3, 2.0, 2.0]])
    clipped = ReliefTexture(height=plain.height, color=plain.color, normal=plain.normal,
                            box_to_world=BOX, clip_bounds=clip)
    for relief, width in ((plain, 29 / 16), (clipped, 0.9)):
        fallback = relief.fallback_mesh()
        corners = fallback.world_positions[fallback.indices]
        top = (np.abs(corners[..., 1] - 0.6) < 1e-6).all(axis=1)
        area = np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0],
                                       corners[:, 2] - corners[:, 0]), axis=1) / 2
        assert area[top].sum() == pytest.approx(width * 29 / 16, rel=1e-5)
    points = fallback.world_positions
    assert (points >= clip[0] - 1e-6).all() and (points <= clip[1] + 1e-6).all()
    assert fallback.triangle_count <= 20_000


def test_reverse_frustum_fallback_covers_its_mesh(gl):
    mesh = terrain_block()
    relief = rk.bake(mesh, "relief-frustum", depth_res=96)
    fallback = relief.fallback_mesh()
    assert fallback.triangle_count <= 20_000
    points = fallback.world_positions
    assert (points >= relief.clip_bounds[0]).all() and (points <= relief.clip_bounds[1]).all()
    assert min(fallback_ious(mesh, fallback)) >= 0.9


def test_relief_cube_fallback_covers_its_mesh(gl):
    mesh = load_mesh("demo:vehicle")
    rep = rk.bake(mesh, "relief-cube", depth_res=64)
    fallback = rep.fallback_mesh()
    assert len(fallback.materials) == 6  # each part's colour
    assert fallback.triangle_count <= 20_000
    assert min(fallback_ious(mesh, fallback)) >= 0.9
    assert 2500 <= rep.fallback_mesh(3000).triangle_count <= 3000


def test_too_small_a_budget_is_refused_in_words(gl):
    from reliefkit.errors import UsageError
    from reliefkit.techniques.relief.representation import ReliefObject

    relief = make_relief(np.full((8, 8), 0.5, np.float32))
    with pytest.raises(UsageError, match="at least 12 triangles, got 7"):
        ReliefObject(parts=[relief] * 6).fallback_mesh(7)
    with pytest.raises(UsageError, match="at least 2 triangles"):
        relief.fallback_mesh(1)
