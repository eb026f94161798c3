"""The fallback mesh of a shell volume (what a glTF viewer without reliefkit shows): the base
mesh with the volume's columns composited into a tiled texture."""

from __future__ import annotations

import numpy as np
import pytest
from shell_scenes import grid_mesh

import reliefkit as rk
from reliefkit.bake.uv_atlas import MaterialAtlas
from reliefkit.colorspace import srgb_decode
from reliefkit.io.inputs import load_input
from reliefkit.metrics import mask_iou
from reliefkit.scene.camera import Camera
from reliefkit.scene.mesh import Material, RenderMesh
from reliefkit.scene.views import orbit_bounds
from reliefkit.techniques.shellvolume.fallback import ALPHA_CUTOFF
from reliefkit.techniques.shellvolume.reference import reference_render
from reliefkit.techniques.shellvolume.representation import TexturedShell
from reliefkit.techniques.shellvolume.textures import VolumeTexture, density_normals

VIEWS = ((30.0, 20.0), (150.0, -10.0), (270.0, 60.0))


def test_the_texture_is_each_column_as_the_cpu_integrator_composites_it():
    """Seen straight down onto a flat shell, one pixel per texel, the CPU integrator's colour
    and opacity are the fallback texture's (rows flipped: the texture's row 0 is v = 0)."""
    depth, size, thickness = 6, 4, 0.2
    rgba = np.random.default_rng(0).random((depth, size, size, 4)).astype(np.float32)
    rgba[..., 3] *= 0.6
    rgba[:, 0, 0, 3] = 0.0  # a clear column: cut away
    texture = VolumeTexture(rgba, density_normals(rgba[..., 3]), "random").over_length(0.2)
    shell = TexturedShell(grid_mesh(4), thickness, texture)
    camera = Camera.orbit((0.0, 0.0, 0.0), 0.0, 0.0, 3.0, size=(size, size), ortho_height=1.0)
    want = reference_render(shell.shell, shell.texture, camera, step=thickness / 2000).color

    fallback = shell.fallback_mesh()
    (material,) = fallback.materials
    got = material.texture[::-1] / 255.0
    np.testing.assert_allclose(srgb_decode(got[..., :3]), want[..., :3], atol=0.006)
    np.testing.assert_allclose(got[..., 3], want[..., 3], atol=0.004)
    assert material.alpha_mode == "MASK" and material.alpha_cutoff == pytest.approx(
        ALPHA_CUTOFF) and material.double_sided
    assert got[-1, 0, 3] == 0.0 < ALPHA_CUTOFF < got[..., 3].min(initial=1, where=got[..., 3] > 0)


def test_the_uvs_tile_the_texture_as_the_shell_does():
    texture = VolumeTexture(np.ones((2, 2, 2, 4), np.float32), np.zeros((2, 2, 2, 3),
                            np.float32), "white", tile=(3, 2))
    shell = TexturedShell(grid_mesh(2), 0.1, texture)
    fallback = shell.fallback_mesh()
    np.testing.assert_allclose(fallback.uvs, shell.base.uvs * (3, 2))
    np.testing.assert_array_equal(fallback.indices, shell.base.indices)
    np.testing.assert_allclose(fallback.world_positions, shell.base.world_positions)


def test_a_fur_shell_looks_like_its_torus_from_three_views(gl):
    torus = load_input("demo:torus")
    shell = rk.bake(torus, "shell-volume", texture="fur", texture_size=(16.0, 16.0, 8.0))
    fallback = shell.fallback_mesh()
    assert fallback.triangle_count == shell.base.triangle_count  # its own: no budget
    for azimuth, elevation in VIEWS:
        camera = orbit_bounds(torus.bounds, azimuth, elevation, size=(128, 128))
        got = rk.render(fallback, camera, ctx=gl)
        assert mask_iou(got, rk.render(torus, camera, ctx=gl)) >= 0.9, (azimuth, elevation)
        # the hue of the fur as the shell draws it (lit differently: compare chromaticity)
        drawn = rk.render(shell, camera, ctx=gl)
        covered = drawn.color[..., 3] >= 0.5
        hue = [c.sum(axis=0) / c.sum() for c in (got.color[..., :3][got.mask],
                                                 drawn.color[..., :3][covered])]
        np.testing.assert_allclose(hue[0], hue[1], atol=0.02)


def test_the_surface_tint_is_the_vertex_colour_of_each_material():
    grid = grid_mesh(4)
    left = grid.world_positions[grid.indices].mean(axis=1)[:, 0] < 0
    base = RenderMesh(grid.world_positions, grid.indices, grid.normals, grid.colors, grid.uvs,
                      materials=[Material("a"), Material("b")], material=np.where(left, 0, 1))
    srgb = np.array([[200, 100, 50], [30, 160, 220]], np.uint8)
    layers = np.full((2, 2, 2, 4), 255, np.uint8)
    layers[..., :3] = srgb[:, None, None]
    texture = VolumeTexture(np.ones((2, 2, 2, 4), np.float32), np.zeros((2, 2, 2, 3),
                            np.float32), "white")
    shell = TexturedShell(base, 0.1, texture, surface=MaterialAtlas(layers, (0, 0, 1, 1)))
    colors = shell.fallback_mesh().colors
    x = base.world_positions[:, 0]
    for side, k in ((x < 0, 0), (x > 0, 1)):
        np.testing.assert_allclose(colors[side, :3], np.broadcast_to(
            srgb_decode(srgb[k] / 255.0), (int(side.sum()), 3)), atol=1e-6)
