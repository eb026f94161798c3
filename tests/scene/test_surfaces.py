"""Tests of the textured demo surfaces (reliefkit.scene.assets.surfaces)."""

from __future__ import annotations

import numpy as np
import pytest

from reliefkit.errors import UsageError
from reliefkit.scene import assets
from reliefkit.scene.assets import surfaces, teapot_data
from reliefkit.techniques.shellvolume.shell import build_shell

CLOSED = {"sphere", "dented-sphere", "torus", "two-spheres", "teapot"}
#: The teapot's creases (foot, knob neck, rolled spout lip) only take a thin shell.
THICKNESS = {"teapot": surfaces.TEAPOT_SHELL}


@pytest.fixture(scope="module")
def meshes():
    with np.errstate(all="raise"):
        return {name: factory() for name, factory in surfaces.SURFACES.items()}


def corners(mesh):
    return mesh.positions.astype(np.float64)[mesh.indices.astype(np.int64)]


def signed_volume(mesh) -> float:
    p = corners(mesh)
    return float(np.einsum("ij,ij->i", p[:, 0], np.cross(p[:, 1], p[:, 2])).sum() / 6.0)


def crossings(mesh, origin, direction) -> int:
    """How many triangles the ray origin + t direction (t > 0) crosses (Moller-Trumbore)."""
    p = corners(mesh)
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    h = np.cross(direction, e2)
    det = np.einsum("fi,fi->f", e1, h)
    ok = np.abs(det) > 1e-12
    inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
    s = origin - p[:, 0]
    u = np.einsum("fi,fi->f", s, h) * inv
    q = np.cross(s, e1)
    v = (q @ direction) * inv
    t = np.einsum("fi,fi->f", e2, q) * inv
    return int((ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 0)).sum())


@pytest.mark.parametrize("name", list(surfaces.SURFACES))
def test_arrays_are_finite_unit_and_textured(meshes, name):
    mesh = meshes[name]
    assert mesh.name == name
    for arr in (mesh.positions, mesh.normals, mesh.colors):
        assert np.isfinite(arr).all()
    assert mesh.uvs is not None and mesh.uvs.shape == (len(mesh.positions), 2)
    assert np.isfinite(mesh.uvs).all() and mesh.uvs.min() >= 0 and mesh.uvs.max() <= 1
    length = np.linalg.norm(mesh.normals.astype(np.float64), axis=1)
    np.testing.assert_allclose(length, 1.0, atol=1e-5)
    np.testing.assert_array_equal(np.asarray(mesh.colors)[:, 3], 1.0)
    assert np.abs(mesh.positions).max() <= 1.06


@pytest.mark.parametrize("name", list(surfaces.SURFACES))
def test_no_degenerate_triangles(meshes, name):
    mesh = meshes[name]
    p = corners(mesh)
    area2 = np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
    assert area2.min() > 1e-9
    for a, b in ((0, 1), (1, 2), (0, 2)):  # no two coincident corners in one triangle
        assert np.linalg.norm(p[:, a] - p[:, b], axis=1).min() > 1e-7
    uv = mesh.uvs.astype(np.float64)[mesh.indices.astype(np.int64)]
    d1, d2 = uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0]
    uv_area = np.abs(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])
    assert uv_area.min() > 1e-9


@pytest.mark.parametrize("name", list(surfaces.SURFACES))
def test_outward_orientation(meshes, name):
    mesh = meshes[name]
    p = corners(mesh)
    face = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    vertex = mesh.normals.astype(np.float64)[mesh.indices.astype(np.int64)].sum(axis=1)
    agree = np.einsum("fi,fi->f", face, vertex)
    assert (agree > 0).mean() >= (0.98 if name == "teapot" else 1.0)
    if name in CLOSED:
        assert signed_volume(mesh) > 0


@pytest.mark.parametrize("name", list(surfaces.SURFACES))
def test_build_shell(meshes, name):
    mesh = meshes[name]
    shell = build_shell(mesh, THICKNESS.get(name, 0.1))
    assert len(shell.tets) == 3 * mesh.triangle_count
    assert (shell.volumes() > 0).all()


def test_sphere_radius_seam_and_poles():
    mesh = surfaces.sphere(segments=16, rings=8, radius=0.8)
    np.testing.assert_allclose(np.linalg.norm(mesh.positions, axis=1), 0.8, atol=1e-6)
    np.testing.assert_allclose(signed_volume(mesh), 4 / 3 * np.pi * 0.8 ** 3, rtol=0.1)
    uv = mesh.uvs
    poles = np.flatnonzero((uv[:, 1] == 0) | (uv[:, 1] == 1))
    assert len(poles) == 2 and np.allclose(uv[poles, 0], 0.5)
    np.testing.assert_allclose(mesh.positions[poles, 1], [-0.8, 0.8], atol=1e-6)
    left, right = np.flatnonzero(uv[:, 0] == 0), np.flatnonzero(uv[:, 0] == 1)
    assert len(left) == len(right) == 8 - 1
    np.testing.assert_array_equal(uv[left, 1], uv[right, 1])
    np.testing.assert_array_equal(mesh.positions[left], mesh.positions[right])
    np.testing.assert_array_equal(mesh.normals[left], mesh.normals[right])
    assert len(mesh.positions) == 2 + (8 - 1) * 17


