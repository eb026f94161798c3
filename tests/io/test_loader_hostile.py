"""Hostile input for `load_mesh` (issue 8): every case ends in one `MeshError` or a real mesh.

The corpus is generated here in tmp_path: FIFOs and device links (loaded in a child process
with a timeout, so a regression fails instead of hanging the suite), internal parser errors,
degenerate geometry, numbers past what float32 holds, and files that are refused today but
should render (a missing .mtl). The CLI cases check that stderr is exactly one `error:` line
(or one `warning:` line on success): no numpy, PIL or trimesh warning gets through.
"""

from __future__ import annotations

import base64
import json
import os
import struct
import subprocess
import sys
import warnings

import numpy as np
import pytest
import trimesh
from PIL import Image

import reliefkit.io.meshes as loader_package
from reliefkit.errors import MeshError
from reliefkit.io.meshes import badfile, load_mesh

TRIANGLE_OBJ = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"
NOT_REGULAR = "is not a regular file"
INVISIBLE = "has no triangle with a visible area"

needs_fifo = pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs os.mkfifo")

# --------------------------------------------------------------------------------------
# helpers

CHILD = """
import sys
from reliefkit.errors import MeshError
from reliefkit.io.meshes import load_mesh
try:
    mesh = load_mesh(sys.argv[1])
except MeshError as exc:
    print("MeshError", exc)
else:
    print(f"mesh {mesh.triangle_count}", *mesh.extra.get("warnings", []), sep=" | ")
"""


def load_in_child(path, timeout: float = 60.0) -> str:
    """`load_mesh(path)` in a child process: its one line of output ('MeshError ...' or
    'mesh N', then ' | WARNING' for each warning); a hang (a blocking read) fails the test
    after `timeout` seconds."""
    try:
        out = subprocess.run([sys.executable, "-c", CHILD, str(path)], capture_output=True,
                             text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        pytest.fail(f"load_mesh({path}) did not return within {timeout} s (blocked?)")
    assert out.returncode == 0, out.stderr
    assert out.stderr == "", out.stderr
    lines = out.stdout.splitlines()
    assert len(lines) == 1, out.stdout
    return lines[0]


def expect_error(path, *words) -> str:
    """load_mesh(path) raises one one-line MeshError naming the file, with `words` in it;
    nothing is warned on the way."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with pytest.raises(MeshError) as info:
            load_mesh(path)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(str(path)), message
    for word in words:
        assert word in message, message
    assert not caught, [str(w.message) for w in caught]
    return message


def load_quietly(path):
    """load_mesh(path) with no Python warning raised on the way."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        mesh = load_mesh(path)
    assert not caught, [str(w.message) for w in caught]
    assert mesh.triangle_count > 0
    return mesh


def run_cli(*args, timeout: float = 120.0) -> subprocess.CompletedProcess:
    try:
        return subprocess.run([sys.executable, "-m", "reliefkit.cli", *map(os.fsencode, args)],
                              capture_output=True, text=True, timeout=timeout,
                              errors="backslashreplace")
    except subprocess.TimeoutExpired:
        pytest.fail(f"reliefkit {' '.join(map(str, args))} did not finish within {timeout} s")


def render_cli(path, tmp_path) -> subprocess.CompletedProcess:
    return run_cli("render", path, "--out", tmp_path / "out.png", "--size", "32x32")


def assert_one_error_line(out: subprocess.CompletedProcess, *words) -> None:
    assert out.returncode == 1, (out.returncode, out.stderr)
    lines = out.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), out.stderr
    for word in words:
        assert word in lines[0], lines[0]


def gltf_json(nodes=None, scene_nodes=(0,), positions=None, mode=None, buffer_uri=None,
              extra=None) -> dict:
    """A one-primitive glTF 2.0 tree with an embedded (or `buffer_uri`) position buffer."""
    if positions is None:
        positions = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]
    positions = np.asarray(positions, np.float32)
    data = positions.tobytes()
    primitive = {"attributes": {"POSITION": 0}}
    if mode is not None:
        primitive["mode"] = mode
    tree = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": list(scene_nodes)}],
        "nodes": nodes if nodes is not None else [{"mesh": 0}],
        "meshes": [{"primitives": [primitive]}],
        "buffers": [{"byteLength": len(data), "uri": buffer_uri or
                     "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
        "bufferViews": [{"buffer": 0, "byteLength": len(data)}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": len(positions),
                       "type": "VEC3", "min": positions.min(0).tolist(),
                       "max": positions.max(0).tolist()}],
    }
    tree.update(extra or {})
    return tree


