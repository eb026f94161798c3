"""Scene-graph placement of glTF parts: positions by the node transforms, normals by the winding.

The files are built with trimesh and, for TRS nodes, edited as JSON. References are
independent of the loader: the nodes' matrices composed here (scipy rotations from the
quaternions written into the file), and each triangle's normal recomputed from its placed,
wound corners.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import trimesh
from scipy.spatial.transform import Rotation

from reliefkit.io.meshes import load_mesh


@pytest.fixture(autouse=True)
def _strict_floats():
    with np.errstate(all="raise"):
        yield


def faceted_blob() -> trimesh.Trimesh:
    """A lumpy closed surface whose triangles own their corners and carry their face normal.

    Flat normals make the reference exact: the placed triangle's winding normal is what the
    transformed file normal must be, for any invertible linear map.
    """
    sphere = trimesh.creation.icosphere(subdivisions=1)
    radii = 1.0 + 0.3 * np.sin(3.0 * sphere.vertices[:, 0]) * np.cos(2.0 * sphere.vertices[:, 1])
    corners = (sphere.vertices * radii[:, None])[sphere.faces].reshape(-1, 3)
    faces = np.arange(len(corners)).reshape(-1, 3)
    tri = corners[faces]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    return trimesh.Trimesh(corners, faces, vertex_normals=np.repeat(normal, 3, axis=0),
                           process=False)


def winding_normals(positions: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """Per-corner unit normals of each triangle, from its corners in their order."""
    tri = positions.astype(np.float64)[indices.astype(np.int64)]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    return np.repeat(n / np.linalg.norm(n, axis=1, keepdims=True), 3, axis=0)


def assert_normals_follow_winding(mesh_out) -> None:
    corners = mesh_out.indices.reshape(-1)
    expected = winding_normals(mesh_out.positions, mesh_out.indices)
    got = mesh_out.normals[corners].astype(np.float64)
    worst = np.linalg.norm(got - expected, axis=1).max()
    assert worst < 1e-4, f"normals differ from the winding by up to {worst:.3g}"


def trs(translation=(0.0, 0.0, 0.0), rotation=(0.0, 0.0, 0.0, 1.0), scale=(1.0, 1.0, 1.0)):
    """The glTF node matrix T * R * S, with R from the (x, y, z, w) quaternion (scipy)."""
    m = np.eye(4)
    m[:3, :3] = Rotation.from_quat(rotation).as_matrix() @ np.diag(scale)
    m[:3, 3] = translation
    return m


def quaternion(axis, degrees) -> list[float]:
    return Rotation.from_rotvec(np.radians(degrees) * np.asarray(axis, float)
                                / np.linalg.norm(axis)).as_quat().tolist()


ROTATIONS = {
    "x90": ([1, 0, 0], 90),
    "y30": ([0, 1, 0], 30),
    "z135": ([0, 0, 1], 135),
    "oblique60": ([1, 2, -0.5], 60),
    "oblique200": ([-0.3, 1, 0.7], 200),
}

MATRICES = {
    **{f"rotate_{k}": trs(rotation=quaternion(*v)) for k, v in ROTATIONS.items()},
    "scale_nonuniform": trs(scale=(2.0, 0.5, 1.5)),
    "rotate_and_scale": trs((1, -2, 3), quaternion([1, 1, 0], 45), (0.5, 3.0, 1.2)),
    "mirror_x": trs(scale=(-1.0, 1.0, 1.0)),
    "mirror_and_rotate": trs((0, 1, 0), quaternion([0, 1, 1], 110), (1.0, -2.0, 0.7)),
}


@pytest.mark.parametrize("name", MATRICES)
def test_glb_node_matrix_places_positions_and_normals(tmp_path, name):
    matrix = MATRICES[name]
    blob = faceted_blob()
    scene = trimesh.Scene()
    scene.add_geometry(blob, transform=matrix)
    scene.export(str(tmp_path / f"{name}.glb"))
    mesh_out = load_mesh(tmp_path / f"{name}.glb")

    expected = trimesh.transform_points(blob.vertices, matrix)
    got = np.unique(mesh_out.positions.round(4), axis=0)
    np.testing.assert_allclose(got, np.unique(expected.round(4), axis=0), atol=2e-4)
    assert_normals_follow_winding(mesh_out)


def gltf_with_nodes(tmp_path, nodes: list[dict]) -> tuple:
    """A .gltf of `faceted_blob` whose node list is replaced by `nodes` (mesh 0 on each leaf)."""
    path = tmp_path / "nodes.gltf"
    blob = faceted_blob()
    trimesh.Scene(blob).export(str(path))
    tree = json.loads(path.read_text())
    tree["nodes"] = nodes
    roots = set(range(len(nodes))) - {c for n in nodes for c in n.get("children", [])}
    tree["scenes"] = [{"nodes": sorted(roots)}]
    tree["scene"] = 0
    path.write_text(json.dumps(tree))
    return path, blob


def test_gltf_trs_nodes_in_a_hierarchy(tmp_path):
    parent = {"translation": [3.0, 0.0, -1.0], "rotation": quaternion([0, 1, 0], 70),
              "scale": [1.0, 2.0, 1.0], "children": [1]}
    child = {"mesh": 0, "rotation": quaternion([1, 0, 0.5], -40), "scale": [0.5, 1.0, 1.5],
             "translation": [0.0, 1.0, 0.0]}
    path, blob = gltf_with_nodes(tmp_path, [parent, child])
    mesh_out = load_mesh(path)

    matrix = trs(parent["translation"], parent["rotation"], parent["scale"]) @ trs(
        child["translation"], child["rotation"], child["scale"])
    expected = trimesh.transform_points(blob.vertices, matrix)
    got = np.unique(mesh_out.positions.round(4), axis=0)
    np.testing.assert_allclose(got, np.unique(expected.round(4), axis=0), atol=2e-4)
    assert_normals_follow_winding(mesh_out)


def test_the_same_mesh_under_two_rotated_nodes(tmp_path):
    nodes = [{"mesh": 0, "rotation": quaternion([0, 0, 1], 90)},
             {"mesh": 0, "rotation": quaternion([1, 0, 0], -90), "translation": [5.0, 0, 0]}]
    path, _ = gltf_with_nodes(tmp_path, nodes)
    mesh_out = load_mesh(path)
    assert mesh_out.triangle_count == 2 * len(faceted_blob().faces)
    assert_normals_follow_winding(mesh_out)


def test_closed_rotated_surface_normals_point_outwards(tmp_path):
    """The classic symptom: a rotated closed mesh lit from behind (normals pointing inwards)."""
    path, _ = gltf_with_nodes(tmp_path, [{"mesh": 0, "rotation": quaternion([1, 1, 1], 120)}])
    mesh_out = load_mesh(path)
    outward = mesh_out.positions - mesh_out.positions.mean(axis=0)
    assert ((outward * mesh_out.normals).sum(axis=1) > 0).all()
