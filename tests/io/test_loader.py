"""Tests for `reliefkit.io.meshes.load_mesh`: every format, colours, textures, bad input.

All input files are generated in tmp_path (with trimesh's exporters or written by hand).
"""

from __future__ import annotations

import json
import struct

import numpy as np
import pytest
import trimesh
from PIL import Image

from reliefkit.errors import MeshError
from reliefkit.io.meshes import SUPPORTED_EXTENSIONS, load_mesh
from reliefkit.scene.mesh import vertex_normals


@pytest.fixture(autouse=True)
def _strict_floats():
    with np.errstate(all="raise"):
        yield


# --------------------------------------------------------------------------------------
# helpers


def srgb_byte_to_linear(byte: int) -> float:
    """The sRGB decoding function, written out independently of the loader."""
    c = byte / 255.0
    if c <= 0.04045:
        return c / 12.92
    return ((c + 0.055) / 1.055) ** 2.4


def grid_mesh(n: int = 4, offset=(100.0, -50.0, 7.0), **kwargs) -> trimesh.Trimesh:
    """An n x n heightfield in the xy plane (random heights), far from the origin."""
    rng = np.random.default_rng(0)
    x, y = np.meshgrid(np.arange(n, dtype=float), np.arange(n, dtype=float))
    z = rng.uniform(0.0, 0.3, size=x.shape)
    vertices = np.column_stack([x.ravel(), y.ravel(), z.ravel()]) + offset
    faces = []
    for j in range(n - 1):
        for i in range(n - 1):
            a = j * n + i
            faces += [[a, a + 1, a + n + 1], [a, a + n + 1, a + n]]
    return trimesh.Trimesh(vertices, np.array(faces), process=False, **kwargs)


def quad(offset=(0.0, 0.0, 0.0), **kwargs) -> trimesh.Trimesh:
    vertices = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float) + offset
    return trimesh.Trimesh(vertices, [[0, 1, 2], [0, 2, 3]], process=False, **kwargs)


def write_export(geometry, path, **kwargs):
    """Export with trimesh to `path`, which also writes .mtl, textures and .bin next to it."""
    geometry.export(str(path), **kwargs)
    return path


def expect_error(path, *words):
    """load_mesh(path) raises MeshError: one line, naming the file, containing `words`."""
    with pytest.raises(MeshError) as info:
        load_mesh(path)
    message = str(info.value)
    assert "\n" not in message
    assert path.name in message
    for word in words:
        assert word.lower() in message.lower(), message
    return message


PLY_HEADER = (
    "ply\nformat ascii 1.0\nelement vertex {v}\nproperty float x\nproperty float y\n"
    "property float z\nelement face {f}\nproperty list uchar int vertex_indices\nend_header\n"
)
TRIANGLE = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]


def ply_ascii(vertices, faces) -> str:
    rows = [" ".join(map(str, v)) for v in vertices]
    rows += [" ".join(map(str, [len(f), *f])) for f in faces]
    return PLY_HEADER.format(v=len(vertices), f=len(faces)) + "\n".join(rows) + "\n"


def binary_stl(triangles) -> bytes:
    triangles = np.asarray(triangles, dtype="<f4")
    body = b"".join(
        struct.pack("<3f", 0, 0, 1) + t.tobytes() + b"\0\0" for t in triangles.reshape(-1, 9)
    )
    return b"\0" * 80 + struct.pack("<I", len(triangles)) + body


# --------------------------------------------------------------------------------------
# good files

GOOD_FORMATS = {
    "obj": ("mesh.obj", {}),
    "ply_ascii": ("mesh.ply", {"encoding": "ascii"}),
    "ply_binary": ("mesh.ply", {"encoding": "binary"}),
    "stl": ("mesh.stl", {}),
    "stl_ascii": ("mesh.stl", {"file_type": "stl_ascii"}),
    "off": ("mesh.off", {}),
    "gltf": ("mesh.gltf", {}),
    "glb": ("mesh.glb", {}),
}