def write_gltf(path, **kwargs):
    path.write_text(json.dumps(gltf_json(**kwargs)))
    return path


def textured_gltf(tmp_path):
    """A textured quad exported by trimesh as .gltf with its texture as a separate file."""
    image = Image.fromarray(np.full((2, 2, 4), 200, np.uint8), "RGBA")
    material = trimesh.visual.material.PBRMaterial(baseColorTexture=image)
    uv = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    quad = trimesh.Trimesh([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], [[0, 1, 2], [0, 2, 3]],
                           visual=trimesh.visual.TextureVisuals(uv=uv, material=material),
                           process=False)
    path = tmp_path / "textured.gltf"
    files = quad.export(file_type="gltf", embed_buffers=False)
    for name, data in files.items():
        (tmp_path / name).write_bytes(data)
    tree = json.loads((tmp_path / "model.gltf").read_bytes())
    (tmp_path / "model.gltf").unlink()
    assert len(tree["images"]) == 1
    image.save(tmp_path / "texture.png")
    tree["images"] = [{"uri": "texture.png"}]  # the texture as a file of its own
    path.write_text(json.dumps(tree))
    return path, tree


# --------------------------------------------------------------------------------------
# 1. non-regular files never block and are never read whole


@needs_fifo
def test_fifo_as_mesh_path_is_refused(tmp_path):
    fifo = tmp_path / "mesh.obj"
    os.mkfifo(fifo)
    line = load_in_child(fifo)
    assert line.startswith("MeshError") and NOT_REGULAR in line and "FIFO" in line, line


@needs_fifo
def test_fifo_as_mtllib_is_not_read(tmp_path):
    path = tmp_path / "m.obj"
    path.write_text("mtllib pipe.mtl\nusemtl a\n" + TRIANGLE_OBJ)
    os.mkfifo(tmp_path / "pipe.mtl")
    line = load_in_child(path)  # the default material, and the reason in one warning
    assert line == ("mesh 1 | material library 'pipe.mtl' is not a regular file (it is a FIFO "
                    "(named pipe)); give a file on disk; using the default material"), line


@needs_fifo
def test_fifo_as_gltf_buffer_is_refused(tmp_path):
    path = write_gltf(tmp_path / "b.gltf", buffer_uri="pipe.bin")
    os.mkfifo(tmp_path / "pipe.bin")
    line = load_in_child(path)
    assert line.startswith("MeshError") and "pipe.bin" in line and "not a regular" in line, line


@needs_fifo
def test_fifo_as_gltf_texture_is_not_read(tmp_path):
    path, tree = textured_gltf(tmp_path)
    assert load_in_child(path) == "mesh 2"  # the file is fine with its texture
    texture = tmp_path / tree["images"][0]["uri"]
    texture.unlink()
    os.mkfifo(texture)
    line = load_in_child(path)  # drawn with the material colour, one warning for the texture
    assert line.startswith(f"mesh 2 | texture '{texture.name}' is not a regular file"), line
    assert line.count(" | ") == 1 and "drawn with the material colour" in line, line


@pytest.mark.skipif(not os.path.exists("/dev/zero"), reason="needs /dev/zero")
def test_symlink_to_dev_zero_is_not_read(tmp_path):
    link = tmp_path / "zero.stl"
    link.symlink_to("/dev/zero")
    line = load_in_child(link, timeout=30)
    assert line.startswith("MeshError") and NOT_REGULAR in line and "device" in line, line
    mtl_link = tmp_path / "z.mtl"
    mtl_link.symlink_to("/dev/zero")
    obj = tmp_path / "z.obj"
    obj.write_text("mtllib z.mtl\n" + TRIANGLE_OBJ)
    line = load_in_child(obj, timeout=30)
    assert line.startswith("mesh 1 | material library 'z.mtl' is outside the mesh's folder "
                           "and is not read"), line  # the link leads to /dev


