"""The shared default of layered bakers (`reliefkit.bake.detail`): a layer as thick as the
mesh's detail and a texture tiled at a fixed texel density, checked on grids whose edge
lengths and uv scales are known, and through both bakers that use it."""

from __future__ import annotations

import numpy as np
import pytest

from reliefkit.bake.detail import (
    LAYER_PER_EDGE,
    TILE_PER_LAYER,
    layer_thickness,
    median_edge_length,
    uv_tiling,
)
from reliefkit.scene.mesh import RenderMesh


def grid(n=10, side=4.0, uv_scale=(1.0, 1.0)):
    """n x n quads over [0, side]^2 at z = 0 (edges side / n, diagonals longer), uvs the
    position over side times ``uv_scale``: one unit of u is side / uv_scale[0] long."""
    xs = np.linspace(0.0, side, n + 1)
    x, y = np.meshgrid(xs, xs, indexing="ij")
    positions = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    at = np.arange(x.size).reshape(n + 1, n + 1)
    a, b = at[:-1, :-1].ravel(), at[1:, :-1].ravel()
    c, d = at[1:, 1:].ravel(), at[:-1, 1:].ravel()
    faces = np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    uvs = positions[:, :2] / side * np.asarray(uv_scale)
    return RenderMesh(positions, faces, np.tile([0.0, 0.0, 1.0], (x.size, 1)),
                      np.ones((x.size, 4)), uvs, name="grid")


def test_thickness_follows_the_edges_not_the_box():
    """Two edges of every triangle are side / n long, the third a diagonal: the median is
    side / n whatever the grid's extent."""
    for n, side in ((10, 4.0), (40, 4.0), (10, 400.0)):
        mesh = grid(n, side)
        assert median_edge_length(mesh) == pytest.approx(side / n)
        assert layer_thickness(mesh) == pytest.approx(LAYER_PER_EDGE * side / n)


@pytest.mark.parametrize("uv_scale", [(1.0, 1.0), (1.0, 2.0), (0.5, 3.0)])
def test_tiles_span_the_asked_length_along_u_and_v(uv_scale):
    """One unit of u is side / uv_scale[0] long: a tile of length L needs that over L."""
    side, length = 4.0, 0.5
    expected = tuple(round(side / s / length) for s in uv_scale)
    assert uv_tiling(grid(10, side, uv_scale), length) == expected


def test_tiling_stays_within_its_range():
    assert uv_tiling(grid(4, 1.0), 10.0) == (1, 1)
    assert uv_tiling(grid(4, 1.0), 1e-9) == (4096, 4096)


def test_both_bakers_take_the_defaults_from_the_mesh_and_keep_given_values():
    from reliefkit.bake import bake

    mesh = grid(10, 4.0)  # edges 0.4: layer 0.2, tile 1.0 long: 4 x 4 tiles over the uvs
    thickness = LAYER_PER_EDGE * 0.4
    tiles = round(4.0 / (TILE_PER_LAYER * thickness))
    shell = bake(mesh, "shell-volume", texture="absorption", texture_size=(4, 4, 4))
    assert shell.params["thickness"] == pytest.approx(thickness)
    assert shell.texture.tile == (tiles, tiles)
    given = bake(mesh, "shell-volume", texture="absorption", texture_size=(4, 4, 4),
                 thickness=0.05, tile=(3.0, 2.0))
    assert given.params["thickness"] == 0.05 and given.texture.tile == (3, 2)
    skin = bake(mesh, "displacement", displacement="bumps", res=16)
    assert skin.scale == pytest.approx(thickness) and skin.tile == (tiles, tiles)
    given = bake(mesh, "displacement", displacement="bumps", res=16,
                 displacement_scale=0.05, tile=(3.0, 2.0))
    assert given.scale == 0.05 and given.tile == (3.0, 2.0)