@pytest.mark.parametrize("kind", GOOD_FORMATS)
def test_good_file_loads_unchanged(tmp_path, kind):
    name, kwargs = GOOD_FORMATS[kind]
    mesh = grid_mesh()
    mesh_out = load_mesh(write_export(mesh, tmp_path / name, **kwargs))

    assert mesh_out.triangle_count == len(mesh.faces)
    written = mesh.vertices[mesh.faces]  # corner positions, comparable even for STL soups
    np.testing.assert_allclose(mesh_out.positions[mesh_out.indices], written, atol=1e-4)
    if not kind.startswith("stl"):  # STL stores a triangle soup; others keep the vertices
        np.testing.assert_allclose(mesh_out.positions, mesh.vertices, atol=1e-4)
        np.testing.assert_array_equal(mesh_out.indices, mesh.faces)
    np.testing.assert_allclose(np.linalg.norm(mesh_out.normals, axis=1), 1.0, atol=1e-5)
    assert (mesh_out.normals[:, 2] > 0.5).all()  # the heightfield faces +z
    np.testing.assert_allclose(mesh_out.colors, [[0.8, 0.8, 0.8, 1.0]] * len(mesh_out.colors))
    assert mesh_out.name == "mesh"
    assert mesh_out.texture is None


def test_name_argument(tmp_path):
    path = write_export(quad(), tmp_path / "q.obj")
    assert load_mesh(path, name="bunny").name == "bunny"
    assert load_mesh(str(path)).name == "q"


OFF_FACES = {
    "quad": ("4 0 1 2 3\n", 2),
    "float colours": ("3 0 1 2 0.5 0.5 0.5\n3 0 2 3 1 0 0\n", 2),
    "mixed sizes": ("3 0 1 2\n4 0 1 2 3\n", 3),
}


@pytest.mark.parametrize("case", OFF_FACES)
def test_off_polygons_and_face_colours(tmp_path, case):
    faces, triangles = OFF_FACES[case]
    path = tmp_path / "polygons.off"
    path.write_text(f"OFF\n4 {faces.count(chr(10))} 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n{faces}")
    assert load_mesh(path).triangle_count == triangles


def test_scene_graph_transforms_are_applied(tmp_path):
    shape = quad()
    a = trimesh.transformations.translation_matrix([10.0, -3.0, 2.5])
    b = trimesh.transformations.rotation_matrix(np.pi / 2, [0, 1, 0])
    b[:3, 3] = [0.0, 5.0, 0.0]
    scene = trimesh.Scene()
    scene.add_geometry(shape, geom_name="quad", node_name="a", transform=a)
    scene.graph.update(frame_to="b", geometry="quad", matrix=b)  # a second instance
    mesh_out = load_mesh(write_export(scene, tmp_path / "scene.glb"))

    expected = np.concatenate([trimesh.transform_points(shape.vertices, m) for m in (a, b)])
    assert mesh_out.triangle_count == 4
    got = np.unique(mesh_out.positions.round(5), axis=0)
    np.testing.assert_allclose(got, np.unique(expected.round(5), axis=0), atol=1e-5)


def test_mirroring_transform_keeps_winding_and_normals_consistent(tmp_path):
    shape = quad(vertex_normals=np.tile([0.0, 0.0, 1.0], (4, 1)))
    scene = trimesh.Scene()
    scene.add_geometry(shape, transform=np.diag([-1.0, 1.0, 1.0, 1.0]))
    mesh_out = load_mesh(write_export(scene, tmp_path / "mirrored.glb"))

    np.testing.assert_allclose(mesh_out.positions[:, 0], -shape.vertices[:, 0])
    np.testing.assert_allclose(mesh_out.normals, np.tile([0.0, 0.0, 1.0], (4, 1)), atol=1e-6)
    from_winding = vertex_normals(mesh_out.positions, mesh_out.indices)
    np.testing.assert_allclose(from_winding, mesh_out.normals, atol=1e-6)


def test_file_normals_are_kept_normalized_and_zero_ones_replaced(tmp_path):
    path = tmp_path / "normals.obj"
    path.write_text(
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n"
        "vn 0 0.6 0.8\nvn 0 0 2\nvn 0 0 0\n"
        "f 1//1 2//2 3//3\nf 2//2 4//2 3//3\n"
    )
    mesh_out = load_mesh(path)
    np.testing.assert_allclose(mesh_out.normals[0], [0, 0.6, 0.8], atol=1e-6)
    np.testing.assert_allclose(mesh_out.normals[1], [0, 0, 1], atol=1e-6)
    np.testing.assert_allclose(mesh_out.normals[2], [0, 0, 1], atol=1e-6)  # computed