def test_regular_symlink_is_followed(tmp_path):
    (tmp_path / "real.obj").write_text(TRIANGLE_OBJ)
    (tmp_path / "link.obj").symlink_to(tmp_path / "real.obj")
    assert load_quietly(tmp_path / "link.obj").triangle_count == 1
    (tmp_path / "dangling.obj").symlink_to(tmp_path / "gone.obj")
    expect_error(tmp_path / "dangling.obj", "broken symbolic link")


def test_size_cap_is_checked_before_reading(tmp_path, monkeypatch):
    path = tmp_path / "t.obj"
    path.write_text(TRIANGLE_OBJ)
    monkeypatch.setattr(badfile, "MAX_FILE_BYTES", 16)
    expect_error(path, "is too large", f"{len(TRIANGLE_OBJ)} bytes", "at most 16 bytes")
    assert loader_package.MAX_FILE_BYTES >= 2**30  # the documented cap fits a 1 GB scan


def test_referenced_file_over_the_cap_is_not_read(tmp_path, monkeypatch):
    path = tmp_path / "m.obj"
    path.write_text("mtllib big.mtl\nusemtl a\n" + TRIANGLE_OBJ)
    (tmp_path / "big.mtl").write_text("newmtl a\nKd 1 0 0\n" + "# padding\n" * 20)
    monkeypatch.setattr(badfile, "MAX_FILE_BYTES", 100)
    mesh = load_quietly(path)
    assert mesh.materials[0] == type(mesh.materials[0])()  # the default, not the file's red
    (line,) = mesh.extra["warnings"]
    assert "'big.mtl' is too large" in line and "default material" in line, line


@needs_fifo
def test_cli_fifo_is_one_error_line(tmp_path):
    fifo = tmp_path / "mesh.ply"
    os.mkfifo(fifo)
    assert_one_error_line(render_cli(fifo, tmp_path), NOT_REGULAR)


# --------------------------------------------------------------------------------------
# 2. internal errors on bad input become one MeshError


def test_non_utf8_file_name_loads(tmp_path):
    raw = os.fsencode(tmp_path) + b"/caf\xe9\xff.obj"
    with open(raw, "wb") as f:
        f.write(TRIANGLE_OBJ.encode())
    assert load_quietly(os.fsdecode(raw)).triangle_count == 1  # surrogate escapes
    assert load_quietly(raw).triangle_count == 1  # a bytes path


def test_cli_non_utf8_file_name_renders(tmp_path, gl):
    raw = os.fsencode(tmp_path) + b"/m\xff.obj"
    with open(raw, "wb") as f:
        f.write(TRIANGLE_OBJ.encode())
    out = render_cli(os.fsdecode(raw), tmp_path)
    assert out.returncode == 0, out.stderr
    assert out.stderr == ""


@pytest.mark.parametrize("nodes, scene_nodes", [
    ([{"mesh": 0, "children": [0]}], (0,)),
    ([{"mesh": 0, "children": [1]}, {"children": [0]}], (0,)),
    ([{"children": [1]}, {"children": [2]}, {"mesh": 0, "children": [0]}], (0,)),
    ([{"mesh": 0, "children": [1]}, {"mesh": 0, "children": [0]}], (0, 1)),
])
def test_gltf_node_cycle(tmp_path, nodes, scene_nodes):
    path = write_gltf(tmp_path / "cycle.gltf", nodes=nodes, scene_nodes=scene_nodes)
    expect_error(path, "cycle")


def test_gltf_child_that_is_not_a_node(tmp_path):
    path = write_gltf(tmp_path / "kids.gltf", nodes=[{"mesh": 0, "children": [7]}])
    expect_error(path, "children")


@pytest.mark.parametrize("suffix", [".gltf", ".glb"])
def test_deeply_nested_json(tmp_path, suffix):
    text = '{"asset": {"version": "2.0"}, "x": ' + "[" * 100_000 + "]" * 100_000 + "}"
    path = tmp_path / f"deep{suffix}"
    if suffix == ".gltf":
        path.write_text(text)
    else:
        chunk = text.encode() + b" " * (-len(text) % 4)
        path.write_bytes(struct.pack("<4sII", b"glTF", 2, 20 + len(chunk))
                         + struct.pack("<II", len(chunk), 0x4E4F534A) + chunk)
    expect_error(path, "nested too deeply")


