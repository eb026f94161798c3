"""scene.decimate: a mesh's bytes as a GPU holds them, its compact quantization, and the
decimation to a byte budget."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from reliefkit.scene.decimate import (
    compact_mesh,
    decimate_to_bytes,
    gpu_bytes,
    octahedral_normals,
    simplified,
)
from reliefkit.scene.mesh import Material, RenderMesh, vertex_normals


def textured_cube(alpha: int = 255, texels=(4, 8)) -> RenderMesh:
    """8 vertices, 12 triangles, uvs, one colour, an 8 x 4 RGBA texture."""
    box = trimesh.creation.box()
    points = np.asarray(box.vertices, np.float32)
    faces = np.asarray(box.faces, np.uint32)
    image = np.full((*texels, 4), 200, np.uint8)
    image[..., 3] = alpha
    return RenderMesh(points, faces, vertex_normals(points, faces),
                      np.broadcast_to(np.float32([0.5, 0.5, 0.5, 1]), (8, 4)),
                      points[:, :2] + 0.5, materials=[Material("m", texture=image)],
                      material=np.zeros(12, np.uint16))


def sphere(subdivisions: int = 4, colored: bool = False) -> RenderMesh:
    ico = trimesh.creation.icosphere(subdivisions)
    points = np.asarray(ico.vertices, np.float32) * np.float32([2.0, 1.0, 0.5]) + 3.0
    faces = np.asarray(ico.faces, np.uint32)
    colors = np.ones((len(points), 4), np.float32)
    if colored:
        colors[:, 0] = (points[:, 0] - points[:, 0].min()) / np.ptp(points[:, 0])
    return RenderMesh(points, faces, vertex_normals(points, faces), colors)


def test_raw_bytes_count_float32_attributes_uint32_indices_and_rgba8_mips():
    # vertices 8 x (12 positions + 12 normals + 8 uvs + 16 colours); 36 uint32 indices;
    # texture 8x4 + 4x2 + 2x1 + 1x1 = 43 texels of 4 bytes
    assert gpu_bytes(textured_cube()) == {"vertices": 384, "indices": 144, "textures": 172,
                                          "total": 700}


def test_compact_bytes_count_quantized_attributes_uint16_indices_and_blocks():
    # vertices 8 x (8 positions + 4 normal + 4 uvs), one colour: a uniform; 36 uint16
    # indices; BC1 (opaque): blocks 2 + 1 + 1 + 1 of 8 bytes
    assert gpu_bytes(textured_cube(), compact=True) == {
        "vertices": 128, "indices": 72, "textures": 40, "total": 240}
    # alpha that varies: BC7, 16-byte blocks
    assert gpu_bytes(textured_cube(alpha=100), compact=True)["textures"] == 80


def test_compact_counts_varying_colours_and_uint32_indices_past_65536_vertices():
    mesh = sphere(colored=True)
    v, f = len(mesh.positions), mesh.triangle_count
    assert gpu_bytes(mesh, compact=True)["vertices"] == v * (8 + 4 + 4)
    many = RenderMesh(np.zeros((70_000, 3)) + np.arange(70_000)[:, None] * [1, 0, 0],
                      np.array([[0, 1, 69_999]]), np.tile([0, 0, 1], (70_000, 1)),
                      np.ones((70_000, 4)))
    assert gpu_bytes(many, compact=True)["indices"] == 3 * 4
    assert gpu_bytes(mesh, compact=True)["indices"] == f * 3 * 2


def test_compact_positions_lie_within_half_a_step_of_the_originals():
    mesh = sphere(colored=True)
    packed = compact_mesh(mesh)
    lo, hi = mesh.bounds
    step = (hi - lo) / 65535
    error = np.abs(packed.world_positions - mesh.world_positions)
    assert (error <= step / 2 + 4 * np.finfo(np.float32).eps * np.abs(hi)).all()
    assert (error > 0).any()  # really quantized
    assert np.abs(packed.colors - mesh.colors).max() <= 0.5 / 255 + 1e-6
    np.testing.assert_array_equal(packed.indices, mesh.indices)


def test_octahedral_normals_stay_within_a_hundredth_of_a_degree():
    rng = np.random.default_rng(1)
    n = rng.normal(size=(20_000, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    angle = np.degrees(np.arccos(np.clip((octahedral_normals(n) * n).sum(axis=1), -1, 1)))
    assert angle.max() < 0.01


@pytest.mark.parametrize("compact", [True, False])
def test_decimate_to_bytes_fits_the_budget_with_the_most_triangles(compact):
    mesh = sphere()
    budget = 20_000
    assert gpu_bytes(mesh, compact=compact)["total"] > budget
    small = decimate_to_bytes(mesh, budget, compact=compact)
    assert gpu_bytes(small, compact=compact)["total"] <= budget
    # one more triangle's decimation no longer fits (the search ends on the largest count)
    more = simplified(mesh, small.triangle_count + 1)
    assert gpu_bytes(more, compact=compact)["total"] > budget or \
        more.triangle_count == small.triangle_count
    again = decimate_to_bytes(mesh, budget, compact=compact)
    np.testing.assert_array_equal(again.positions, small.positions)  # deterministic


def test_decimate_to_bytes_keeps_a_mesh_that_fits_and_refuses_an_impossible_budget():
    mesh = sphere(subdivisions=1)
    kept = decimate_to_bytes(mesh, 10**6)
    assert kept.triangle_count == mesh.triangle_count
    assert decimate_to_bytes(textured_cube(), 30) is None  # the texture alone takes 40


def test_textures_that_do_not_fit_are_halved_to_half_the_budget():
    mesh = textured_cube(texels=(64, 64))
    # compact: geometry 200 bytes; the 64 x 64 BC1 texture with its mips 2048 + 512 + 128
    # + 32 + 3 x 8 = 2744 bytes: the whole mesh fits 3000, not 2000, where the texture may
    # take 1000: at 32 x 32 it takes 512 + 128 + 32 + 3 x 8 = 696
    assert decimate_to_bytes(mesh, 3000).texture.shape == (64, 64, 4)
    small = decimate_to_bytes(mesh, 2000)
    assert small.texture.shape == (32, 32, 4) and small.triangle_count == 12
    assert gpu_bytes(small, compact=True) == {"vertices": 128, "indices": 72,
                                              "textures": 696, "total": 896}
    np.testing.assert_array_equal(small.texture, mesh.texture[:32, :32])  # flat stays flat