def test_gltf_normals_are_kept(tmp_path):
    normals = np.array([[0.0, 0.6, 0.8], [0.0, 0.0, 1.0], [0.6, 0.0, 0.8]])
    shape = trimesh.Trimesh(TRIANGLE, [[0, 1, 2]], vertex_normals=normals, process=False)
    mesh_out = load_mesh(write_export(shape, tmp_path / "n.glb"))
    np.testing.assert_allclose(mesh_out.normals, normals, atol=1e-6)


# --------------------------------------------------------------------------------------
# colours


def test_ply_vertex_colours_are_decoded_from_srgb(tmp_path):
    rng = np.random.default_rng(0)
    mesh = grid_mesh()
    rgba = rng.integers(0, 256, size=(len(mesh.vertices), 4), dtype=np.uint8)
    mesh.visual.vertex_colors = rgba
    mesh_out = load_mesh(write_export(mesh, tmp_path / "colours.ply", encoding="binary"))

    expected = np.array(
        [[srgb_byte_to_linear(int(b)) for b in row[:3]] + [row[3] / 255.0] for row in rgba]
    )
    np.testing.assert_array_equal(mesh_out.colors, expected.astype(np.float32))


def test_ply_face_colours_become_per_corner_colours(tmp_path):
    path = tmp_path / "faces.ply"
    path.write_text(
        ply_ascii([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], [])
        .replace("element face 0\nproperty list uchar int vertex_indices\n", "")
        .replace(
            "end_header",
            "element face 2\nproperty list uchar int vertex_indices\n"
            "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header",
        )
        + "3 0 1 2 255 0 0\n3 0 2 3 0 0 128\n"
    )
    mesh_out = load_mesh(path)
    assert mesh_out.triangle_count == 2
    corner_colors = mesh_out.colors[mesh_out.indices]
    np.testing.assert_allclose(corner_colors[0], np.tile([1, 0, 0, 1], (3, 1)))
    blue = srgb_byte_to_linear(128)
    np.testing.assert_allclose(corner_colors[1], np.tile([0, 0, blue, 1], (3, 1)), rtol=1e-6)


def test_gltf_vertex_colours_are_linear_already(tmp_path):
    rgba = np.array([[255, 0, 0, 255], [0, 128, 0, 255], [0, 0, 10, 100]], np.uint8)
    shape = trimesh.Trimesh(TRIANGLE, [[0, 1, 2]], vertex_colors=rgba, process=False)
    mesh_out = load_mesh(write_export(shape, tmp_path / "vc.glb"))
    np.testing.assert_allclose(mesh_out.colors, rgba / 255.0, rtol=1e-6)