@pytest.mark.parametrize("index", ["100000000000000000000000", "-100000000000000000000000"])
def test_off_huge_face_index(tmp_path, index):
    path = tmp_path / "big.off"
    path.write_text(f"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 {index}\n")
    expect_error(path, "face index")


PLY_HEADER = (b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
              b"property float y\nproperty float z\nelement face %d\n"
              b"property list uchar int vertex_indices\nend_header\n")
PLY_VERTICES = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], "<f4").tobytes()
TRIANGLE_ROW = bytes([3]) + struct.pack("<3i", 0, 1, 2)


@pytest.mark.parametrize("faces, body", [
    (1, bytes([200]) + struct.pack("<3i", 0, 1, 2)),  # the one row claims 200 indices
    (2, TRIANGLE_ROW + bytes([200]) + struct.pack("<3i", 0, 1, 2)),  # the second one does
    (2, TRIANGLE_ROW + bytes([3]) + struct.pack("<2i", 0, 1)),  # the second row is cut off
    (1, bytes([255])),  # a list length and nothing after it
    (1, b""),  # no face row at all
])
def test_binary_ply_list_row_past_the_end(tmp_path, faces, body):
    path = tmp_path / "cut.ply"
    path.write_bytes(PLY_HEADER % faces + PLY_VERTICES + body)
    expect_error(path)


def test_binary_ply_that_fits_still_loads(tmp_path):
    path = tmp_path / "ok.ply"
    path.write_bytes(PLY_HEADER % 1 + PLY_VERTICES + TRIANGLE_ROW)
    assert load_quietly(path).triangle_count == 1


def test_memory_error_while_parsing(tmp_path, monkeypatch):
    path = tmp_path / "t.obj"
    path.write_text(TRIANGLE_OBJ)

    def out_of_memory(*args, **kwargs):
        raise MemoryError

    monkeypatch.setattr(trimesh, "load_scene", out_of_memory)
    expect_error(path, "ran out of memory")


def test_memory_error_after_parsing(tmp_path, monkeypatch):
    path = tmp_path / "t.obj"
    path.write_text(TRIANGLE_OBJ)

    def out_of_memory(*args, **kwargs):
        raise MemoryError

    monkeypatch.setattr(loader_package, "scene_parts", out_of_memory)
    expect_error(path, "ran out of memory")


@pytest.mark.parametrize("error", [IndexError("index 9 is out of bounds"), KeyError("x"),
                                   OverflowError("int too large"), RecursionError("deep"),
                                   UnicodeEncodeError("utf-8", "\udcff", 0, 1, "surrogate"),
                                   ValueError("Iteration limit exceeded!"), TypeError("odd")])
def test_unexpected_parser_exception_becomes_mesh_error(tmp_path, monkeypatch, error):
    path = tmp_path / "t.obj"
    path.write_text(TRIANGLE_OBJ)

    def fail(*args, **kwargs):
        raise error

    for where in (trimesh, loader_package):  # inside the parser and after it
        name = "load_scene" if where is trimesh else "scene_parts"
        with monkeypatch.context() as patch:
            patch.setattr(where, name, fail)
            expect_error(path)


@pytest.mark.parametrize("name, text", [
    ("cycle.gltf", json.dumps(gltf_json(nodes=[{"mesh": 0, "children": [0]}]))),
    ("deep.gltf", '{"asset": {"version": "2.0"}, "x": ' + "[" * 50_000 + "]" * 50_000 + "}"),
    ("big.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 100000000000000000000000\n"),
])
def test_cli_internal_errors_are_one_error_line(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    assert_one_error_line(render_cli(path, tmp_path), str(path))


# --------------------------------------------------------------------------------------
# 3. degenerate geometry


@pytest.mark.parametrize("text", [
    "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n",  # collinear
    "v 1 1 1\nv 1 1 1\nv 1 1 1\nf 1 2 3\nf 3 2 1\n",  # all vertices equal
    "v 0 0 0\nv 1 0 0\nv 0 1e-30 0\nf 1 2 3\n",  # a sliver of 1e-30
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 5 5\nf 1 1 2\nf 2 3 3\nf 4 4 4\n",  # repeated corners
])
def test_only_zero_area_faces_are_refused(tmp_path, text):
    path = tmp_path / "flat.obj"
    path.write_text(text)
    expect_error(path, INVISIBLE)


@pytest.mark.parametrize("node", [{"mesh": 0, "scale": [0, 0, 0]},
                                  {"mesh": 0, "scale": [1, 0, 1]},  # flattened to a line
                                  {"mesh": 0, "matrix": [0.0] * 16}])
def test_gltf_node_scaled_to_zero(tmp_path, node):
    path = write_gltf(tmp_path / "flat.gltf", nodes=[node])
    expect_error(path, INVISIBLE)


def test_zero_area_faces_are_kept_beside_visible_ones(tmp_path):
    path = tmp_path / "mixed.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 4\n")
    mesh = load_quietly(path)
    assert mesh.triangle_count == 2  # documented: kept, they draw nothing


