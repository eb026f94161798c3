"""The shell geometry: prisms split consistently into positive tetrahedra, their texture
matrices, planes and adjacency, and the refusals."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
import trimesh

from reliefkit.errors import UsageError
from reliefkit.scene.mesh import RenderMesh, vertex_normals
from reliefkit.techniques.shellvolume.shell import build_shell


def mesh(positions, faces, uvs="planar", normals=None):
    positions = np.asarray(positions, dtype=np.float64)
    faces = np.asarray(faces)
    if normals is None:
        normals = vertex_normals(positions, faces)
    if isinstance(uvs, str):
        uvs = positions[:, :2] - positions[:, :2].min(axis=0)
    return RenderMesh(positions, faces, normals, np.ones((len(positions), 4)), uvs)


def grid(n=6, m=5, width=2.0, height=1.5, seed=0, flip_some=False):
    """A plane z = 0 of (n x m) vertices, normals +z, uv = (x / width, y / height), with
    the vertex numbering shuffled so the split rule meets every index order."""
    x, y = np.meshgrid(np.linspace(0, width, n), np.linspace(0, height, m), indexing="ij")
    positions = np.column_stack([x.ravel(), y.ravel(), np.zeros(n * m)])
    at = np.arange(n * m).reshape(n, m)
    quads = [(at[i, j], at[i + 1, j], at[i + 1, j + 1], at[i, j + 1])
             for i in range(n - 1) for j in range(m - 1)]
    faces = np.array([t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))])
    rng = np.random.default_rng(seed)
    perm = rng.permutation(n * m)  # new index of old vertex
    new_positions = np.empty_like(positions)
    new_positions[perm] = positions
    faces = perm[faces]
    if flip_some:
        flip = rng.random(len(faces)) < 0.3
        faces[flip] = faces[flip][:, ::-1]
    uvs = new_positions[:, :2] / [width, height]
    normals = np.tile([0.0, 0.0, 1.0], (n * m, 1))
    return mesh(new_positions, faces, uvs, normals), (n, m, width, height)


def sphere(radius=1.0, subdivisions=2):
    """trimesh's icosphere with exact radial normals and a (tilted) spherical mapping."""
    ico = trimesh.creation.icosphere(subdivisions=subdivisions, radius=radius)
    p = np.asarray(ico.vertices, dtype=np.float64)
    unit = p / np.linalg.norm(p, axis=1, keepdims=True)
    u = np.arctan2(unit[:, 1], unit[:, 0]) / (2 * np.pi) + 0.5
    v = np.arccos(np.clip(unit[:, 2], -1, 1)) / np.pi
    uvs = np.column_stack([u + 0.05 * unit[:, 2], v + 0.05 * unit[:, 0]])
    return mesh(p, np.asarray(ico.faces), uvs, unit)


def closed_volume(points, faces):
    """Volume enclosed by a closed outward-wound triangle mesh (divergence theorem)."""
    a, b, c = (points[faces[:, k]] for k in range(3))
    return float(np.einsum("fi,fi->f", a, np.cross(b, c)).sum() / 6.0)


def vfold(thickness):
    """A valley z = |x| over x in [-1, 1], y in [0, 1]: concave on its normals' side."""
    positions = [(-1, 0, 1), (0, 0, 0), (1, 0, 1), (-1, 1, 1), (0, 1, 0), (1, 1, 1)]
    faces = [(0, 1, 4), (0, 4, 3), (1, 2, 5), (1, 5, 4)]
    return build_shell(mesh(positions, faces), thickness)


def test_a_single_triangle_is_three_positive_tetrahedra_of_the_prism_volume():
    corners = np.array([[0.0, 0, 0], [2, 0, 0], [0, 1, 0]])
    for perm in itertools.permutations(range(3)):
        for winding in ((0, 1, 2), (0, 2, 1)):
            positions = corners[list(perm)]
            inverse = np.argsort(perm)
            face = inverse[list(winding)][None]
            normals = np.tile([0.0, 0, 1], (3, 1))
            shell = build_shell(mesh(positions, face, normals=normals), 0.5)
            volumes = shell.volumes()
            assert shell.tets.shape == (3, 4) and (volumes > 0).all()
            assert volumes.sum() == pytest.approx(1.0 * 0.5, rel=1e-12)
            assert shell.tetrahedra().shape == (3, 4, 3)
            assert len(shell.boundary_faces()) == 8  # base, top, 3 quads x 2 halves


def test_a_plane_shell_has_the_exact_volume_and_consistent_splits():
    m, (n, k, width, height) = grid(flip_some=True)
    shell = build_shell(m, 0.3)
    assert (shell.volumes() > 0).all()
    assert shell.volumes().sum() == pytest.approx(width * height * 0.3, rel=1e-12)
    faces = len(m.indices)
    border_edges = 2 * (n - 1) + 2 * (k - 1)
    interior_edges = (3 * faces - border_edges) // 2
    summary = shell.summary()
    assert summary["boundary_faces"] == 2 * faces + 2 * border_edges
    assert summary["interior_faces"] == 2 * faces + 2 * interior_edges
    assert_diagonals_follow_the_rule(shell, len(m.positions))


