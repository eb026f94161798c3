"""Meshes far from the world origin render like the same mesh at the origin (issue 8).

Georeferenced meshes sit 1e4..1e8 units away from the origin, where float32 keeps only a few
bits of a coordinate's fraction. The reference is the mesh itself drawn at the origin: the
same picture, and AOV positions in the file's own coordinates (float64), offset exactly.
"""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from reliefkit.render import render
from reliefkit.scene.camera import Camera
from reliefkit.scene.mesh import RenderMesh, vertex_normals

OFFSETS = [1e4, 1e6, 1e7, 1e8]


def colourful_sphere(offset=0.0) -> RenderMesh:
    """A unit icosphere coloured by its normal (so every pixel has a distinct colour),
    moved by ``offset`` along all three axes; positions given in float64."""
    sphere = trimesh.creation.icosphere(subdivisions=3)
    positions = np.asarray(sphere.vertices, np.float64)
    normals = vertex_normals(positions, sphere.faces)
    colors = np.c_[0.5 + 0.5 * normals, np.ones(len(normals))]
    return RenderMesh(positions + offset, sphere.faces, normals, colors, name="sphere")


def view(mesh: RenderMesh, size=(96, 96)) -> Camera:
    return Camera.orbit(mesh.center, 30.0, 20.0, 3.0, size=size)


@pytest.mark.parametrize("offset", OFFSETS)
def test_a_far_mesh_renders_like_the_mesh_at_the_origin(gl, offset):
    near, far = colourful_sphere(), colourful_sphere(offset)
    assert np.array_equal(far.origin, [offset] * 3)  # kept relative to its centre
    reference, frame = render(near, view(near)), render(far, view(far))
    differ = reference.mask != frame.mask
    assert reference.mask.sum() > 2000 and differ.sum() <= 4  # edge pixels at most
    both = reference.mask & frame.mask
    assert np.abs(frame.color[both] - reference.color[both]).max() < 2e-3
    # positions in the file's own coordinates, to float32 precision at the sphere's size
    assert frame.position.dtype == np.float64
    moved = frame.position[both] - offset
    assert np.abs(moved - reference.position[both]).max() < 1e-4
    np.testing.assert_allclose(frame.depth[both], reference.depth[both], atol=1e-5)


def test_mesh_bounds_and_world_positions_keep_the_file_coordinates():
    mesh = colourful_sphere(1e8 + 0.25)
    np.testing.assert_allclose(mesh.bounds, [[1e8 + 0.25 - 1] * 3, [1e8 + 0.25 + 1] * 3],
                               rtol=0, atol=1e-6)
    exact = np.asarray(trimesh.creation.icosphere(subdivisions=3).vertices) + 1e8 + 0.25
    assert np.abs(mesh.world_positions - exact).max() < 1e-6
    assert mesh.radius == pytest.approx(1.0, abs=1e-6)


def test_near_meshes_keep_their_coordinates_as_they_are():
    mesh = colourful_sphere(100.0)  # 100 units away, 2 units wide: float32 is plenty
    assert not mesh.origin.any()
    exact = np.asarray(trimesh.creation.icosphere(subdivisions=3).vertices) + 100.0
    np.testing.assert_array_equal(mesh.positions, exact.astype(np.float32))


def test_a_far_mesh_keeps_its_origin_in_an_rk_file(tmp_path):
    from reliefkit.io import rk

    mesh = colourful_sphere(1e8)
    rk.save(tmp_path / "far.rk", mesh)
    back = rk.load(tmp_path / "far.rk")
    np.testing.assert_array_equal(back.origin, mesh.origin)
    np.testing.assert_array_equal(back.world_positions, mesh.world_positions)


@pytest.mark.parametrize("offset", [1e6, 1e8])
def test_voxelizing_a_far_mesh_fills_the_same_voxels(gl, offset):
    from reliefkit.bake.voxelize import voxelize

    def grid(mesh):
        lo, hi = mesh.bounds
        box = np.diag([*(hi - lo) * 1.1, 1.0])
        box[:3, 3] = lo - 0.05 * (hi - lo)
        return voxelize(mesh, box, (16, 16, 16), mode="solid").occupancy

    np.testing.assert_array_equal(grid(colourful_sphere(offset)), grid(colourful_sphere()))


def test_the_cli_renders_a_far_obj_like_the_same_obj_at_the_origin(gl, tmp_path):
    from PIL import Image

    from reliefkit.cli import main

    sphere = trimesh.creation.icosphere(subdivisions=2)
    pictures = []
    for offset in (0.0, 1e7):
        path = tmp_path / f"s{int(offset)}.obj"
        lines = [f"v {x + offset:.17g} {y + offset:.17g} {z + offset:.17g}"
                 for x, y, z in sphere.vertices]
        lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in sphere.faces]
        path.write_text("\n".join(lines) + "\n")
        out = tmp_path / f"s{int(offset)}.png"
        assert main(["render", str(path), "-o", str(out), "--size", "80x80"]) == 0
        pictures.append(np.asarray(Image.open(out)).astype(int))
    differ = np.abs(pictures[0] - pictures[1]).max(axis=-1) > 2
    assert pictures[0][..., 3].sum() > 0 and differ.sum() <= 4
