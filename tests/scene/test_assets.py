"""Tests of the procedural demo assets (reliefkit.scene.assets) with independent geometry checks."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from reliefkit.errors import UsageError
from reliefkit.scene import assets
from reliefkit.scene.mesh import RenderMesh

FACTORIES = {
    "terrain": assets.terrain,
    "blob": assets.blob,
    "tree": assets.tree,
    "vehicle": assets.vehicle,
}
TRIANGLE_BUDGET = {"terrain": 2 * 127**2, "blob": 40_000, "tree": 20_000, "vehicle": 20_000}


@pytest.fixture(autouse=True)
def _strict_float():
    """Floating-point errors (overflow, underflow, invalid, divide) raise."""
    old = np.seterr(all="raise")
    yield
    np.seterr(**old)


@pytest.fixture(scope="module")
def meshes() -> dict[str, RenderMesh]:
    with np.errstate(all="raise"):
        return {name: assets.make_asset(name) for name in assets.ASSET_NAMES}


# ----------------------------------------------------------------------------- helpers


def face_normals(positions: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """Unnormalised face normals (length = twice the area), float64."""
    p = positions.astype(np.float64)[indices.astype(np.int64)]
    return np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])


def signed_volume(positions: np.ndarray, indices: np.ndarray) -> float:
    p = positions.astype(np.float64)[indices.astype(np.int64)]
    return float(np.einsum("ij,ij->i", p[:, 0], np.cross(p[:, 1], p[:, 2])).sum() / 6.0)


def is_closed_and_oriented(indices: np.ndarray, vertex_count: int) -> bool:
    """Every edge is used by exactly two triangles, once in each direction."""
    t = indices.astype(np.int64)
    a = np.concatenate([t[:, 0], t[:, 1], t[:, 2]])
    b = np.concatenate([t[:, 1], t[:, 2], t[:, 0]])
    code, reverse = a * vertex_count + b, b * vertex_count + a
    return len(np.unique(code)) == len(code) and bool(np.isin(reverse, code).all())


def weld(positions: np.ndarray, indices: np.ndarray, tol: float = 1e-5) -> np.ndarray:
    """Indices re-pointed so that vertices closer than `tol` share one index."""
    pairs = cKDTree(positions).query_pairs(tol, output_type="ndarray")
    n = len(positions)
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    _, labels = connected_components(graph, directed=False)
    return labels[indices.astype(np.int64)]


def part_triangles(mesh: RenderMesh, closed: bool | None = None, name: str | None = None):
    """Yield (name, indices) of the mesh's parts, filtered by closedness and/or name."""
    for part in mesh.extra["parts"]:
        if closed is not None and part["closed"] != closed:
            continue
        if name is not None and part["name"] != name:
            continue
        start, stop = part["triangles"]
        yield part["name"], mesh.indices[start:stop]


def crossings(mesh: RenderMesh, axis: int, points: np.ndarray) -> np.ndarray:
    """How many triangles each axis-parallel line (through 2D `points`) passes through.

    The line along `axis` through (a, b) in the other two coordinates (in increasing axis
    order) crosses a triangle when the point lies strictly inside the triangle's projection.
    """
    others = [k for k in range(3) if k != axis]
    tri = mesh.positions.astype(np.float64)[mesh.indices.astype(np.int64)][:, :, others]
    p0, p1, p2 = tri[:, 0], tri[:, 1], tri[:, 2]

    def edge(a, b, q):  # (F,) x (P,) signed areas of (a, b, q)
        return (b[:, 0] - a[:, 0])[:, None] * (q[None, :, 1] - a[:, 1][:, None]) - (
            b[:, 1] - a[:, 1]
        )[:, None] * (q[None, :, 0] - a[:, 0][:, None])

    counts = np.zeros(len(points), dtype=np.int64)
    for start in range(0, len(points), 16):
        q = points[start : start + 16]
        w0, w1, w2 = edge(p1, p2, q), edge(p2, p0, q), edge(p0, p1, q)
        inside = ((w0 > 0) & (w1 > 0) & (w2 > 0)) | ((w0 < 0) & (w1 < 0) & (w2 < 0))
        counts[start : start + 16] = inside.sum(axis=0)
    return counts


def line_grid(mesh: RenderMesh, axis: int, n: int = 17) -> np.ndarray:
    """An n x n grid of line positions across the mesh's extent (off any symmetry plane)."""
    lo, hi = mesh.bounds
    others = [k for k in range(3) if k != axis]
    a = np.linspace(lo[others[0]], hi[others[0]], n) + 0.0031
    b = np.linspace(lo[others[1]], hi[others[1]], n) + 0.0017
    return np.stack(np.meshgrid(a, b), axis=-1).reshape(-1, 2)


# ----------------------------------------------------------------------------- every asset