@pytest.mark.parametrize("scale", [1e-30, 1e-12, 1e12, 1e17])
def test_tiny_and_huge_meshes_are_visible(tmp_path, scale):
    path = tmp_path / "scaled.obj"
    path.write_text(f"v 0 0 0\nv {scale} 0 0\nv 0 {scale} 0\nf 1 2 3\n")
    assert load_quietly(path).triangle_count == 1


def test_cli_degenerate_mesh_is_one_error_line(tmp_path):
    path = tmp_path / "flat.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n")
    assert_one_error_line(render_cli(path, tmp_path), INVISIBLE)


# --------------------------------------------------------------------------------------
# 4. numbers


@pytest.mark.parametrize("value", ["1e39", "1e300", "3e38", "-3e38", "1.7e308", "2e18"])
def test_coordinates_beyond_the_limit(tmp_path, value):
    path = tmp_path / "far.obj"
    path.write_text(f"v 0 0 0\nv {value} 0 0\nv 0 1 0\nf 1 2 3\n")
    expect_error(path, f"beyond {loader_package.MAX_COORDINATE:g}")


def test_binary_stl_coordinates_beyond_the_limit(tmp_path):
    triangle = np.array([[0, 0, 0], [3e38, 0, 0], [0, 3e38, 0]], "<f4")
    path = tmp_path / "far.stl"
    path.write_bytes(b"\0" * 80 + struct.pack("<I", 1) + np.zeros(3, "<f4").tobytes()
                     + triangle.tobytes() + b"\0\0")
    expect_error(path, "beyond")


def test_coordinates_beyond_the_limit_after_the_scene_transform(tmp_path):
    path = write_gltf(tmp_path / "far.gltf", nodes=[{"mesh": 0, "translation": [1e30, 0, 0]}])
    expect_error(path, "beyond", "after the scene transforms")
    path = write_gltf(tmp_path / "big.gltf", nodes=[{"mesh": 0, "scale": [1e36, 1e36, 1e36]}])
    expect_error(path, "beyond")


@pytest.mark.parametrize("bad", ["NaN", "Infinity"])
@pytest.mark.parametrize("slot", [0, 12, 15])
def test_gltf_matrix_not_finite(tmp_path, bad, slot):
    matrix = [1.0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]
    matrix[slot] = float(bad.lower().replace("infinity", "inf"))
    path = write_gltf(tmp_path / "nan.gltf", nodes=[{"mesh": 0, "matrix": matrix}])
    expect_error(path, "NaN or Inf")


def test_limit_is_within_float32():
    largest_squared = loader_package.MAX_COORDINATE ** 2
    assert largest_squared < float(np.finfo(np.float32).max)


