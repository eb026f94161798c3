"""`referenced_files` names exactly the files `load_mesh` reads besides the mesh itself
(recorded where every read goes through: `badfile.reads_recorded`)."""

from __future__ import annotations

import struct

from helpers import write_gltf_triangle, write_png

from reliefkit.io.meshes import load_mesh
from reliefkit.io.meshes.badfile import reads_recorded
from reliefkit.io.meshes.references import referenced_files


def _read_by_load(path) -> set:
    with reads_recorded() as read:
        load_mesh(path)
    return {p.resolve() for p in read} - {path.resolve()}


def test_obj_with_mtl_and_texture_in_a_subfolder(tmp_path):
    (tmp_path / "m.mtl").write_text("newmtl a\nKd 1 1 1\nmap_Kd tex/Wood.png\n")
    write_png(tmp_path / "tex" / "Wood.png")
    write_png(tmp_path / "unused.png")
    mesh = tmp_path / "m.obj"
    mesh.write_text("mtllib m.mtl\nusemtl a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\n"
                    "vt 0 1\nf 1/1 2/2 3/3\n")
    found = referenced_files(mesh)
    assert sorted(found) == ["m.mtl", "tex/Wood.png"]
    assert {p.resolve() for p in found.values()} == _read_by_load(mesh)


def test_a_texture_named_in_another_case_is_found_as_the_loader_finds_it(tmp_path):
    (tmp_path / "m.mtl").write_text("newmtl a\nKd 1 1 1\nmap_Kd WOOD.PNG\n")
    write_png(tmp_path / "wood.png")
    mesh = tmp_path / "m.obj"
    mesh.write_text("mtllib m.mtl\nusemtl a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\n"
                    "vt 0 1\nf 1/1 2/2 3/3\n")
    assert sorted(referenced_files(mesh)) == ["m.mtl", "wood.png"]
    assert {p.resolve() for p in referenced_files(mesh).values()} == _read_by_load(mesh)


def test_a_missing_texture_is_left_out_as_the_load_leaves_it(tmp_path):
    (tmp_path / "m.mtl").write_text("newmtl a\nKd 1 1 1\nmap_Kd gone.png\n")
    mesh = tmp_path / "m.obj"
    mesh.write_text("mtllib m.mtl\nusemtl a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\n"
                    "vt 0 1\nf 1/1 2/2 3/3\n")
    assert sorted(referenced_files(mesh)) == ["m.mtl"]
    assert {p.resolve() for p in referenced_files(mesh).values()} == _read_by_load(mesh)


def test_gltf_buffer_and_image_files(tmp_path):
    mesh = write_gltf_triangle(tmp_path)
    found = referenced_files(mesh)
    assert sorted(found) == ["data.bin", "images/base colour.png"]
    assert {p.resolve() for p in found.values()} == _read_by_load(mesh)


def test_files_without_references(tmp_path):
    stl = tmp_path / "t.stl"
    triangle = struct.pack("<12fH", 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0)
    stl.write_bytes(b"\0" * 80 + struct.pack("<I", 1) + triangle)
    assert referenced_files(stl) == {}
    assert _read_by_load(stl) == set()