def test_obj_material_diffuse_is_decoded_from_srgb(tmp_path):
    (tmp_path / "m.mtl").write_text("newmtl paint\nKd 0.5 0.25 1.0\n")
    path = tmp_path / "m.obj"
    path.write_text("mtllib m.mtl\nusemtl paint\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    mesh_out = load_mesh(path)
    c = 0.5, 0.25
    expected = [((x + 0.055) / 1.055) ** 2.4 for x in c] + [1.0, 1.0]
    assert [m.name for m in mesh_out.materials] == ["paint"]
    np.testing.assert_allclose(mesh_out.materials[0].color, expected, rtol=1e-6)
    np.testing.assert_array_equal(mesh_out.colors, 1.0)  # the file has no vertex colours


def test_gltf_base_color_factor_is_linear_already(tmp_path):
    material = trimesh.visual.material.PBRMaterial(baseColorFactor=[0.5, 0.25, 1.0, 1.0])
    shape = quad(visual=trimesh.visual.TextureVisuals(material=material))
    mesh_out = load_mesh(write_export(shape, tmp_path / "factor.glb"))
    np.testing.assert_allclose(mesh_out.materials[0].color, [0.5, 0.25, 1, 1], atol=1 / 255)
    np.testing.assert_array_equal(mesh_out.colors, 1.0)


# the 2x2 texture as PIL stores it (row 0 is the top of the picture, v = 1)
TEXTURE_TOP_DOWN = np.array(
    [[[255, 0, 0, 255], [0, 255, 0, 255]], [[0, 0, 255, 255], [255, 255, 0, 128]]], np.uint8
)
QUAD_UV = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
# the picture's corner each quad vertex maps to: bottom-left, bottom-right, top-right, top-left
CORNER_COLORS = TEXTURE_TOP_DOWN[[1, 1, 0, 0], [0, 1, 1, 0]]


def textured_quad(image=TEXTURE_TOP_DOWN, offset=(0.0, 0.0, 0.0)) -> trimesh.Trimesh:
    material = trimesh.visual.material.PBRMaterial(
        baseColorTexture=Image.fromarray(image, "RGBA"), baseColorFactor=[255, 255, 255, 255]
    )
    return quad(offset, visual=trimesh.visual.TextureVisuals(uv=QUAD_UV, material=material))


def sample_nearest(texture, uv):
    """The texel containing `uv` in a texture whose row 0 is at v = 0."""
    h, w = texture.shape[:2]
    i = np.clip(np.floor(uv[:, 0] * w).astype(int), 0, w - 1)
    j = np.clip(np.floor(uv[:, 1] * h).astype(int), 0, h - 1)
    return texture[j, i]


@pytest.mark.parametrize("suffix", [".glb", ".gltf", ".obj"])
def test_texture_is_kept_with_row_zero_at_v_zero(tmp_path, suffix):
    mesh_out = load_mesh(write_export(textured_quad(), tmp_path / f"textured{suffix}"))

    assert mesh_out.texture is not None and mesh_out.texture.shape == (2, 2, 4)
    assert mesh_out.uvs is not None
    np.testing.assert_allclose(mesh_out.uvs, QUAD_UV)
    np.testing.assert_array_equal(sample_nearest(mesh_out.texture, mesh_out.uvs), CORNER_COLORS)
    np.testing.assert_allclose(mesh_out.colors, 1.0)  # the factor is white


def test_gltf_image_given_by_uri_is_loaded(tmp_path):
    path = write_export(textured_quad(), tmp_path / "uri.gltf")
    tree = json.loads(path.read_text())
    tree["images"] = [{"uri": "my%20texture.png"}]  # glTF URIs are URL-encoded
    path.write_text(json.dumps(tree))
    Image.fromarray(TEXTURE_TOP_DOWN, "RGBA").save(tmp_path / "my texture.png")
    mesh_out = load_mesh(path)
    np.testing.assert_array_equal(sample_nearest(mesh_out.texture, mesh_out.uvs), CORNER_COLORS)


def test_different_textures_are_kept_one_material_each(tmp_path):
    red = np.tile(np.array([255, 0, 0, 255], np.uint8), (2, 2, 1))
    blue = np.tile(np.array([0, 0, 255, 255], np.uint8), (2, 2, 1))
    scene = trimesh.Scene([textured_quad(red), textured_quad(blue, offset=(2.0, 0.0, 0.0))])
    mesh_out = load_mesh(write_export(scene, tmp_path / "two.glb"))

    assert mesh_out.textured and mesh_out.texture is None  # no single texture
    assert len(mesh_out.materials) == 2
    triangle_x = mesh_out.positions[mesh_out.indices][:, :, 0].mean(axis=1)
    for is_red, image in ((triangle_x < 1.5, red), (triangle_x > 1.5, blue)):
        (used,) = set(mesh_out.material[is_red])
        np.testing.assert_array_equal(mesh_out.materials[used].texture, image)
    np.testing.assert_array_equal(mesh_out.colors, 1.0)


def test_textured_and_untextured_parts_keep_their_materials(tmp_path):
    scene = trimesh.Scene([textured_quad(), quad(offset=(2.0, 0.0, 0.0))])
    mesh_out = load_mesh(write_export(scene, tmp_path / "mixed.glb"))

    triangle_x = mesh_out.positions[mesh_out.indices][:, :, 0].mean(axis=1)
    textured = mesh_out.materials[mesh_out.material[triangle_x < 1.5][0]]
    plain = mesh_out.materials[mesh_out.material[triangle_x > 1.5][0]]
    np.testing.assert_array_equal(sample_nearest(textured.texture, QUAD_UV), CORNER_COLORS)
    assert plain.texture is None
    untextured_vertices = mesh_out.positions[:, 0] > 1.5
    np.testing.assert_allclose(mesh_out.colors[untextured_vertices], [[0.8, 0.8, 0.8, 1]] * 4)


# --------------------------------------------------------------------------------------
# bad input


def test_supported_extensions():
    assert set(SUPPORTED_EXTENSIONS) == {".obj", ".ply", ".stl", ".off", ".gltf", ".glb"}


def test_missing_file(tmp_path):
    expect_error(tmp_path / "nothing.obj", "no such file")


def test_directory(tmp_path):
    folder = tmp_path / "folder.obj"
    folder.mkdir()
    expect_error(folder, "directory")


def test_unsupported_extension(tmp_path):
    path = tmp_path / "mesh.xyz"
    path.write_text("0 0 0\n")
    expect_error(path, "unsupported", ".xyz", ".obj", ".glb")


@pytest.mark.parametrize("suffix", SUPPORTED_EXTENSIONS)
@pytest.mark.parametrize("content", ["random", "text", "empty"])
def test_garbage_file(tmp_path, suffix, content):
    data = {
        "random": np.random.default_rng(0).integers(0, 256, 300, dtype=np.uint8).tobytes(),
        "text": b"hello world\nthis is not a mesh\n",
        "empty": b"",
    }[content]
    path = tmp_path / f"garbage{suffix}"
    path.write_bytes(data)
    expect_error(path)


def test_parser_exceptions_are_converted(tmp_path):
    path = tmp_path / "broken.gltf"  # valid JSON, but accessor 5 does not exist
    tree = {"asset": {"version": "2.0"}, "meshes": [{"primitives": [{"attributes": {}}]}]}
    tree["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 5
    tree.update(nodes=[{"mesh": 0}], scenes=[{"nodes": [0]}], scene=0)
    path.write_text(json.dumps(tree))
    expect_error(path, "could not read")


def test_keyboard_interrupt_is_not_converted(tmp_path, monkeypatch):
    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(trimesh, "load_scene", interrupted)
    with pytest.raises(KeyboardInterrupt):
        load_mesh(write_export(quad(), tmp_path / "q.obj"))


def test_truncated_binary_stl(tmp_path):
    data = binary_stl([TRIANGLE, TRIANGLE])
    path = tmp_path / "cut.stl"
    path.write_bytes(data[:-10])
    expect_error(path, "truncated", "2 triangles")


def test_binary_stl_with_trailing_bytes_loads(tmp_path):
    path = tmp_path / "padded.stl"
    path.write_bytes(binary_stl([TRIANGLE]) + b"\0" * 7)
    assert load_mesh(path).triangle_count == 1


def test_truncated_ascii_stl(tmp_path):
    path = write_export(quad(), tmp_path / "cut.stl", file_type="stl_ascii")
    path.write_bytes(path.read_bytes()[:-40])
    expect_error(path, "truncated")


@pytest.mark.parametrize("keep", [0.99, 0.5, 0.05])
def test_truncated_glb(tmp_path, keep):
    data = textured_quad().export(file_type="glb")
    path = tmp_path / "cut.glb"
    path.write_bytes(data[: int(len(data) * keep)])
    expect_error(path, "truncated")


@pytest.mark.parametrize("encoding", ["ascii", "binary"])
@pytest.mark.parametrize("cut", [4, 30, 200])
def test_truncated_ply(tmp_path, encoding, cut):
    data = grid_mesh().export(file_type="ply", encoding=encoding)
    path = tmp_path / "cut.ply"
    path.write_bytes(data[:-cut])
    expect_error(path, "truncated")


def binary_ply(vertices, faces, endian="<") -> bytes:
    """A binary PLY written by hand (trimesh only writes little-endian triangles)."""
    name = {"<": "binary_little_endian", ">": "binary_big_endian"}[endian]
    header = PLY_HEADER.format(v=len(vertices), f=len(faces)).replace("ascii", name)
    body = np.asarray(vertices, dtype=endian + "f4").tobytes()
    for face in faces:
        body += struct.pack(endian + "B", len(face)) + np.asarray(face, endian + "i4").tobytes()
    return header.encode() + body


QUAD_VERTICES = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0]]