def test_asset_names(meshes):
    assert list(meshes) == ["terrain", "blob", "tree", "vehicle"]
    for name, mesh in meshes.items():
        assert isinstance(mesh, RenderMesh)
        assert mesh.name == name


def test_listing_the_names_loads_no_scipy():
    """The CLI's help lists the registered names: that imports none of the heavy libraries the
    assets are built with (in a fresh interpreter, as the command runs)."""
    import subprocess
    import sys

    code = ("import sys; from reliefkit.scene.assets import DEMO_NAMES; "
            "print(len(DEMO_NAMES), sorted(m for m in ('scipy', 'skimage') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split(maxsplit=1) == [str(len(assets.DEMO_NAMES)), "[]\n"]


@pytest.mark.parametrize("name", assets.ASSET_NAMES)
def test_make_asset_matches_factory_and_is_deterministic(name, meshes):
    again = assets.make_asset(name)
    direct = FACTORIES[name]()
    for other in (again, direct):
        for field in ("positions", "indices", "normals", "colors"):
            np.testing.assert_array_equal(getattr(other, field), getattr(meshes[name], field))


@pytest.mark.parametrize("name", assets.ASSET_NAMES)
def test_different_seed_changes_the_asset(name, meshes):
    other = FACTORIES[name](seed=1)
    same_shape = other.positions.shape == meshes[name].positions.shape
    assert not same_shape or not np.array_equal(other.positions, meshes[name].positions)


@pytest.mark.parametrize("name", assets.ASSET_NAMES)
def test_valid_arrays(name, meshes):
    mesh = meshes[name]
    assert mesh.positions.dtype == np.float32 and mesh.indices.dtype == np.uint32
    assert mesh.normals.dtype == np.float32 and mesh.colors.dtype == np.float32
    # Re-validating through the constructor must succeed.
    RenderMesh(mesh.positions, mesh.indices, mesh.normals, mesh.colors, name=mesh.name)
    np.testing.assert_allclose(np.linalg.norm(mesh.normals, axis=1), 1.0, atol=1e-5)
    assert np.abs(mesh.positions).max() <= 1.1, "assets fit roughly in [-1, 1]"
    assert 0 < mesh.triangle_count <= TRIANGLE_BUDGET[name]
    # Every vertex is used.
    assert np.array_equal(np.unique(mesh.indices), np.arange(len(mesh.positions)))


@pytest.mark.parametrize("name", assets.ASSET_NAMES)
def test_colors_in_range_and_varied(name, meshes):
    colors = meshes[name].colors
    assert colors.min() >= 0.0 and colors.max() <= 1.0
    np.testing.assert_array_equal(colors[:, 3], 1.0)
    assert (colors[:, :3].std(axis=0) > 0.02).any(), "colours should not all be the same"
    assert len(np.unique(colors[:, :3].round(3), axis=0)) >= 5


@pytest.mark.parametrize("name", assets.ASSET_NAMES)
def test_vertex_normals_agree_with_winding(name, meshes):
    """Counter-clockwise front faces: the vertex normals lie on the front side of each face."""
    mesh = meshes[name]
    face = face_normals(mesh.positions, mesh.indices)
    area = np.linalg.norm(face, axis=1)
    big = area > 1e-6 * area.max()
    mean_normal = mesh.normals[mesh.indices.astype(np.int64)].sum(axis=1)
    agree = np.einsum("ij,ij->i", face[big], mean_normal[big]) > 0
    assert agree.mean() > 0.999, f"{(~agree).sum()} of {big.sum()} faces disagree"


@pytest.mark.parametrize("name", assets.ASSET_NAMES)
def test_parts_cover_the_mesh(name, meshes):
    parts = meshes[name].extra["parts"]
    ranges = [p["triangles"] for p in parts]
    assert ranges[0][0] == 0 and ranges[-1][1] == meshes[name].triangle_count
    assert all(a[1] == b[0] for a, b in zip(ranges[:-1], ranges[1:], strict=True))


@pytest.mark.parametrize("name", assets.ASSET_NAMES)
def test_closed_parts_are_closed_and_outward(name, meshes):
    mesh = meshes[name]
    closed = list(part_triangles(mesh, closed=True))
    if name == "terrain":
        assert not closed
        return
    assert closed
    n = len(mesh.positions)
    for part, tris in closed:
        # Smooth parts share vertices; flat-shaded ones are closed once coincident corners merge.
        assert is_closed_and_oriented(tris, n) or is_closed_and_oriented(
            weld(mesh.positions, tris), n
        ), part
        assert signed_volume(mesh.positions, tris) > 0, part


def test_unknown_asset_raises_usage_error():
    with pytest.raises(UsageError, match="terrain, blob, tree, vehicle"):
        assets.make_asset("nope")


@pytest.mark.parametrize(
    "call",
    [
        lambda: assets.terrain_heights(resolution=1),
        lambda: assets.terrain_heights(resolution=12.5),
        lambda: assets.terrain(size=0.0),
        lambda: assets.terrain(height=float("nan")),
        lambda: assets.blob(subdivisions=0),
        lambda: assets.blob(subdivisions=9),
        lambda: assets.tree(leaves=-1),
    ],
)
def test_bad_parameters_raise_usage_error(call):
    with pytest.raises(UsageError):
        call()


# ----------------------------------------------------------------------------- terrain


def test_terrain_heights_shape_range_and_determinism():
    h = assets.terrain_heights(64, seed=3)
    assert h.shape == (64, 64) and h.dtype == np.float32
    assert h.min() == 0.0 and h.max() == 1.0
    np.testing.assert_array_equal(h, assets.terrain_heights(64, seed=3))
    assert not np.array_equal(h, assets.terrain_heights(64, seed=4))
    assert (h == 0).mean() > 0.01, "a river of flat water at height 0"
    assert h.std() > 0.1


def test_terrain_has_a_cliff():
    h = assets.terrain_heights(128)
    step = np.maximum(np.abs(np.diff(h, axis=0)).max(), np.abs(np.diff(h, axis=1)).max())
    assert step > 0.1, "the plateau ends in a cliff a couple of texels wide"


def test_terrain_mesh_is_the_heightfield(meshes):
    mesh, r, size, height = meshes["terrain"], 128, 2.0, 0.5
    heights = assets.terrain_heights(r)
    assert len(mesh.positions) == r * r
    assert mesh.triangle_count == 2 * (r - 1) ** 2
    grid = mesh.positions.reshape(r, r, 3)
    np.testing.assert_allclose(grid[..., 1], heights * height, rtol=0, atol=1e-6)
    texel = (np.arange(r) + 0.5) / r
    np.testing.assert_allclose(grid[0, :, 0], (texel - 0.5) * size, atol=1e-6)  # x from u = i
    np.testing.assert_allclose(grid[:, 0, 2], (texel - 0.5) * size, atol=1e-6)  # z from v = j
    # Front faces point up: looking down -y sees the top.
    assert (face_normals(mesh.positions, mesh.indices)[:, 1] > 0).all()


def test_terrain_parameters():
    mesh = assets.terrain(resolution=16, seed=2, size=4.0, height=2.0)
    heights = assets.terrain_heights(16, seed=2)
    np.testing.assert_allclose(mesh.positions[:, 1], heights.ravel() * 2.0, atol=1e-6)
    np.testing.assert_allclose(mesh.bounds[:, 0], [-2.0 + 0.125, 2.0 - 0.125], atol=1e-6)


def test_terrain_colors_follow_altitude(meshes):
    mesh = meshes["terrain"]
    heights = assets.terrain_heights(128).ravel()
    water = mesh.colors[heights == 0, :3]
    high = mesh.colors[heights > 0.95, :3]
    assert (water[:, 2] > water[:, 0]).all(), "water is blue-green"
    assert high.mean() > water.mean(), "snow on top is brighter than water"


# ----------------------------------------------------------------------------- blob


def test_blob_is_watertight_with_positive_volume(meshes):
    mesh = meshes["blob"]
    assert is_closed_and_oriented(mesh.indices, len(mesh.positions))
    assert signed_volume(mesh.positions, mesh.indices) > 0.1


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_blob_is_not_a_heightfield_along_any_axis(meshes, axis):
    mesh = meshes["blob"]
    counts = crossings(mesh, axis, line_grid(mesh, axis))
    assert (counts % 2 == 0).all(), "a closed surface is crossed an even number of times"
    assert counts.max() >= 4, "some line parallel to this axis enters the solid twice"


def test_blob_is_one_solid_with_tunnels(meshes):
    """One connected surface of genus 4: the arch and the three gaps between the spokes."""
    mesh = meshes["blob"]
    t = mesh.indices.astype(np.int64)
    edges = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    edges = np.unique(edges, axis=0)
    n = len(mesh.positions)
    graph = coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(n, n))
    assert connected_components(graph, directed=False)[0] == 1
    euler = n - len(edges) + len(t)
    assert (2 - euler) // 2 == 4


