"""`load_mesh_bytes`: a mesh file and the files it references, as bytes, load as
`load_mesh` loads them from disk (same arrays, same warnings), every message naming the
name given, never the private folder they are unpacked into."""

from __future__ import annotations

import tempfile
from pathlib import Path

import pytest
from helpers import assert_same_mesh, write_gltf_triangle, write_png, write_tetrahedron

from reliefkit.errors import MeshError
from reliefkit.io.meshes import load_mesh, load_mesh_bytes
from reliefkit.io.meshes.references import referenced_files


def as_bytes(path: Path) -> tuple[bytes, dict[str, bytes]]:
    """What a batch task carries: the file's bytes and its references' by relative name."""
    return path.read_bytes(), {name: file.read_bytes()
                               for name, file in referenced_files(path).items()}


def obj_with_texture(folder: Path) -> Path:
    mesh = write_tetrahedron(folder / "t.obj", name_texture="tex/t.png")
    write_png(folder / "tex" / "t.png", (10, 200, 10))
    return mesh


@pytest.mark.parametrize("scene, names", [
    (obj_with_texture, {"t.mtl", "tex/t.png"}),
    (write_gltf_triangle, {"data.bin", "images/base colour.png"}),
], ids=["obj-mtl-texture", "gltf-bin-image"])
def test_the_bytes_load_as_the_files_on_disk(tmp_path, scene, names):
    path = scene(tmp_path / "lib")
    data, files = as_bytes(path)
    assert set(files) == names
    mesh = load_mesh_bytes(path.name, data, files)
    assert_same_mesh(mesh, load_mesh(path))
    assert mesh.materials[0].texture is not None  # the texture came with the bytes
    assert mesh.extra["source"] == path.name and "warnings" not in mesh.extra


def test_warnings_name_the_given_folder_as_on_disk(tmp_path):
    path = write_tetrahedron(tmp_path / "lib" / "t.obj", name_texture="gone.png")
    data, files = as_bytes(path)
    on_disk = load_mesh(path).extra["warnings"]
    assert on_disk and all(str(tmp_path / "lib") in w for w in on_disk)
    mesh = load_mesh_bytes(str(path), data, files)
    assert mesh.extra["warnings"] == on_disk
    bare = load_mesh_bytes("t.obj", data, files).extra["warnings"]  # no folder: "."
    assert bare == [w.replace(str(tmp_path / "lib"), ".") for w in on_disk]


@pytest.mark.parametrize("name", ["../escaped.png", "/tmp/escaped.png", "a/../../escaped.png", ""])
def test_a_file_named_outside_the_folder_is_refused(name):
    with pytest.raises(MeshError, match="outside its folder") as info:
        load_mesh_bytes("lib/t.obj", b"v 0 0 0\n", {name: b"x"})
    assert str(info.value).startswith("lib/t.obj: ") and "\n" not in str(info.value)
    assert not (Path(tempfile.gettempdir()) / "escaped.png").exists()


@pytest.mark.parametrize("data, words", [
    (b"", "is empty"),
    (b"v 0 0 0\nv 1 1 1\nv 2 2 2\nf 1 2 3\n", "no triangle with a visible area"),
    (b"v 0 0 0\nf 1 2 3\n", "out of range"),
])
def test_a_bad_mesh_is_one_line_naming_the_given_name(tmp_path, data, words):
    on_disk = tmp_path / "broken.obj"
    on_disk.write_bytes(data)
    with pytest.raises(MeshError) as disk:
        load_mesh(on_disk)
    with pytest.raises(MeshError) as given:
        load_mesh_bytes("chairs/broken.obj", data)
    message = str(given.value)
    assert message == str(disk.value).replace(str(on_disk), "chairs/broken.obj")
    assert message.startswith("chairs/broken.obj: ") and words in message
    assert "reliefkit-mesh-" not in message and "\n" not in message


def test_the_suffix_of_the_name_picks_the_format():
    with pytest.raises(MeshError, match=r"^t\.xyz: unsupported file type '\.xyz'"):
        load_mesh_bytes("t.xyz", b"v 0 0 0\n")
    with pytest.raises(MeshError, match="bytes need its file name .*got ''"):
        load_mesh_bytes("", b"v 0 0 0\n")
