"""The billboard cloud generator, checked against the geometry itself: vertex distances to the
planes, meshes made of known planes, and rectangles computed by hand."""

from __future__ import annotations

import math

import numpy as np
import pytest

from reliefkit.errors import UsageError
from reliefkit.scene.assets import make_asset
from reliefkit.scene.mesh import RenderMesh, vertex_normals
from reliefkit.techniques.billboard.cloud import (
    _diagonal,
    _Faces,
    _Grid,
    _hemisphere_directions,
    _Selector,
    build_billboard_cloud,
)


def mesh_of(points, indices, name="test") -> RenderMesh:
    points = np.asarray(points, dtype=np.float64)
    indices = np.asarray(indices)
    return RenderMesh(points, indices, vertex_normals(points, indices),
                      np.ones((len(points), 4)), name=name)


def box(low=(0.0, 0.0, 0.0), high=(1.0, 1.0, 1.0)) -> RenderMesh:
    """An axis-aligned box, 12 outward-facing (counter-clockwise) triangles."""
    lo, hi = np.asarray(low, float), np.asarray(high, float)
    corners = np.array([[(lo, hi)[(i >> a) & 1][a] for a in range(3)] for i in range(8)])
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    tris = [t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))]
    return mesh_of(corners, tris, "box")


def uv_sphere(rings=24, segments=48) -> RenderMesh:
    theta = np.linspace(0, np.pi, rings + 1)[1:-1]
    phi = np.arange(segments) * 2 * np.pi / segments
    pts = [[0, 0, 1]] + [[math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)]
                         for t in theta for p in phi] + [[0, 0, -1]]
    tris = [(0, 1 + j, 1 + (j + 1) % segments) for j in range(segments)]
    for r in range(rings - 2):
        for j in range(segments):
            a, b = 1 + r * segments + j, 1 + r * segments + (j + 1) % segments
            tris += [(a, a + segments, b), (b, a + segments, b + segments)]
    last, base = len(pts) - 1, 1 + (rings - 2) * segments
    tris += [(base + j, last, base + (j + 1) % segments) for j in range(segments)]
    return mesh_of(pts, tris, "sphere")


def grid_rectangle(width, height, cols, rows, rotation, normal_tilt=0.4, origin=(5, -3, 2)):
    """A width x height rectangle of 2*cols*rows triangles, rotated in its (tilted) plane."""
    s, t = np.meshgrid(np.linspace(0, width, cols + 1), np.linspace(0, height, rows + 1))
    c, r = math.cos(rotation), math.sin(rotation)
    x, y = c * s - r * t, r * s + c * t
    e1 = np.array([1.0, 0.0, 0.0])
    e2 = np.array([0.0, math.cos(normal_tilt), math.sin(normal_tilt)])
    pts = np.asarray(origin) + x.reshape(-1, 1) * e1 + y.reshape(-1, 1) * e2
    tris = []
    for j in range(rows):
        for i in range(cols):
            a = j * (cols + 1) + i
            tris += [(a, a + 1, a + cols + 2), (a, a + cols + 2, a + cols + 1)]
    corners = np.asarray(origin) + np.array(
        [[0, 0], [width, 0], [width, height], [0, height]]) @ np.array([[c, r], [-r, c]]) \
        @ np.stack([e1, e2])
    return mesh_of(pts, tris, "rectangle"), corners


MESHES = {"tree": lambda: make_asset("tree"), "vehicle": lambda: make_asset("vehicle"),
          "blob": lambda: make_asset("blob"), "sphere": uv_sphere}


def vertex_distances(mesh: RenderMesh, plan) -> np.ndarray:
    """|distance| of every vertex of every face to its assigned plane, (F, 3)."""
    tri = mesh.world_positions[mesh.indices.astype(np.int64)]
    normals = np.array([p.normal for p in plan.planes])[plan.face_plane]
    offsets = np.array([p.offset for p in plan.planes])[plan.face_plane]
    return np.abs(np.einsum("fvk,fk->fv", tri, normals) - offsets[:, None])


@pytest.mark.parametrize("name,epsilon", [("tree", 0.05), ("tree", 0.1), ("vehicle", 0.05),
                                          ("vehicle", 0.1), ("sphere", 0.05), ("sphere", 0.1),
                                          ("blob", 0.1), ("blob", 0.2)])