@pytest.mark.parametrize("name, text", [
    ("e39.obj", "v 0 0 0\nv 1e39 0 0\nv 0 1 0\nf 1 2 3\n"),
    ("e300.obj", "v 0 0 0\nv 1e300 0 0\nv 0 1 0\nf 1 2 3\n"),
    ("e38.obj", "v 0 0 0\nv 3e38 0 0\nv 0 3e38 0\nf 1 2 3\n"),
    ("nan.gltf", json.dumps(gltf_json(nodes=[{"mesh": 0, "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0,
                                                                    0, 1, 0, 0, 0, 0, "NaN"]}]))
     .replace('"NaN"', "NaN")),
])
def test_cli_numbers_are_one_error_line(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    assert_one_error_line(render_cli(path, tmp_path), str(path))


def test_cli_valid_mesh_has_empty_stderr(tmp_path, gl):
    path = tmp_path / "ok.obj"
    path.write_text(TRIANGLE_OBJ)
    out = render_cli(path, tmp_path)
    assert out.returncode == 0, out.stderr
    assert out.stderr == ""


# --------------------------------------------------------------------------------------
# 5. a missing .mtl renders with the default material and one warning


def test_missing_mtl_is_a_warning(tmp_path):
    path = tmp_path / "m.obj"
    path.write_text("mtllib missing.mtl\nusemtl red\n" + TRIANGLE_OBJ)
    mesh = load_quietly(path)
    assert mesh.triangle_count == 1
    found = [w for w in mesh.extra.get("warnings", []) if "missing.mtl" in w]
    assert len(found) == 1 and "\n" not in found[0] and "default material" in found[0]
    assert len(mesh.materials) == 1
    assert mesh.materials[0] == type(mesh.materials[0])()  # the default material


def test_present_mtl_has_no_warning(tmp_path):
    path = tmp_path / "m.obj"
    path.write_text("mtllib here.mtl\nusemtl red\n" + TRIANGLE_OBJ)
    (tmp_path / "here.mtl").write_text("newmtl red\nKd 1 0 0\n")
    assert "warnings" not in load_quietly(path).extra


def test_missing_texture_shared_by_two_materials_is_one_warning(tmp_path):
    path = tmp_path / "m.obj"
    path.write_text("mtllib here.mtl\nvt 0 0\nvt 1 0\nvt 0 1\nv 0 0 0\nv 1 0 0\nv 0 1 0\n"
                    "v 0 0 1\nv 1 0 1\nv 0 1 1\n"
                    "usemtl red\nf 1/1 2/2 3/3\nusemtl blue\nf 4/1 5/2 6/3\n")
    (tmp_path / "here.mtl").write_text("newmtl red\nKd 1 0 0\nmap_Kd gone.png\n"
                                       "newmtl blue\nKd 0 0 1\nmap_Kd gone.png\n")
    mesh = load_quietly(path)
    assert not mesh.textured
    assert sorted(tuple(m.color) for m in mesh.materials) == [(0, 0, 1, 1), (1, 0, 0, 1)]
    (line,) = mesh.extra["warnings"]
    assert line.startswith("texture 'gone.png' not found"), line


def test_cli_missing_texture_renders_with_one_warning_line(tmp_path, gl):
    path = tmp_path / "m.obj"
    path.write_text("mtllib here.mtl\nusemtl red\nvt 0 0\nvt 1 0\nvt 0 1\n" + TRIANGLE_OBJ
                    .replace("f 1 2 3", "f 1/1 2/2 3/3"))
    (tmp_path / "here.mtl").write_text("newmtl red\nKd 1 1 1\nmap_Kd gone.png\n")
    out = render_cli(path, tmp_path)
    assert out.returncode == 0, out.stderr
    lines = out.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("warning: texture 'gone.png' not found"), \
        out.stderr


def test_cli_missing_mtl_renders_with_one_warning_line(tmp_path, gl):
    path = tmp_path / "m.obj"
    path.write_text("mtllib missing.mtl\nusemtl red\n" + TRIANGLE_OBJ)
    out = render_cli(path, tmp_path)
    assert out.returncode == 0, out.stderr
    lines = out.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("warning: ") and "missing.mtl" in lines[0], \
        out.stderr


def test_gltf_triangle_strip_is_triangulated(tmp_path):
    square = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]]
    mesh = load_quietly(write_gltf(tmp_path / "strip.gltf", positions=square, mode=5))
    assert mesh.triangle_count == 2
    corners = {tuple(map(float, p)) for p in mesh.positions[mesh.indices.reshape(-1)]}
    assert corners == {tuple(map(float, p)) for p in square}
    cross = np.cross(*(mesh.positions[mesh.indices[:, k]] - mesh.positions[mesh.indices[:, 0]]
                       for k in (1, 2)))
    assert (cross[:, 2] > 0).all()  # strips alternate their winding; every triangle faces +z


# a convex pentagon in the xy plane, as a fan around vertex 0, counter-clockwise seen from +z
PENTAGON = [[0, 0, 0], [2, 0, 0], [3, 1, 0], [1, 3, 0], [-1, 1, 0]]
PENTAGON_TRIANGLES = [[0, 1, 2], [0, 2, 3], [0, 3, 4]]