def test_big_endian_binary_ply(tmp_path):
    path = tmp_path / "big.ply"
    path.write_bytes(binary_ply(QUAD_VERTICES, [[0, 1, 2], [0, 2, 3]], endian=">"))
    mesh_out = load_mesh(path)
    np.testing.assert_array_equal(mesh_out.positions, QUAD_VERTICES)
    np.testing.assert_array_equal(mesh_out.indices, [[0, 1, 2], [0, 2, 3]])


def test_ascii_ply_with_mixed_polygons(tmp_path):
    path = tmp_path / "mixed.ply"
    path.write_text(ply_ascii(QUAD_VERTICES, [[0, 1, 2, 3], [1, 4, 2]]))
    assert load_mesh(path).triangle_count == 3


def test_binary_ply_with_mixed_polygons_is_reported(tmp_path):
    path = tmp_path / "mixed.ply"
    path.write_bytes(binary_ply(QUAD_VERTICES, [[0, 1, 2, 3], [1, 4, 2], [1, 4, 2], [0, 1, 2]]))
    expect_error(path, "mixes list lengths", "triangulate")


def test_truncated_off(tmp_path):
    path = tmp_path / "cut.off"
    path.write_text("OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n")
    expect_error(path, "truncated", "2 faces")


NO_TRIANGLES = {
    "points.obj": "v 0 0 0\nv 1 0 0\nv 0 1 0\n",
    "lines.obj": "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2 3\n",
    "nofaces.off": "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n",
    "nofaces.ply": ply_ascii(TRIANGLE, []),
    "points.ply": PLY_HEADER.format(v=3, f=0).replace(
        "element face 0\nproperty list uchar int vertex_indices\n", ""
    )
    + "0 0 0\n1 0 0\n0 1 0\n",
}