def test_torus_and_tube_seams():
    for mesh in (surfaces.torus(), surfaces.tube()):
        uv = mesh.uvs
        left, right = np.flatnonzero(uv[:, 0] == 0), np.flatnonzero(uv[:, 0] == 1)
        np.testing.assert_array_equal(mesh.positions[left], mesh.positions[right])
        np.testing.assert_array_equal(mesh.normals[left], mesh.normals[right])


def test_plane_faces_up_and_spans_uv():
    mesh = surfaces.plane()
    np.testing.assert_array_equal(mesh.positions[:, 1], 0)
    np.testing.assert_array_equal(mesh.normals, np.tile([0, 1, 0], (len(mesh.positions), 1)))
    assert mesh.uvs.min() == 0 and mesh.uvs.max() == 1


@pytest.mark.parametrize("name, origin, direction", [
    ("torus", (-2.0, 0.0123, 0.0171), (1.0, 0.0031, 0.0)),
    ("two-spheres", (0.0123, 0.0171, -3.0), (0.0, 0.0031, 1.0)),
    ("dented-sphere", (-2.0, 0.0123, 0.6), (1.0, 0.0031, 0.0)),
])
def test_non_convex_rays_cross_four_times(meshes, name, origin, direction):
    assert crossings(meshes[name], np.array(origin), np.array(direction)) == 4


def test_dented_sphere_normals_follow_geometry(meshes):
    mesh = meshes["dented-sphere"]
    front = np.argmax(mesh.positions[:, 2])
    assert mesh.positions[:, 2].max() < 0.7  # dented: the front is pushed in
    centre = np.argmin(np.linalg.norm(mesh.positions[:, :2], axis=1)
                       + (mesh.positions[:, 2] < 0))
    assert mesh.normals[centre, 2] > 0.99 and front != centre


def test_vase_uv_follows_arc_length(meshes):
    mesh = meshes["vase"]
    column = np.flatnonzero(mesh.uvs[:, 0] == 0)
    column = column[np.argsort(mesh.uvs[column, 1])]
    steps = np.linalg.norm(np.diff(mesh.positions[column], axis=0), axis=1)
    assert steps.max() / steps.min() < 1.3
    assert len(np.flatnonzero(mesh.uvs[:, 1] == 0)) == 1  # one bottom pole


def test_teapot_data_and_bounds(meshes):
    assert teapot_data.PATCHES.shape == (32, 16) and teapot_data.VERTICES.shape == (306, 3)
    assert meshes["teapot"].extra["patches"] == 32
    nets = teapot_data.patch_control_points()
    for _, first, around, rows in surfaces.TEAPOT_PARTS:  # parts are patch grids
        for r in range(rows):
            for c in range(around):
                net = nets[first + r * around + c]
                np.testing.assert_array_equal(net[:, 3], nets[first + r * around
                                                              + (c + 1) % around][:, 0])
                if r + 1 < rows:
                    np.testing.assert_array_equal(net[3], nets[first + (r + 1) * around + c][0])
    # bounding box of the data's own surface (dense de Casteljau-free Bernstein sampling)
    t = np.linspace(0, 1, 41)[:, None]
    b = np.concatenate([(1 - t) ** 3, 3 * t * (1 - t) ** 2, 3 * t ** 2 * (1 - t), t ** 3], 1)
    points = np.einsum("ti,sj,pijx->ptsx", b, b, nets).reshape(-1, 3)
    extent = points.max(0) - points.min(0)  # z up
    bounds = meshes["teapot"].bounds
    size = bounds[1] - bounds[0]  # y up
    np.testing.assert_allclose(size / size.max(), extent[[0, 2, 1]] / extent.max(), atol=0.01)
    assert 1.9 < size[0] / size[1] < 2.1  # spout to handle vs height, as in the data
    assert size.max() == pytest.approx(2.0, abs=1e-5)
    top = np.argmax(meshes["teapot"].positions[:, 1])
    assert meshes["teapot"].normals[top, 1] > 0.99  # the knob's top faces up


def test_make_asset_knows_the_surfaces():
    assert tuple(surfaces.SURFACES) == assets.SURFACE_NAMES
    assert assets.ASSET_NAMES == ("terrain", "blob", "tree", "vehicle")
    assert assets.make_asset("torus").name == "torus"
    with pytest.raises(UsageError, match="teapot"):
        assets.make_asset("kettle")


def test_bad_parameters_are_refused():
    with pytest.raises(UsageError):
        surfaces.sphere(segments=2)
    with pytest.raises(UsageError):
        surfaces.torus(major=0.3, minor=0.5)
    with pytest.raises(UsageError):
        surfaces.teapot(subdivisions=0)