def fan_tree(index_dtype=None, order=None, index_uri=None):
    """A glTF tree with PENTAGON as one fan (mode 6): unindexed, or with indices `order`
    of `index_dtype` in a second buffer (a data: URI unless `index_uri`). Returns the tree
    and the index bytes."""
    tree = gltf_json(positions=PENTAGON, mode=6)
    if index_dtype is None:
        return tree, b""
    raw = np.asarray(order, index_dtype).tobytes()
    component = {"<u1": 5121, "<u2": 5123, "<u4": 5125}[index_dtype]
    uri = index_uri or "data:application/octet-stream;base64," + base64.b64encode(raw).decode()
    tree["buffers"].append({"byteLength": len(raw), "uri": uri})
    tree["bufferViews"].append({"buffer": 1, "byteLength": len(raw)})
    tree["accessors"].append({"bufferView": 1, "componentType": component, "count": len(order),
                              "type": "SCALAR"})
    tree["meshes"][0]["primitives"][0]["indices"] = 1
    return tree, raw


def assert_pentagon(mesh, triangles=PENTAGON_TRIANGLES):
    np.testing.assert_allclose(mesh.positions[mesh.indices], np.asarray(PENTAGON)[triangles])


def test_gltf_triangle_fan_is_triangulated(tmp_path):
    tree, _ = fan_tree()
    path = tmp_path / "fan.gltf"
    path.write_text(json.dumps(tree))
    assert_pentagon(load_quietly(path))


@pytest.mark.parametrize("index_dtype", ["<u1", "<u2", "<u4"])
def test_gltf_indexed_triangle_fan(tmp_path, index_dtype):
    order = [2, 3, 4, 0, 1]  # the same pentagon, fanned around vertex 2
    tree, _ = fan_tree(index_dtype, order)
    path = tmp_path / "fan.gltf"
    path.write_text(json.dumps(tree))
    assert_pentagon(load_quietly(path), [[2, 3, 4], [2, 4, 0], [2, 0, 1]])


def test_gltf_triangle_fan_with_indices_in_a_file(tmp_path):
    tree, raw = fan_tree("<u2", [0, 1, 2, 3, 4], index_uri="fan%20indices.bin")
    (tmp_path / "fan indices.bin").write_bytes(raw)
    path = tmp_path / "fan.gltf"
    path.write_text(json.dumps(tree))
    assert_pentagon(load_quietly(path))


def test_glb_indexed_triangle_fan(tmp_path):
    positions = np.asarray(PENTAGON, "<f4").tobytes()
    indices = np.arange(5, dtype="<u2").tobytes() + b"\0\0"
    tree = gltf_json(positions=PENTAGON, mode=6)
    tree["buffers"] = [{"byteLength": len(positions) + len(indices)}]
    tree["bufferViews"].append({"buffer": 0, "byteOffset": len(positions), "byteLength": 10})
    tree["accessors"].append({"bufferView": 1, "componentType": 5123, "count": 5,
                              "type": "SCALAR"})
    tree["meshes"][0]["primitives"][0]["indices"] = 1
    text = json.dumps(tree).encode()
    text += b" " * (-len(text) % 4)
    binary = positions + indices
    body = (struct.pack("<II", len(text), 0x4E4F534A) + text
            + struct.pack("<II", len(binary), 0x004E4942) + binary)
    path = tmp_path / "fan.glb"
    path.write_bytes(struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body)
    assert_pentagon(load_quietly(path))


def test_gltf_fan_with_out_of_range_index_is_refused(tmp_path):
    tree, _ = fan_tree("<u1", [0, 1, 2, 9])
    path = tmp_path / "fan.gltf"
    path.write_text(json.dumps(tree))
    expect_error(path, "9")


def test_gltf_fan_of_two_vertices_has_no_triangles(tmp_path):
    tree, _ = fan_tree("<u1", [0, 1])
    path = tmp_path / "fan.gltf"
    path.write_text(json.dumps(tree))
    expect_error(path, "contains no triangles")


def test_cli_triangle_fan_renders(tmp_path, gl):
    tree, _ = fan_tree()
    path = tmp_path / "fan.gltf"
    path.write_text(json.dumps(tree))
    out = render_cli(path, tmp_path)
    assert out.returncode == 0 and out.stderr == "", out.stderr
    assert "0 pixels" not in out.stdout