def test_every_face_is_within_epsilon_of_its_plane_and_inside_its_rectangle(name, epsilon):
    mesh = MESHES[name]()
    plan = build_billboard_cloud(mesh, epsilon)
    low, high = mesh.bounds
    assert plan.epsilon == pytest.approx(epsilon * np.linalg.norm(high - low))
    assert len(plan.skipped) == 0 and plan.summary()["skipped"] == 0
    assert plan.face_plane.shape == (mesh.triangle_count,) and plan.face_plane.min() >= 0
    assert vertex_distances(mesh, plan).max() <= plan.epsilon
    listed = np.concatenate([p.faces for p in plan.planes])
    assert np.array_equal(np.sort(listed), np.arange(mesh.triangle_count))  # each face once
    tri = mesh.world_positions[mesh.indices.astype(np.int64)]
    for k, plane in enumerate(plan.planes):
        assert np.all(plan.face_plane[plane.faces] == k)
        st = plane.world_to_plane(tri[plane.faces].reshape(-1, 3))
        assert st[:, :2].min() >= -1e-9 and st[:, :2].max() <= 1 + 1e-9


def test_a_box_gives_its_six_face_planes():
    mesh = box((3.0, -2.0, 5.0), (5.0, -1.0, 5.5))
    plan = build_billboard_cloud(mesh, 0.05)
    assert len(plan.planes) == 6
    expected = {(tuple(n), o) for n, o in [
        ((1, 0, 0), 5.0), ((-1, 0, 0), -3.0), ((0, 1, 0), -1.0), ((0, -1, 0), 2.0),
        ((0, 0, 1), 5.5), ((0, 0, -1), -5.0)]}
    got = set()
    for plane in plan.planes:
        assert len(plane.faces) == 2
        got.add((tuple(np.round(plane.normal, 9) + 0.0), round(plane.offset, 9)))
    assert got == expected          # outward normals: the planes face like their faces


def test_a_folded_card_gives_two_planes():
    fold = math.radians(60)
    flap = np.array([0.0, math.sin(fold), math.cos(fold)])
    pts = [[0, 0, 0], [1, 0, 0], [1, 0, 1], [0, 0, 1], [1, 0, 0] + flap, [0, 0, 0] + flap]
    mesh = mesh_of(pts, [(0, 1, 2), (0, 2, 3), (1, 0, 5), (1, 5, 4)], "card")
    plan = build_billboard_cloud(mesh, 0.05)
    assert len(plan.planes) == 2
    groups = sorted(tuple(p.faces.tolist()) for p in plan.planes)
    assert groups == [(0, 1), (2, 3)]


def test_a_single_quad_gives_one_plane_whose_rectangle_is_the_quad():
    mesh, _ = grid_rectangle(2.0, 1.0, 1, 1, rotation=0.3)
    corners = mesh.world_positions                      # as stored (float32 relative)
    plan = build_billboard_cloud(mesh, 0.05)
    (plane,) = plan.planes
    texel = plan.texel_size
    rect = plane.corner + np.array([[0, 0], [1, 0], [1, 1], [0, 1]]) @ np.stack(
        [plane.u_axis, plane.v_axis])
    # each rectangle corner is a quad corner moved out by half a texel along both sides
    for point in rect:
        assert np.linalg.norm(corners - point, axis=1).min() <= texel / math.sqrt(2) + 1e-6
    sides = sorted([np.linalg.norm(plane.u_axis), np.linalg.norm(plane.v_axis)])
    assert sides == pytest.approx([1.0 + texel, 2.0 + texel], abs=1e-6)


def test_the_rectangle_of_a_rotated_rectangle_of_faces_is_tight():
    mesh, corners = grid_rectangle(3.0, 1.0, 12, 5, rotation=math.radians(30))
    plan = build_billboard_cloud(mesh, 0.05, texel_size=0.01)
    (plane,) = plan.planes
    area = np.linalg.norm(np.cross(plane.u_axis, plane.v_axis))
    assert area == pytest.approx((3.0 + 0.01) * (1.0 + 0.01), rel=0.02)
    assert plane.resolution == tuple(math.ceil(np.linalg.norm(a) / 0.01 - 1e-9)
                                     for a in (plane.u_axis, plane.v_axis))


def test_plane_frames_are_unit_orthogonal_and_right_handed():
    mesh = make_asset("vehicle")
    plan = build_billboard_cloud(mesh, 0.1)
    points = mesh.world_positions[:50]
    for plane in plan.planes:
        assert np.linalg.norm(plane.normal) == pytest.approx(1.0)
        assert abs(plane.u_axis @ plane.v_axis) < 1e-9
        assert np.cross(plane.u_axis, plane.v_axis) @ plane.normal > 0
        assert min(plane.resolution) >= 1
        coords = plane.world_to_plane(points)
        assert np.allclose(plane.plane_to_world(coords), points)
        assert np.allclose(coords[:, 2], points @ plane.normal - plane.offset)