def test_blob_detail_level():
    coarse = assets.blob(subdivisions=2)
    assert is_closed_and_oriented(coarse.indices, len(coarse.positions))
    assert coarse.triangle_count < assets.blob().triangle_count


# ----------------------------------------------------------------------------- tree


def test_tree_leaves_are_double_sided_quads(meshes):
    mesh = meshes["tree"]
    ((name, tris),) = part_triangles(mesh, name="leaves")
    assert len(tris) == 4 * 600  # 600 quads, two triangles each, both windings
    leaf_vertices = np.unique(tris)
    assert len(leaf_vertices) == 8 * 600
    front, back = mesh.positions[tris[0::2][:300]], mesh.positions[tris[1::2][:300]]
    assert front.shape == back.shape
    green = mesh.colors[leaf_vertices, :3]
    assert (green[:, 1] > green[:, 0]).all() and (green[:, 1] > green[:, 2]).all()


@pytest.mark.parametrize("leaves", [0, 1, 37])
def test_tree_leaf_count_parameter(leaves):
    mesh = assets.tree(seed=5, leaves=leaves)
    parts = list(part_triangles(mesh, name="leaves"))
    assert sum(len(t) for _, t in parts) == 4 * leaves
    assert len(list(part_triangles(mesh, name="trunk"))) == 1


