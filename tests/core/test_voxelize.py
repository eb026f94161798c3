"""Voxelization against independent references: analytic inside tests at voxel centres,
exact plane/box overlap for surface layers, and known colours and normals."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from reliefkit.bake.voxelize import VoxelGrid, voxelize
from reliefkit.errors import GPUError, UsageError
from reliefkit.scene.mesh import Material, RenderMesh, vertex_normals

CUBE = np.array([[2.0, 0, 0, -1], [0, 2.0, 0, -1], [0, 0, 2.0, -1], [0, 0, 0, 1]])  # [-1, 1]^3
UNIT = np.eye(4)


def render_mesh(tm: trimesh.Trimesh, color=(0.8, 0.6, 0.4, 1.0), normals=None, name="test"):
    v, f = np.asarray(tm.vertices), np.asarray(tm.faces)
    n = vertex_normals(v, f) if normals is None else normals
    return RenderMesh(v, f, n, np.tile(np.asarray(color, np.float32), (len(v), 1)), name=name)


def sphere(radius=0.8, center=(0.0, 0.0, 0.0), subdivisions=4):
    tm = trimesh.creation.icosphere(subdivisions=subdivisions, radius=radius)
    tm.apply_translation(center)
    return tm


def faceted_box(extents, center=(0.0, 0.0, 0.0), color=(0.8, 0.6, 0.4, 1.0)):
    """A box whose faces have their own vertices and face normals (sharp edges)."""
    tm = trimesh.creation.box(extents=extents)
    tm.apply_translation(center)
    v = tm.vertices[tm.faces].reshape(-1, 3)
    f = np.arange(len(v)).reshape(-1, 3)
    n = np.repeat(tm.face_normals, 3, axis=0)
    return RenderMesh(v, f, n, np.tile(np.asarray(color, np.float32), (len(v), 1)))


def quad(corners, color=(1.0, 1.0, 1.0, 1.0), uvs=None, texture=None, alpha_mode="OPAQUE"):
    """Two triangles over four corners given counter-clockwise, one material."""
    p = np.asarray(corners, np.float64)
    f = np.array([[0, 1, 2], [0, 2, 3]])
    n = vertex_normals(p, f)
    c = np.tile(np.asarray(color, np.float32), (4, 1))
    material = Material(texture=texture, alpha_mode=alpha_mode)
    return RenderMesh(p, f, n, c, uvs=uvs, materials=(material,), name="quad")


def plane_quad(axis: int, position: float, pad: float = 0.2):
    """A quad perpendicular to box axis ``axis`` (0 u, 1 v, 2 h) at ``position``, overhanging
    the unit box by ``pad`` on every side."""
    lo, hi = -pad, 1 + pad
    square = np.array([[lo, lo], [hi, lo], [hi, hi], [lo, hi]])
    others = [a for a in range(3) if a != axis]
    p = np.zeros((4, 3))
    p[:, others[0]], p[:, others[1]] = square[:, 0], square[:, 1]
    p[:, axis] = position
    return quad(p)


def assert_all_close(actual, expected, atol: float) -> None:
    """Every row of ``actual`` equals ``expected`` within ``atol`` (and there are rows)."""
    actual = np.asarray(actual)
    assert actual.size > 0
    error = np.abs(actual - np.asarray(expected)).max()
    assert error <= atol, f"max error {error} over {actual.size // actual.shape[-1]} rows"


def distance_in_voxels(grid: VoxelGrid, signed_distance) -> np.ndarray:
    """|signed distance| of every voxel centre to the reference surface, in voxel sizes."""
    voxel = min(np.linalg.norm(grid.box_to_world[:3, :3], axis=0) / grid.resolution)
    return np.abs(signed_distance(grid.centres())) / voxel


def sphere_distance(center, radius):
    return lambda p: np.linalg.norm(p - np.asarray(center), axis=-1) - radius


def box_distance(center, extents):
    def sdf(p):
        q = np.abs(p - np.asarray(center)) - np.asarray(extents) / 2
        outside = np.linalg.norm(np.maximum(q, 0), axis=-1)
        return outside + np.minimum(q.max(axis=-1), 0)
    return sdf


def check_solid(grid: VoxelGrid, sdf, *, centre_tolerance: float):
    """Solid voxelization vs the analytic inside test at voxel centres.

    * with one sub-point per voxel (supersample 1) ``inside`` is the mesh's own inside test
      at the centre: it may differ from the analytic shape only within ``centre_tolerance``
      voxels of the surface (the tessellation's error);
    * ``occupancy`` (surface plus interior) adds the surface layer: it never misses an
      inside centre, and its extra voxels lie within one voxel of the surface.
    Returns the mismatch counts for the report.
    """
    d = sdf(grid.centres())
    ref = d < 0
    dist = distance_in_voxels(grid, sdf)
    occupied = grid.occupancy > 0
    extra = occupied & ~ref
    missing = ref & ~occupied
    assert not missing.any(), f"{missing.sum()} inside voxels missing"
    assert dist[extra].max() <= np.sqrt(3) / 2 + 1e-6, dist[extra].max()
    band = dist <= np.sqrt(3) / 2  # voxels the surface can pass through
    assert extra.sum() < band.sum()
    mismatch = (grid.inside > 0.5) != ref
    if grid.params["supersample"] == 1:
        assert mismatch.sum() == 0 or dist[mismatch].max() <= centre_tolerance, \
            (mismatch.sum(), dist[mismatch].max())
    return int(mismatch.sum()), int(extra.sum())


# -- solids -----------------------------------------------------------------------------

def test_sphere_solid_matches_analytic_inside(gl):
    tm = sphere(0.8)
    mesh = render_mesh(tm)
    grid = voxelize(mesh, CUBE, (48, 48, 48), mode="solid", supersample=1, ctx=gl)
    # subdivision 4: the facets lie at most 0.8 * (1 - cos(half an edge angle)) inside
    check_solid(grid, sphere_distance((0, 0, 0), 0.8), centre_tolerance=0.05)
    assert grid.occupancy.dtype == np.float32 and grid.occupancy.shape == (48, 48, 48)
    assert set(np.unique(grid.inside)) <= {0.0, 1.0}


def test_sphere_solid_equals_the_meshs_own_inside_test(gl):
    # the faceted sphere is convex: a point is inside iff it is behind every facet plane
    tm = sphere(0.8, subdivisions=2)  # coarse facets: far from the analytic sphere
    grid = voxelize(render_mesh(tm), CUBE, 32, mode="solid", supersample=1, ctx=gl)
    p = grid.centres().reshape(-1, 3)
    margin = p @ tm.face_normals.T - (tm.face_normals * tm.triangles[:, 0]).sum(1)
    exact = (margin < 0).all(axis=1).reshape(grid.inside.shape)
    wrong = (grid.inside > 0.5) != exact
    ties = np.abs(margin).min(axis=1).reshape(exact.shape) < 1e-6  # on a facet plane
    assert not (wrong & ~ties).any(), f"{(wrong & ~ties).sum()} voxels disagree"


def test_sphere_volume_fraction_estimates_the_volume(gl):
    tm = sphere(0.8)
    grid = voxelize(render_mesh(tm), CUBE, 32, mode="solid", supersample=4, ctx=gl)
    voxel_volume = (2 / 32) ** 3
    assert grid.inside.sum() * voxel_volume == pytest.approx(tm.volume, rel=0.01)
    boundary = (grid.inside > 0) & (grid.inside < 1)
    assert boundary.any()  # fractions at the boundary, not just 0 and 1
    assert (grid.occupancy >= grid.inside).all()


def test_axis_aligned_box_solid_anisotropic_grid(gl):
    center, extents = (0.05, 0.02, -0.03), (0.9, 0.5, 0.7)  # faces off voxel boundaries
    mesh = faceted_box(extents, center)
    grid = voxelize(mesh, CUBE, (40, 32, 24), mode="solid", supersample=1, ctx=gl)
    assert grid.occupancy.shape == (24, 32, 40)
    check_solid(grid, box_distance(center, extents), centre_tolerance=1e-3)


def test_rotated_translated_box_to_world(gl):
    rot = trimesh.transformations.rotation_matrix(0.7, [1, 2, 3])[:3, :3]
    box_to_world = np.eye(4)
    box_to_world[:3, :3] = rot @ np.diag([2.2, 1.8, 2.0])
    box_to_world[:3, 3] = [3.0, -1.0, 2.0]
    center = box_to_world[:3, :3] @ [0.5, 0.5, 0.5] + box_to_world[:3, 3]
    mesh = render_mesh(sphere(0.75, center))
    grid = voxelize(mesh, box_to_world, (36, 30, 32), mode="solid", supersample=1, ctx=gl)
    check_solid(grid, sphere_distance(center, 0.75), centre_tolerance=0.05)
    # and the surface layer hugs the sphere
    surf = voxelize(mesh, box_to_world, (36, 30, 32), ctx=gl)
    dist = distance_in_voxels(surf, sphere_distance(center, 0.75))
    assert dist[surf.occupancy > 0].max() <= np.sqrt(3) / 2 + 1e-6


def test_far_from_the_origin(gl):
    offset = np.array([1.0e4, -2.0e4, 5.0e3])  # float32 world positions: ~1e-3 apart
    box_to_world = CUBE.copy()
    box_to_world[:3, 3] += offset
    mesh = render_mesh(sphere(0.8, offset))
    grid = voxelize(mesh, box_to_world, 32, mode="solid", supersample=1, ctx=gl)
    check_solid(grid, sphere_distance(offset, 0.8), centre_tolerance=0.1)


def test_left_handed_box(gl):
    mirror = CUBE.copy()
    mirror[:3, 0] *= -1  # u runs along -x: det < 0, every sweep sees the facing flipped
    mirror[0, 3] = 1.0
    mesh = render_mesh(sphere(0.7, (0.1, 0.0, 0.0)))
    grid = voxelize(mesh, mirror, 32, mode="solid", supersample=1, ctx=gl)
    check_solid(grid, sphere_distance((0.1, 0, 0), 0.7), centre_tolerance=0.05)


def test_parity_rule_ignores_orientation(gl):
    tm = sphere(0.7, subdivisions=3)
    faces = np.asarray(tm.faces).copy()
    faces[::2] = faces[::2, ::-1]  # every other triangle inside out
    mesh = RenderMesh(tm.vertices, faces, vertex_normals(tm.vertices, tm.faces),
                      np.ones((len(tm.vertices), 4)))
    sdf = sphere_distance((0, 0, 0), 0.7)
    parity = voxelize(mesh, CUBE, 32, mode="solid", rule="parity", supersample=1, ctx=gl)
    check_solid(parity, sdf, centre_tolerance=0.1)
    nonzero = voxelize(mesh, CUBE, 32, mode="solid", supersample=1, ctx=gl)
    assert ((nonzero.inside > 0) != (sdf(nonzero.centres()) < 0)).sum() > 100  # broken


def test_overlapping_closed_parts_nonzero_is_the_union_parity_is_not(gl):
    a, b = sphere(0.5, (-0.25, 0, 0), 3), sphere(0.5, (0.25, 0, 0), 3)
    both = trimesh.util.concatenate([a, b])
    mesh = render_mesh(both)
    da, db = sphere_distance((-0.25, 0, 0), 0.5), sphere_distance((0.25, 0, 0), 0.5)
    union = voxelize(mesh, CUBE, 32, mode="solid", supersample=1, ctx=gl)
    check_solid(union, lambda p: np.minimum(da(p), db(p)), centre_tolerance=0.1)
    parity = voxelize(mesh, CUBE, 32, mode="solid", rule="parity", supersample=1, ctx=gl)
    c = parity.centres()
    lens = (da(c) < -0.05) & (db(c) < -0.05)  # well inside both: two crossings above
    assert lens.sum() > 100 and (parity.inside[lens] == 0).all()
    only_a = (da(c) < -0.05) & (db(c) > 0.05)
    assert (parity.inside[only_a] == 1).all()


def test_box_partly_outside_the_grid_counts_surfaces_above(gl):
    # the sphere's top is above the box: the winding still comes from the surfaces up there
    box_to_world = np.diag([2.0, 2.0, 1.0, 1.0])
    box_to_world[:3, 3] = [-1, -1, -0.8]
    mesh = render_mesh(sphere(0.8))
    grid = voxelize(mesh, box_to_world, (32, 32, 16), mode="solid", supersample=1, ctx=gl)
    check_solid(grid, sphere_distance((0, 0, 0), 0.8), centre_tolerance=0.05)
    assert grid.occupancy[-1].sum() > 100  # the top layer is inside the sphere


# -- surfaces ---------------------------------------------------------------------------

@pytest.mark.parametrize("axis", [0, 1, 2])
def test_plane_marks_exactly_its_voxel_layer(gl, axis):
    size = (16, 12, 20)  # W, H, D: a different count per axis
    n = size[axis]
    layer = 7
    grid = voxelize(plane_quad(axis, (layer + 0.3) / n), UNIT, size, ctx=gl)
    expected = np.zeros((20, 12, 16), bool)
    index = [slice(None)] * 3
    index[2 - axis] = layer  # arrays are [h, v, u]
    expected[tuple(index)] = True
    np.testing.assert_array_equal(grid.occupancy > 0, expected)
    np.testing.assert_array_equal(grid.occupancy[expected], 1.0)  # every line crosses it
    assert grid.inside is None
    normal = np.zeros(3)
    normal[axis] = 1.0
    np.testing.assert_allclose(np.abs(grid.normal[expected]), np.tile(normal, (expected.sum(),
                                                                              1)), atol=1e-6)


@pytest.mark.parametrize("mode", ["surface", "solid"])
def test_thin_closed_slab_marks_one_layer(gl, mode):
    # a closed slab 0.3 voxels thick inside layer 5 of 16 along v
    mesh = faceted_box((1.4, 0.3 / 16, 1.4), (0.5, 5.5 / 16, 0.5))
    grid = voxelize(mesh, UNIT, 16, mode=mode, ctx=gl)
    occupied = np.argwhere(grid.occupancy > 0)
    assert set(occupied[:, 1]) == {5}
    assert len(occupied) == 16 * 16


def test_tilted_plane_lies_between_the_naive_and_the_conservative_layer(gl):
    n = np.array([0.3, 0.5, 0.81])
    n /= np.linalg.norm(n)
    point = np.array([0.5, 0.47, 0.52])
    size = np.array([24, 20, 28])
    # a big quad in the plane, centred on the box
    t1 = np.cross(n, [1.0, 0, 0])
    t1 /= np.linalg.norm(t1)
    t2 = np.cross(n, t1)
    corners = [point + 2 * (a * t1 + b * t2) for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    grid = voxelize(quad(corners), UNIT, tuple(size), supersample=2, ctx=gl)
    marked = grid.occupancy > 0
    c = grid.centres() - point
    voxel = 1.0 / size  # (u, v, h)
    # conservative: the voxel cell touches the plane (plane / box overlap test)
    conservative = np.abs(c @ n) <= 0.5 * (np.abs(n) * voxel).sum() + 1e-9
    # naive: along the dominant axis (h), each column's voxel holding the crossing
    naive = np.zeros_like(marked)
    k, j, i = np.meshgrid(*(np.arange(s) for s in size[::-1]), indexing="ij")
    uu, vv = (i[0] + 0.5) / size[0], (j[0] + 0.5) / size[1]
    hh = point[2] - (n[0] * (uu - point[0]) + n[1] * (vv - point[1])) / n[2]
    layer = np.floor(hh * size[2]).astype(int)
    ok = (layer >= 0) & (layer < size[2])
    naive[layer[ok], j[0][ok], i[0][ok]] = True
    assert not (marked & ~conservative).any(), "a marked voxel does not touch the plane"
    assert not (naive & ~marked).any(), "a column crossing was missed"
    assert marked.sum() > naive.sum()  # the side sweeps add the voxels the h lines skip


def test_geometry_in_one_corner_lands_at_the_right_index(gl):
    # a small cube at high u, low v, middle h; box (W, H, D) = (20, 16, 12)
    lo = np.array([0.81, 0.05, 0.40])
    hi = np.array([0.93, 0.30, 0.60])
    mesh = faceted_box(hi - lo, (lo + hi) / 2)
    for mode in ("surface", "solid"):
        grid = voxelize(mesh, UNIT, (20, 16, 12), mode=mode, ctx=gl)
        k, j, i = np.nonzero(grid.occupancy > 0)
        assert (i.min(), i.max()) == (16, 18)   # u in [0.81, 0.93] of 20
        assert (j.min(), j.max()) == (0, 4)     # v in [0.05, 0.30] of 16
        assert (k.min(), k.max()) == (4, 7)     # h in [0.40, 0.60] of 12


def test_two_colours_land_in_their_voxels(gl):
    red = faceted_box((0.6, 0.6, 0.6), (-0.5, 0.0, 0.0), color=(1.0, 0.0, 0.0, 1.0))
    blue = faceted_box((0.6, 0.6, 0.6), (0.5, 0.0, 0.0), color=(0.0, 0.0, 1.0, 0.5))
    both = RenderMesh(np.vstack([red.positions, blue.positions]),
                      np.vstack([red.indices, blue.indices + len(red.positions)]),
                      np.vstack([red.normals, blue.normals]),
                      np.vstack([red.colors, blue.colors]),
                      materials=(Material(alpha_mode="BLEND"),))  # vertex alpha counts
    for mode in ("surface", "solid"):
        grid = voxelize(both, CUBE, 32, mode=mode, ctx=gl)
        x = grid.centres()[..., 0]
        occupied = grid.occupancy > 0
        assert_all_close(grid.color[occupied & (x < 0)], [1, 0, 0, 1], 1e-6)
        # straight alpha: the rgb is not darkened by the alpha of 0.5
        assert_all_close(grid.color[occupied & (x > 0)], [0, 0, 1, 0.5], 1e-6)
        np.testing.assert_array_equal(grid.color[~occupied], 0.0)
        if mode == "solid":  # interior voxels copy the surface
            assert (grid.inside[occupied & (x < 0)] == 1).sum() > 500


def test_texture_colours_are_sampled_linear(gl):
    texture = np.zeros((8, 8, 4), np.uint8)
    texture[..., 3] = 255
    texture[:, :4, 0] = 255    # left half (u < 0.5) red
    texture[:, 4:, 1] = 188    # right half green, sRGB 188 = linear 0.5029
    corners = [[0, 0, 0.5], [1, 0, 0.5], [1, 1, 0.5], [0, 1, 0.5]]
    uvs = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float32)
    grid = voxelize(quad(corners, uvs=uvs, texture=texture), UNIT, (16, 16, 8), ctx=gl)
    layer = grid.color[4]  # h = 0.5 lies in layer 4 of 8
    assert (grid.occupancy[4] == 1).all()
    # away from the middle and the borders (the texture repeats, so u = 0 blends with u = 1)
    assert_all_close(layer[:, 1:6], [1, 0, 0, 1], 2e-3)
    assert_all_close(layer[:, 10:15], [0, 0.5029, 0, 1], 2e-3)


def test_transparent_texels_are_holes(gl):
    texture = np.full((8, 8, 4), 255, np.uint8)
    texture[:, 4:, 3] = 0      # right half fully transparent (a cut-out leaf)
    texture[:, :4, 3] = 100    # left half partly transparent
    corners = [[0, 0, 0.5], [1, 0, 0.5], [1, 1, 0.5], [0, 1, 0.5]]
    uvs = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float32)
    leaf = quad(corners, uvs=uvs, texture=texture, alpha_mode="BLEND")
    grid = voxelize(leaf, UNIT, (16, 16, 8), supersample=1, ctx=gl)
    assert (grid.occupancy[4, :, 1:7] == 1).all()
    assert (grid.occupancy[4, :, 9:15] == 0).all()
    assert_all_close(grid.color[4, :, 1:7], [1, 1, 1, 100 / 255], 2e-3)  # straight alpha
    with pytest.raises(UsageError, match="no part of the mesh.*alpha_cutoff"):
        voxelize(leaf, UNIT, (16, 16, 8), supersample=1, alpha_cutoff=0.5, ctx=gl)
    # a closed mesh keeps its inside where the texture is transparent
    box = trimesh.creation.box(extents=(0.6, 0.6, 0.6))
    ghost = RenderMesh(box.vertices, box.faces, vertex_normals(box.vertices, box.faces),
                       np.tile([1, 1, 1, 0.0], (len(box.vertices), 1)),
                       materials=(Material(alpha_mode="BLEND"),))
    solid = voxelize(ghost, CUBE, 16, mode="solid", supersample=1, ctx=gl)
    expected = (np.abs(solid.centres()) < 0.3).all(axis=-1)
    np.testing.assert_array_equal(solid.inside > 0, expected)
    assert solid.surface.max() == 0 and (solid.occupancy == solid.inside).all()


def test_box_voxels_carry_the_face_normals(gl):
    center, extents = np.array([0.03, -0.02, 0.01]), np.array([1.2, 1.0, 1.4])
    grid = voxelize(faceted_box(extents, center), CUBE, 40, supersample=2, ctx=gl)
    occupied = grid.occupancy > 0
    q = (grid.centres() - center) / (extents / 2)  # faces at |q| = 1
    voxel = 2 / 40
    near_face = np.abs(np.abs(q) - 1) * extents / 2 < voxel  # within a voxel of a face plane
    checked = 0
    for axis in range(3):
        others = [a for a in range(3) if a != axis]
        # well inside the face: more than 1.5 voxels from the other faces' planes
        inner = np.all([(1 - np.abs(q[..., a])) * extents[a] / 2 > 1.5 * voxel
                        for a in others], axis=0)
        for sign in (-1, 1):
            sel = occupied & near_face[..., axis] & inner & (np.sign(q[..., axis]) == sign)
            expected = np.zeros(3)
            expected[axis] = sign
            assert sel.sum() > 100
            assert (grid.normal[sel] @ expected).min() > 0.9999
            checked += sel.sum()
    length = np.linalg.norm(grid.normal[occupied], axis=-1)
    np.testing.assert_allclose(length, 1.0, atol=1e-5)  # unit everywhere (edges: averaged)
    np.testing.assert_array_equal(grid.normal[~occupied], 0.0)
    assert checked > 0.5 * occupied.sum()


@pytest.mark.parametrize("s", [1, 2, 4])
def test_occupancy_is_the_covered_fraction_of_the_voxel_face(gl, s):
    # a quad in layer 2 (of 4) along h covering u up to the middle of column 3 (of 8)
    edge = 3.51 / 8  # just past the middle of column 3: its centre line is covered
    corners = [[-0.2, -0.2, 0.6], [edge, -0.2, 0.6], [edge, 1.2, 0.6], [-0.2, 1.2, 0.6]]
    grid = voxelize(quad(corners), UNIT, (8, 8, 4), supersample=s, ctx=gl)
    expected = np.zeros((4, 8, 8), np.float32)
    expected[2, :, :3] = 1.0
    expected[2, :, 3] = {1: 1.0, 2: 0.5, 4: 0.5}[s]  # lines at (a + 0.5) / s of the voxel
    np.testing.assert_array_equal(grid.occupancy, expected)


def test_drawing_every_triangle_per_slab_gives_the_same_grid(gl, monkeypatch):
    from reliefkit.bake import voxelize as module

    mesh = render_mesh(sphere(0.7, (0.1, -0.05, 0.0), subdivisions=3))
    bucketed = voxelize(mesh, CUBE, (20, 24, 16), mode="solid", ctx=gl)
    monkeypatch.setattr(module, "MAX_SLAB_ENTRIES", 0)  # the fallback for huge triangles
    unbucketed = voxelize(mesh, CUBE, (20, 24, 16), mode="solid", ctx=gl)
    np.testing.assert_array_equal(bucketed.occupancy, unbucketed.occupancy)
    np.testing.assert_allclose(bucketed.normal, unbucketed.normal, atol=1e-6)


def test_progress_reports_every_slab(gl):
    calls = []
    voxelize(render_mesh(sphere(0.5, subdivisions=2)), CUBE, (8, 6, 4), mode="solid",
             progress=lambda done, total: calls.append((done, total)), ctx=gl)
    total = 8 + 6 + 4 + 1  # slabs of the three sweeps + the surfaces above the box
    assert calls == [(i, total) for i in range(1, total + 1)]


def test_state_is_left_clean_for_the_next_renderer(gl):
    voxelize(render_mesh(sphere(0.5, subdivisions=1)), CUBE, 8, mode="solid", ctx=gl)
    assert gl.error == "GL_NO_ERROR"
    from reliefkit.gl.context import bind_home_framebuffer

    bind_home_framebuffer(gl)  # the home framebuffer is still bound and valid
    assert gl.error == "GL_NO_ERROR"


# -- refusals ---------------------------------------------------------------------------

def _mesh():
    return render_mesh(sphere(0.5, subdivisions=1))


@pytest.mark.parametrize("resolution", [(0, 4, 4), (4, 4), (4, 4, 4, 4), (4.5, 4, 4),
                                        ("a", 4, 4), True, None, -3, (1 << 13, 1 << 12, 1)])
def test_bad_resolution_is_refused(gl, resolution):
    with pytest.raises(UsageError, match="resolution|voxels"):
        voxelize(_mesh(), CUBE, resolution, ctx=gl)


def test_resolution_over_the_3d_texture_limit_is_a_gpu_error(gl):
    limit = int(gl.info["GL_MAX_3D_TEXTURE_SIZE"])
    with pytest.raises(GPUError, match="limit"):
        voxelize(_mesh(), CUBE, (limit + 1, 1, 1), ctx=gl)


@pytest.mark.parametrize(("box", "match"), [
    (np.array([[1.0, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0.5, 1]]), "projective"),
    (np.diag([1.0, 1.0, 0.0, 1.0]), "singular"),
    (np.full((4, 4), np.nan), "NaN"),
    (np.eye(3), "4x4"),
    ("box", "4x4"),
])
def test_bad_box_is_refused(gl, box, match):
    with pytest.raises(UsageError, match=match):
        voxelize(_mesh(), box, 8, ctx=gl)


@pytest.mark.parametrize(("kwargs", "match"), [
    ({"mode": "volume"}, "mode"), ({"rule": "evenodd"}, "rule"),
    ({"supersample": 0}, "supersample"), ({"supersample": 5}, "supersample"),
    ({"supersample": 1.5}, "supersample"), ({"alpha_cutoff": 1.0}, "alpha_cutoff"),
    ({"alpha_cutoff": "0.5"}, "alpha_cutoff"),
])
def test_bad_options_are_refused(gl, kwargs, match):
    with pytest.raises(UsageError, match=match):
        voxelize(_mesh(), CUBE, 8, ctx=gl, **kwargs)


def test_non_mesh_is_refused(gl):
    with pytest.raises(UsageError, match="RenderMesh"):
        voxelize(sphere(), CUBE, 8, ctx=gl)


def test_mesh_outside_the_box_is_an_error_not_an_empty_grid(gl):
    far = render_mesh(sphere(0.5, (5.0, 0, 0), subdivisions=1))
    with pytest.raises(UsageError, match="no part of the mesh"):
        voxelize(far, CUBE, 8, mode="solid", ctx=gl)


def test_every_material_lands_in_its_voxels(gl):
    """Two quads at z = -0.5 and z = +0.5, each with its own material: a textured one (a
    uniform blue image, a grey factor) and a plain red one."""
    from reliefkit.colorspace import srgb_decode
    from reliefkit.scene.mesh import Material

    quad = np.array([[-0.8, -0.8], [0.8, -0.8], [0.8, 0.8], [-0.8, 0.8]])
    pos = np.concatenate([np.c_[quad, np.full(4, z)] for z in (-0.5, 0.5)]).astype(np.float32)
    faces = np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]])
    uvs = np.tile([[0, 0], [1, 0], [1, 1], [0, 1]], (2, 1)).astype(np.float32)
    blue = np.zeros((4, 4, 4), np.uint8)
    blue[..., 2] = blue[..., 3] = 255
    materials = (Material("blue", (0.5, 0.5, 0.5, 1.0), blue), Material("red", (1, 0, 0, 1)))
    mesh = RenderMesh(pos, faces, np.tile([0, 0, 1], (8, 1)), np.ones((8, 4)), uvs=uvs,
                      materials=materials, material=np.array([0, 0, 1, 1]), name="two")
    grid = voxelize(mesh, CUBE, 16, mode="surface", ctx=gl)
    back, front = grid.color[4, 8, 8], grid.color[12, 8, 8]  # voxels at z = -0.5 and +0.5
    np.testing.assert_allclose(back, [0, 0, 0.5 * srgb_decode(1.0), 1], atol=1e-3)
    np.testing.assert_allclose(front, [1, 0, 0, 1], atol=1e-3)


@pytest.mark.parametrize("mode, expected", [("OPAQUE", 1.0), ("MASK", 0.0), ("BLEND", 0.25)])
def test_the_materials_alpha_mode_applies(gl, mode, expected):
    """As in the renderer: OPAQUE ignores alpha, MASK cuts below its cutoff, BLEND keeps it."""
    corners = [[0, 0, 0.5], [1, 0, 0.5], [1, 1, 0.5], [0, 1, 0.5]]
    leaf = quad(corners, color=(1, 1, 1, 0.25), alpha_mode=mode)
    if mode == "MASK":
        with pytest.raises(UsageError, match="no part of the mesh"):
            voxelize(leaf, UNIT, (8, 8, 4), supersample=1, ctx=gl)
        return
    grid = voxelize(leaf, UNIT, (8, 8, 4), supersample=1, ctx=gl)
    np.testing.assert_allclose(grid.color[2, 2:6, 2:6, 3], expected, atol=1e-6)