@pytest.mark.parametrize("name", [*NO_TRIANGLES, "empty.stl", "points.glb"])
def test_no_triangles(tmp_path, name):
    path = tmp_path / name
    if name == "empty.stl":
        path.write_bytes(binary_stl(np.zeros((0, 3, 3))))
    elif name == "points.glb":
        write_export(trimesh.Scene(trimesh.PointCloud(TRIANGLE)), path)
    else:
        path.write_text(NO_TRIANGLES[name])
    expect_error(path, "no triangles")


NAN_FILES = {
    "nan.obj": "v 0 0 0\nv nan 0 0\nv 0 inf 0\nf 1 2 3\n",
    "nan.off": "OFF\n3 1 0\n0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n",
    "nan.ply": ply_ascii([[0, 0, 0], ["nan", 0, 0], [0, 1, 0]], [[0, 1, 2]]),
}


@pytest.mark.parametrize("name", [*NAN_FILES, "nan.stl", "nan.glb"])
def test_nan_coordinates(tmp_path, name):
    path = tmp_path / name
    bad = [[0.0, 0.0, 0.0], [np.nan, 0.0, 0.0], [0.0, np.inf, 0.0]]
    if name == "nan.stl":
        path.write_bytes(binary_stl([bad]))
    elif name == "nan.glb":
        write_export(trimesh.Trimesh(bad, [[0, 1, 2]], process=False), path)
    else:
        path.write_text(NAN_FILES[name])
    count = "1 vertex has" if name in ("nan.off", "nan.ply") else "2 vertices have"
    expect_error(path, count, "NaN or Inf")


BAD_INDEX_FILES = {
    "range.obj": ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99\n", "99"),
    "range.off": ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 99\n", "99"),
    "range.ply": (ply_ascii(TRIANGLE, [[0, 1, 99]]), "99"),
    "negative.obj": ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -9\n", "-9"),
    "negative.off": ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 -1\n", "-1"),
    "negative.ply": (ply_ascii(TRIANGLE, [[0, 1, -1]]), "-1"),
}


@pytest.mark.parametrize("name", BAD_INDEX_FILES)
def test_face_index_out_of_range(tmp_path, name):
    text, index = BAD_INDEX_FILES[name]
    path = tmp_path / name
    path.write_text(text)
    expect_error(path, f"face index {index} out of range for 3 vertices")


def test_face_index_out_of_range_binary_ply(tmp_path):
    shape = trimesh.Trimesh(TRIANGLE, [[0, 1, 99]], process=False, validate=False)
    path = write_export(shape, tmp_path / "range.ply", encoding="binary")
    expect_error(path, "face index 99 out of range for 3 vertices")


def test_face_index_out_of_range_glb(tmp_path):
    shape = trimesh.Trimesh(TRIANGLE, [[0, 1, 5]], process=False, validate=False)
    expect_error(write_export(shape, tmp_path / "range.glb"), "face index 5 out of range")


def test_obj_zero_index(tmp_path):
    path = tmp_path / "zero.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n")
    expect_error(path, "face index 0 out of range", "start at 1")


