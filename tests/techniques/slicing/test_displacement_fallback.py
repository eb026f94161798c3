"""The displacement map's glTF fallback mesh: the displaced surface within a triangle budget,
its silhouette from three views, its colour, nothing where the texture is transparent."""

import numpy as np
import pytest
from helpers import fallback_ious, terrain_block

import reliefkit as rk
from reliefkit.render import render
from reliefkit.scene.assets.surfaces import torus
from reliefkit.scene.light import DirectionalLight
from reliefkit.scene.views import orbit_bounds
from reliefkit.techniques.slicing.displacement import DisplacementMap
from reliefkit.techniques.slicing.displacement_bake import square_base
from reliefkit.techniques.slicing.displacement_textures import waves

UNLIT = DirectionalLight(intensity=0.0, ambient=1.0, specular=0.0)  # colour = base colour



@pytest.fixture(scope="module")
def projected(gl):
    mesh = terrain_block()
    return mesh, rk.bake(mesh, "displacement", res=96)


@pytest.fixture(scope="module")
def wavy_torus():
    color, height = waves(res=32)
    return DisplacementMap(torus(major_segments=25, minor_segments=25), color, height, 0.12,
                           (2.0, 1.0), True)


def test_projected_mesh_fallback_covers_its_mesh_from_three_views(projected):
    mesh, rep = projected
    fallback = rep.fallback_mesh()
    assert fallback.triangle_count <= 20_000
    assert min(fallback_ious(mesh, fallback)) >= 0.9


def test_projected_mesh_fallback_takes_the_mesh_colour(projected):
    mesh, rep = projected
    fallback = rep.fallback_mesh()
    for az, el in [(30.0, 20.0), (150.0, 35.0), (270.0, 60.0)]:
        camera = orbit_bounds(mesh.bounds, az, el, size=(96, 96))
        got, want = render(fallback, camera, light=UNLIT), render(mesh, camera, light=UNLIT)
        both = got.mask & want.mask & (want.normal[..., 1] > 0.5)  # the top, per pixel
        error = np.abs(got.color[both][:, :3] - want.color[both][:, :3])
        assert np.median(error) < 0.02 and np.percentile(error, 90) < 0.08, (az, el)


def test_mesh_base_fallback_is_the_displaced_surface(gl, wavy_torus):
    truth = wavy_torus.displaced_mesh(8)  # 64 triangles per base triangle
    fallback = wavy_torus.fallback_mesh()
    assert min(fallback_ious(truth, fallback)) >= 0.95


@pytest.mark.parametrize("budget", [1250, 5000, 20_000, 80_000])
def test_fallback_cuts_each_base_triangle_as_finely_as_the_budget_allows(wavy_torus, budget):
    base = wavy_torus.triangle_count
    count = wavy_torus.fallback_mesh(budget).triangle_count
    n = int(np.sqrt(count / base))
    assert count == base * n * n <= budget < base * (n + 1) ** 2


def test_a_base_larger_than_the_budget_keeps_one_triangle_each(wavy_torus):
    assert wavy_torus.fallback_mesh(100).triangle_count == wavy_torus.triangle_count


def test_fallback_leaves_out_where_the_texture_is_transparent():
    """A disc of radius 0.6 (alpha 1, height 0.5) on the 2 x 2 square, alpha 0 around it:
    seen from above the fallback covers the disc's area, not the square's."""
    res = 128
    s = (np.arange(res) + 0.5) / res * 2 - 1
    x, z = np.meshgrid(s, s)
    inside = x**2 + z**2 < 0.36
    color = np.zeros((res, res, 4), np.float32)
    color[inside] = (0.8, 0.3, 0.2, 1.0)
    height = np.where(inside, 0.5, 0.0).astype(np.float32)
    rep = DisplacementMap(square_base(), color, height, 0.4)
    fallback = rep.fallback_mesh()
    corners = fallback.world_positions[fallback.indices][..., [0, 2]]
    edges = corners[:, 1:] - corners[:, :1]
    e0, e1 = edges[:, 0], edges[:, 1]
    area = np.abs(e0[:, 0] * e1[:, 1] - e0[:, 1] * e1[:, 0]).sum() / 2
    assert area == pytest.approx(np.pi * 0.36, rel=0.05)
    points = fallback.world_positions
    within = np.hypot(points[:, 0], points[:, 2]) < 0.5
    np.testing.assert_allclose(fallback.colors[within, :3], [(0.8, 0.3, 0.2)] * within.sum(),
                               atol=1e-6)
    # the disc's wall: from the surface 0.5 * 0.4 up down to the base, all around
    assert np.isclose(points[:, 1], 0.0).sum() > 100 and points[:, 1].max() == pytest.approx(0.2)