def test_two_runs_give_identical_planes():
    first, second = (build_billboard_cloud(make_asset("tree"), 0.05) for _ in range(2))
    assert np.array_equal(first.face_plane, second.face_plane)
    assert len(first.planes) == len(second.planes)
    for a, b in zip(first.planes, second.planes, strict=True):
        for attr in ("normal", "offset", "faces", "corner", "u_axis", "v_axis", "resolution"):
            assert np.array_equal(getattr(a, attr), getattr(b, attr)), attr


def test_max_planes_stops_early_and_reports_the_skipped_faces():
    calls = []
    plan = build_billboard_cloud(box(), 0.05, max_planes=1,
                                 progress=lambda done, total: calls.append((done, total)))
    assert len(plan.planes) == 1 and len(plan.planes[0].faces) == 2
    assert sorted(plan.skipped.tolist()) == sorted(set(range(12)) - set(plan.planes[0].faces))
    assert np.all(plan.face_plane[plan.skipped] == -1)
    summary = plan.summary()
    assert summary["skipped"] == 10 and "max_planes" in summary["skipped_reason"]
    assert calls[0] == (0, 12) and calls[-1] == (2, 12)


def test_zero_area_faces_join_a_plane_they_lie_on():
    full = box()
    pts = np.concatenate([full.world_positions, [[0.2, 0.3, 1.0], [0.6, 0.3, 1.0]]])
    tris = np.concatenate([full.indices, [[8, 9, 9], [8, 8, 8]]])      # a segment, a point
    plan = build_billboard_cloud(mesh_of(pts, tris), 0.05)
    assert len(plan.planes) == 6 and len(plan.skipped) == 0
    top = plan.planes[plan.face_plane[12]]
    assert plan.face_plane[13] == plan.face_plane[12]
    assert np.allclose(top.normal, [0, 0, 1]) and top.offset == pytest.approx(1.0)


@pytest.mark.parametrize("kwargs,message", [
    ({"epsilon": 0}, "epsilon"), ({"epsilon": -0.1}, "epsilon"), ({"epsilon": 0.6}, "epsilon"),
    ({"epsilon": float("nan")}, "epsilon"), ({"epsilon": True}, "epsilon"),
    ({"epsilon": "0.1"}, "epsilon"), ({"max_planes": 0}, "max_planes"),
    ({"max_planes": 1.5}, "max_planes"), ({"max_planes": True}, "max_planes"),
    ({"texel_size": 0}, "texel_size"), ({"texel_size": -1.0}, "texel_size"),
    ({"texel_size": float("inf")}, "texel_size"), ({"direction_step": 0}, "direction_step"),
    ({"rho_step": 2}, "rho_step"), ({"penalty_weight": -1}, "penalty_weight"),
])
def test_bad_parameters_are_usage_errors(kwargs, message):
    with pytest.raises(UsageError, match=message) as info:
        build_billboard_cloud(box(), **kwargs)
    assert "\n" not in str(info.value)