def assert_diagonals_follow_the_rule(shell, count):
    """Every half of a side quad is cut by the diagonal from the smaller base index to the
    larger one's top."""
    tets = shell.tets.astype(np.int64)
    faces = np.stack([np.delete(tets, f, axis=1) for f in range(4)], axis=1).reshape(-1, 3)
    base_of = faces % count
    is_top = faces >= count
    distinct = np.array([len(set(row)) for row in base_of])
    side = faces[distinct == 2]
    assert len(side)
    for face in side:
        for p, q in itertools.combinations(face, 2):
            if p % count != q % count and (p >= count) != (q >= count):
                low, high = (p, q) if p < count else (q, p)
                assert low < high % count, (face, low, high)
    assert is_top.any()


def test_a_sphere_shell_matches_the_volume_between_its_two_surfaces():
    radius, t = 1.0, 0.2
    m = sphere(radius)
    shell = build_shell(m, t)
    volumes = shell.volumes()
    assert (volumes > 0).all()
    faces = np.asarray(m.indices, dtype=np.int64)
    count = len(m.positions)
    between = closed_volume(shell.positions, faces + count) \
        - closed_volume(shell.positions, faces)
    assert volumes.sum() == pytest.approx(between, rel=1e-10)
    assert volumes.sum() == pytest.approx(4 / 3 * np.pi * ((radius + t) ** 3 - radius ** 3),
                                          rel=0.05)
    summary = shell.summary()
    assert summary["boundary_faces"] == 2 * len(faces)  # closed: only base and top
    assert summary["interior_faces"] == (12 * len(faces) - 2 * len(faces)) // 2
    assert_diagonals_follow_the_rule(shell, count)
    boundary = shell.boundary_faces()
    levels = {tuple(sorted(set((np.delete(shell.tets[t_], f) >= count).tolist())))
              for t_, f in boundary}
    assert levels == {(False,), (True,)}  # every boundary face is all base or all top


def test_the_texture_matrix_maps_corners_centroids_and_insides():
    m, _ = grid()
    shell = build_shell(m, 0.25)
    corners, uvw = shell.tetrahedra(), shell.uvw[shell.tets]
    homogeneous = np.concatenate([corners, np.ones(corners.shape[:2] + (1,))], axis=2)
    mapped = np.einsum("tij,tvj->tvi", shell.object_to_texture, homogeneous)
    np.testing.assert_allclose(mapped[..., :3], uvw, atol=1e-12)
    np.testing.assert_allclose(mapped[..., 3], 1.0, atol=1e-12)
    centre = np.einsum("tij,tj->ti", shell.object_to_texture, homogeneous.mean(axis=1))
    np.testing.assert_allclose(centre[:, :3], uvw.mean(axis=1), atol=1e-12)
    weights = np.random.default_rng(1).dirichlet(np.ones(4), size=len(corners))
    inside = np.einsum("tv,tvj->tj", weights, homogeneous)
    texture = np.einsum("tij,tj->ti", shell.object_to_texture, inside)
    assert (texture[:, 2] >= -1e-12).all() and (texture[:, 2] <= 1 + 1e-12).all()
    np.testing.assert_allclose(texture[:, :3], np.einsum("tv,tvj->tj", weights, uvw),
                               atol=1e-12)


def test_planes_hold_their_face_and_have_the_opposite_vertex_inside():
    shell = build_shell(sphere(), 0.15)
    corners = shell.tetrahedra()
    homogeneous = np.concatenate([corners, np.ones(corners.shape[:2] + (1,))], axis=2)
    distance = np.einsum("tfi,tvi->tfv", shell.planes, homogeneous)  # plane f, vertex v
    np.testing.assert_allclose(np.linalg.norm(shell.planes[..., :3], axis=2), 1.0)
    on_face = ~np.eye(4, dtype=bool)
    assert np.abs(distance[:, on_face]).max() < 1e-12
    assert (distance[:, np.eye(4, dtype=bool)] < 0).all()


def test_adjacency_is_symmetric():
    for shell in (build_shell(sphere(), 0.1), build_shell(grid()[0], 0.1)):
        t, f = np.nonzero(shell.neighbors >= 0)
        other, face = shell.neighbors[t, f], shell.neighbor_faces[t, f]
        np.testing.assert_array_equal(shell.neighbors[other, face], t)
        np.testing.assert_array_equal(shell.neighbor_faces[other, face], f)
        for a, b, fa, fb in zip(t, other, f, face, strict=True):
            assert set(np.delete(shell.tets[a], fa)) == set(np.delete(shell.tets[b], fb))
        assert ((shell.neighbors < 0) == (shell.neighbor_faces < 0)).all()