def test_obj_texture_coordinate_index_out_of_range(tmp_path):
    path = tmp_path / "vt.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/7 3/1\n")
    expect_error(path, "texture-coordinate index 7 out of range")


def test_obj_relative_indices(tmp_path):
    path = tmp_path / "relative.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n")
    np.testing.assert_array_equal(load_mesh(path).indices, [[0, 1, 2]])
    path.write_text(path.read_text() + "v 5 0 0\nv 6 0 0\nv 5 1 0\nf -3 -2 -1\n")
    expect_error(path, "relative")


def test_obj_missing_mtl_loads_with_the_default_material_and_one_warning(tmp_path):
    path = write_export(textured_quad(), tmp_path / "q.obj")
    (tmp_path / "material.mtl").unlink()
    mesh = load_mesh(path)
    assert not mesh.textured and len(mesh.extra["warnings"]) == 1
    assert "material.mtl" in mesh.extra["warnings"][0]


def assert_drawn_without_texture(mesh_out, name: str, why: str, color) -> None:
    """The mesh kept its triangles and UVs, no texture, the material's colour, and one
    one-line warning that names the texture and why it was not read."""
    assert mesh_out.triangle_count == 2 and mesh_out.uvs is not None
    assert not mesh_out.textured and mesh_out.texture is None
    np.testing.assert_allclose(mesh_out.materials[0].color, color, atol=1e-6)
    (line,) = mesh_out.extra["warnings"]
    assert "\n" not in line and f"texture '{name}'" in line and why in line, line
    assert "drawn with the material colour" in line, line


def test_obj_missing_texture_draws_the_material_colour_with_one_warning(tmp_path):
    path = write_export(textured_quad(), tmp_path / "q.obj")
    (tmp_path / "material_0.png").unlink()
    kd = [float(x) for x in next(line.split()[1:] for line in
                                 (tmp_path / "material.mtl").read_text().splitlines()
                                 if line.startswith("Kd"))]
    linear = [srgb_byte_to_linear(round(255 * x)) for x in kd]
    assert_drawn_without_texture(load_mesh(path), "material_0.png", "not found",
                                 [*linear, 1.0])


def test_gltf_missing_buffer(tmp_path):
    path = write_export(quad(), tmp_path / "q.gltf")
    (tmp_path / "gltf_buffer_0.bin").unlink()
    expect_error(path, "references missing file", "gltf_buffer_0.bin")


def test_gltf_missing_image_draws_the_factor_with_one_warning(tmp_path):
    path = write_export(textured_quad(), tmp_path / "q.gltf")
    tree = json.loads(path.read_text())
    tree["images"] = [{"uri": "texture.png"}]
    tree["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = [0.2, 0.4, 1.0, 1.0]
    path.write_text(json.dumps(tree))
    assert_drawn_without_texture(load_mesh(path), "texture.png", "not found",
                                 [0.2, 0.4, 1.0, 1.0])


def test_gltf_image_outside_the_folder_is_not_read(tmp_path):
    folder = tmp_path / "model"
    folder.mkdir()
    path = write_export(textured_quad(), folder / "q.gltf")
    Image.fromarray(TEXTURE_TOP_DOWN, "RGBA").save(tmp_path / "texture.png")
    tree = json.loads(path.read_text())
    tree["images"] = [{"uri": "../texture.png"}]
    path.write_text(json.dumps(tree))
    assert_drawn_without_texture(load_mesh(path), "../texture.png", "outside the mesh's folder",
                                 [1.0, 1.0, 1.0, 1.0])


def test_mtl_outside_the_folder_is_not_read(tmp_path):
    folder = tmp_path / "model"
    folder.mkdir()
    (tmp_path / "m.mtl").write_text("newmtl paint\nKd 1 0 0\n")
    path = folder / "m.obj"
    path.write_text("mtllib ../m.mtl\nusemtl paint\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    mesh_out = load_mesh(path)
    assert mesh_out.materials == (type(mesh_out.materials[0])(),)  # the default, not its red
    (line,) = mesh_out.extra["warnings"]
    assert "'../m.mtl'" in line and "outside the mesh's folder" in line, line


@pytest.mark.parametrize("suffix", SUPPORTED_EXTENSIONS)
def test_empty_file_says_it_is_empty(tmp_path, suffix):
    path = tmp_path / f"empty{suffix}"
    path.write_bytes(b"")
    expect_error(path, "is empty")