def test_tree_trunk_is_brown_and_grounded(meshes):
    mesh = meshes["tree"]
    ((_, trunk),) = part_triangles(mesh, name="trunk")
    brown = mesh.colors[np.unique(trunk), :3]
    assert (brown[:, 0] > brown[:, 1]).all() and (brown[:, 1] > brown[:, 2]).all()
    assert mesh.bounds[0, 1] == pytest.approx(-1.0, abs=1e-6)


# ----------------------------------------------------------------------------- vehicle


def test_vehicle_is_long_along_x(meshes):
    extent = np.ptp(meshes["vehicle"].positions, axis=0)
    assert extent[0] > 1.5 * extent[1] and extent[0] > 1.5 * extent[2]
    assert meshes["vehicle"].bounds[0, 1] == pytest.approx(0.0, abs=1e-6), "wheels on y = 0"


def test_vehicle_has_parts_with_side_detail(meshes):
    mesh = meshes["vehicle"]
    names = [p["name"] for p in mesh.extra["parts"]]
    for part, count in (
        ("tyre", 4),
        ("rim", 4),
        ("window", 6),
        ("handle", 4),
        ("mirror", 6),
        ("headlight", 2),
        ("seam", 4),
    ):
        assert names.count(part) >= count, part
    assert all(p["closed"] for p in mesh.extra["parts"])


def test_vehicle_sides_are_vertical(meshes):
    """Side-facing faces are (almost all) vertical: edge-on to an orthographic top view, yet
    seen by a reverse-perspective frustum (rays spreading outwards as they go down)."""
    mesh = meshes["vehicle"]
    face = face_normals(mesh.positions, mesh.indices)
    area = np.linalg.norm(face, axis=1) / 2
    unit = face / np.maximum(2 * area, 1e-30)[:, None]
    side = np.abs(unit[:, 2]) > 0.9
    seen_from_side = (area * np.abs(unit[:, 2]))[side].sum()
    seen_from_top = (area * np.maximum(unit[:, 1], 0.0))[side].sum()
    assert seen_from_top < 0.01 * seen_from_side
    for _, tris in part_triangles(mesh, name="body"):
        n = face_normals(mesh.positions, tris)
        n /= np.linalg.norm(n, axis=1, keepdims=True)
        flank = np.abs(n[:, 2]) > 0.9
        assert flank.any() and np.abs(n[flank, 1]).max() < 1e-6
    # Sides carry detail: side-facing area of other parts standing proud of the body.
    parts = mesh.extra["parts"]
    body = np.zeros(mesh.triangle_count, dtype=bool)
    for p in parts:
        if p["name"] in ("body", "cabin"):
            body[p["triangles"][0] : p["triangles"][1]] = True
    z = mesh.positions[mesh.indices.astype(np.int64)][:, :, 2].mean(axis=1)
    proud = side & ~body & (np.abs(z) > 0.42)
    assert area[proud].sum() > 0.3
    assert (unit[proud, 2] * np.sign(z[proud]) > 0).mean() > 0.7, "details face outwards"


def test_vehicle_seed_changes_paint_or_size():
    a, b = assets.vehicle(seed=0), assets.vehicle(seed=1)
    assert not np.array_equal(a.positions, b.positions)


def test_the_cup_is_closed_and_hollow():
    from reliefkit.scene.assets.cup import FLOOR, RIM

    mesh = assets.make_asset("cup")
    assert is_closed_and_oriented(mesh.indices, len(mesh.positions))
    assert signed_volume(mesh.positions, mesh.indices) > 0
    assert np.abs(mesh.positions).max() <= 1.1
    # a vertical line through the middle meets the floor's top, not the rim: the triangles
    # above the axis point x = z = 0 lie at the floor
    p = mesh.positions.astype(np.float64)[mesh.indices.astype(np.int64)]
    near_axis = (np.abs(p[..., 0]).max(axis=1) < 0.05) & (np.abs(p[..., 2]).max(axis=1) < 0.05)
    assert near_axis.any()
    assert abs(p[near_axis][..., 1].max() - FLOOR) < 0.03 and FLOOR < RIM - 0.5