def test_removing_faces_leaves_the_density_of_the_rest():
    """Both ways of removing a plane's faces (subtracting them, or rebuilding from the rest
    when that is fewer faces) give the density of the remaining faces alone."""
    mesh = uv_sphere(12, 24)
    diag = _diagonal(mesh)
    faces = _Faces(mesh, 0.05 * diag)

    def grid():
        return _Grid(faces, _hemisphere_directions(0.1), 0.1, diag, 0.025 * diag, 10.0)

    everything = np.arange(faces.count)
    for cut in (faces.count // 4, 3 * faces.count // 4):     # subtract, then rebuild
        removed, rest = everything[:cut], everything[cut:]
        g = grid()
        g.remove(removed, rest)
        fresh = grid()
        fresh.diff[:] = 0.0
        fresh._update(rest, 1.0)
        scale = np.abs(fresh.diff).max()
        assert np.allclose(g.diff, fresh.diff, rtol=0, atol=1e-9 * scale)


def test_the_density_is_every_faces_gain_and_penalty_bin_by_bin():
    """The difference arrays' density against a direct sum over (face, direction, bin): +area
    x |cos| where the bin's rho is valid for the face (every vertex within epsilon), -10x
    that on the outer miss band (the plane would be valid moved outwards by < epsilon), for
    faces that fit in 2 epsilon. Bin coordinates in float32, as the grid rounds them."""
    mesh = uv_sphere(8, 16)
    diag = _diagonal(mesh)
    faces = _Faces(mesh, 0.05 * diag)
    g = _Grid(faces, _hemisphere_directions(0.1), 0.1, diag, 0.025 * diag, 10.0)
    eps = np.float32(faces.eps / g.width)
    proj = (faces.tri / g.width).astype(np.float32) @ g.dirs32.T          # (F, 3, D)
    low = proj.min(axis=1) + np.float32(-g.start / g.width)          # (F, D) bin units
    high = proj.max(axis=1) + np.float32(-g.start / g.width)
    gain = faces.area[:, None] * np.abs(faces.normal @ g.dirs.T) * (high - low <= 2 * eps)
    k = np.arange(g.bins, dtype=np.float32)[None, None, :]
    low, high, gain = low[..., None], high[..., None], gain[..., None]
    valid = (k >= high - eps) & (k <= low + eps)
    outer = (k >= g.first_outer) & (k >= high - 2 * eps) & (k < high - eps)
    inner = (k < g.first_outer) & (k > low + eps) & (k <= low + 2 * eps)
    expected = (gain * (valid - 10.0 * (outer | inner))).sum(axis=0)   # (D, bins)
    density = np.cumsum(g.diff[:, :-1], axis=1)
    assert np.abs(expected).max() > 0 and (outer | inner).any()
    np.testing.assert_allclose(density, expected, rtol=0, atol=1e-5 * np.abs(expected).max())


def test_the_rho_sweep_finds_the_highest_density_in_its_window():
    """The windowed sweep against the penalized density evaluated face by face."""
    mesh = make_asset("vehicle")
    diag = _diagonal(mesh)
    faces = _Faces(mesh, 0.05 * diag)
    grid = _Grid(faces, _hemisphere_directions(0.2), 0.2, diag, 0.025 * diag, 10.0)
    selector = _Selector(faces, grid)
    live = np.flatnonzero(~faces.degenerate)
    near = (faces.tri[live], faces.normal[live], faces.area[live])
    eps = faces.eps

    def density(normal, rho):
        low, high = faces.extent(live, normal)
        lo, hi = high - eps, low + eps
        gain = np.where(lo < hi, faces.area[live] * np.abs(faces.normal[live] @ normal), 0.0)
        band = ((lo > 0) & (np.maximum(lo - eps, 0) <= rho) & (rho < lo)) \
            | ((hi < 0) & (hi < rho) & (rho <= np.minimum(hi + eps, 0)))
        return float(gain @ ((lo <= rho) & (rho <= hi)) - 10.0 * gain @ band)

    rng = np.random.default_rng(3)
    for _ in range(5):
        normal = rng.normal(size=3)
        normal /= np.linalg.norm(normal)
        centre = rng.uniform(-0.3, 0.3) * diag
        window = (centre - 2 * eps, centre + eps)
        value, rho = selector._best_rho(near, normal, window)
        assert window[0] <= rho <= window[1]
        assert value == pytest.approx(density(normal, rho), rel=1e-9, abs=1e-12)
        samples = np.linspace(*window, 301)
        assert max(density(normal, r) for r in samples) <= value + 1e-9 * abs(value) + 1e-12


@pytest.mark.parametrize("shape", ["disc", "square", "circle", "segment", "grid"])
def test_the_convex_hull_keeps_exactly_the_hull_vertices(shape):
    """The interior filter never drops a hull vertex: the hull matches qhull's."""
    from scipy.spatial import ConvexHull

    from reliefkit.techniques.billboard.rectangles import convex_hull_2d

    rng = np.random.default_rng(7)
    if shape == "disc":
        r, a = np.sqrt(rng.uniform(size=4000)), rng.uniform(0, 2 * np.pi, 4000)
        pts = np.stack([r * np.cos(a), r * np.sin(a)], axis=1)
    elif shape == "square":
        pts = rng.uniform(-1, 1, (4000, 2))
    elif shape == "circle":
        a = rng.uniform(0, 2 * np.pi, 500)
        pts = np.stack([np.cos(a), np.sin(a)], axis=1)
    elif shape == "segment":
        pts = np.outer(rng.uniform(size=50), [2.0, 1.0])
    else:
        pts = np.stack(np.meshgrid(np.arange(7.0), np.arange(5.0)), axis=-1).reshape(-1, 2)
    hull = convex_hull_2d(pts)
    if shape == "segment":
        assert len(hull) == 2 and set(map(tuple, hull)) == {tuple(pts.min(0)), tuple(pts.max(0))}
        return
    expected = pts[ConvexHull(pts).vertices]
    assert set(map(tuple, hull)) == set(map(tuple, expected))
    turn = [(b - a)[0] * (c - b)[1] - (b - a)[1] * (c - b)[0] for a, b, c in
            zip(hull, np.roll(hull, -1, 0), np.roll(hull, -2, 0), strict=True)]
    assert min(turn) > 0                       # counter-clockwise, no collinear vertices