def test_the_local_frame_follows_the_uvs():
    m, _ = grid()
    shell = build_shell(m, 0.1)
    np.testing.assert_allclose(shell.tangents, np.tile([1.0, 0, 0], (len(shell.uvw), 1)),
                               atol=1e-12)
    np.testing.assert_allclose(shell.bitangents, np.tile([0.0, 1, 0], (len(shell.uvw), 1)),
                               atol=1e-12)
    curved = build_shell(sphere(), 0.1)
    for a, b in ((curved.tangents, curved.normals), (curved.bitangents, curved.normals),
                 (curved.tangents, curved.bitangents)):
        assert np.abs(np.einsum("vi,vi->v", a, b)).max() < 1e-12
    np.testing.assert_allclose(np.linalg.norm(curved.tangents, axis=1), 1.0)


def test_a_per_vertex_thickness_gives_the_integral_volume():
    m, (_, _, width, height) = grid()
    x = m.world_positions[:, 0]
    thickness = 0.1 + 0.2 * x
    shell = build_shell(m, thickness)
    assert (shell.volumes() > 0).all()
    assert shell.volumes().sum() == pytest.approx(width * height * (0.1 + 0.2 * width / 2),
                                                  rel=1e-12)
    np.testing.assert_allclose(shell.positions[len(x):, 2], thickness)
    np.testing.assert_array_equal(shell.thickness, thickness)


def test_a_thin_valley_is_fine_and_a_thick_one_folds():
    assert (vfold(0.2).volumes() > 0).all()
    with pytest.raises(UsageError, match=r"^\d+ of 12 tetrahedra are inverted.*smaller "
                                         r"thickness"):
        vfold(3.0)


@pytest.mark.parametrize("thickness, message", [
    (0.0, "positive"), (-1.0, "positive"), (float("nan"), "positive"),
    (np.ones(7), r"one per vertex \(6,\)"), (np.ones((6, 1)), "one per vertex"),
    (np.array([0.1, 0.1, np.nan, 0.1, 0.1, 0.1]), "1 value"), ("thick", "positive number"),
    (True, "bool"),
])
def test_bad_thickness_is_refused(thickness, message):
    with pytest.raises(UsageError, match=message):
        vfold(thickness)


def test_bad_inputs_are_refused_in_one_line():
    positions = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]
    no_uvs = RenderMesh(positions, [(0, 1, 2)], [(0, 0, 1)] * 3, np.ones((3, 4)))
    errors = []
    with pytest.raises(UsageError, match="needs texture coordinates") as caught:
        build_shell(no_uvs, 0.1)
    errors.append(caught)
    with pytest.raises(UsageError, match="direction must be") as caught:
        build_shell(mesh(positions, [(0, 1, 2)]), 0.1, direction="up")
    errors.append(caught)
    flat_uv = mesh(positions, [(0, 1, 2)], uvs=np.zeros((3, 2)))
    with pytest.raises(UsageError, match="degenerate texture mapping") as caught:
        build_shell(flat_uv, 0.1)
    errors.append(caught)
    fan = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, -1, 0), (0.5, 0.5, 0.5)]  # edge 0-1 on 3 triangles
    with pytest.raises(UsageError, match="not manifold") as caught:
        build_shell(mesh(fan, [(0, 1, 2), (1, 0, 3), (0, 1, 4)], uvs=np.array(
            [(0, 0), (1, 0), (0, 1), (0.3, -1), (-0.5, 0.7)]),
            normals=np.tile([0.0, 0, 1], (5, 1))), 0.01)
    errors.append(caught)
    with pytest.raises(UsageError, match="degenerate"):
        build_shell(mesh(positions + [(2, 0, 0)], [(0, 1, 3)],
                         normals=np.tile([0.0, 0, 1], (4, 1))), 0.1)
    assert all("\n" not in str(e.value) for e in errors)


def test_unusable_triangles_and_fitted_thickness():
    """A backward vertex normal makes its triangle unusable at any thickness; a too thick
    shell over a concave mesh is thinned only where it would fold."""
    from reliefkit.scene.assets import make_asset
    from reliefkit.techniques.shellvolume.shell import fitted_thickness, unusable_triangles

    torus = make_asset("torus")
    assert not unusable_triangles(torus).any()
    normals = np.asarray(torus.normals).copy()
    normals[0] = -normals[0]
    flipped = RenderMesh(torus.world_positions, torus.indices, normals, torus.colors,
                         torus.uvs)
    bad = unusable_triangles(flipped)
    assert bad.sum() == (np.asarray(torus.indices) == 0).any(axis=1).sum()
    with pytest.raises(UsageError):
        build_shell(torus, 1.0)
    fitted = fitted_thickness(torus, 1.0)
    shell = build_shell(torus, fitted)  # builds now
    assert fitted.max() == 1.0 and fitted.min() < 0.5 and len(shell.tets) > 0
    outer = np.hypot(*torus.world_positions[:, [0, 2]].T) > 1.2  # the convex outside
    assert (fitted[outer] == 1.0).all()
