"""What the user names as an input: the public `load_mesh` takes ``demo:NAME`` as the CLI does,
and `reliefkit info` says whether a mesh has UVs and how many materials and textures it has.

References are independent of the code under test: the asset factories themselves, and the
files written here (the images each material names).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from helpers import sample, technique_samples, toy_technique
from PIL import Image

import reliefkit as rk
from reliefkit.cli import main
from reliefkit.errors import MeshError
from reliefkit.scene.assets import make_asset

TRIANGLE = "v 0 0 0\nv 1 0 0\nv 0 1 0\n"


def test_public_load_mesh_takes_demo_names():
    mesh = rk.load_mesh("demo:blob")
    asset = make_asset("blob")
    np.testing.assert_array_equal(mesh.world_positions, asset.world_positions)
    np.testing.assert_array_equal(mesh.indices, asset.indices)
    assert mesh.name == asset.name
    renamed = rk.load_mesh("demo:blob", name="my blob")
    assert renamed.name == "my blob"
    np.testing.assert_array_equal(renamed.world_positions, asset.world_positions)


def test_public_load_mesh_names_the_demo_assets_when_one_is_unknown():
    with pytest.raises(MeshError, match="demo:nope: unknown asset 'nope'.*blob"):
        rk.load_mesh("demo:nope")


def test_a_path_object_is_always_a_file(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "demo:blob").mkdir()
    (tmp_path / "demo:blob" / "t.obj").write_text(TRIANGLE + "f 1 2 3\n")
    assert rk.load_mesh(tmp_path / "demo:blob" / "t.obj").triangle_count == 1
    with pytest.raises(MeshError, match="no such file"):
        rk.load_mesh(Path("demo:terrain"))


def write_materials_obj(folder, uvs: bool = True):
    """Three materials on three triangles: 'a' and 'b' name the same image, 'c' another."""
    for name, colour in (("one.png", (255, 0, 0, 255)), ("two.png", (0, 0, 255, 255))):
        Image.new("RGBA", (2, 2), colour).save(folder / name)
    (folder / "m.mtl").write_text("newmtl a\nmap_Kd one.png\nnewmtl b\nKd 0.5 0.5 0.5\n"
                                  "map_Kd one.png\nnewmtl c\nmap_Kd two.png\n")
    corners = [f"{3 * k + 1}{'/1' if uvs else ''} {3 * k + 2}{'/2' if uvs else ''} "
               f"{3 * k + 3}{'/3' if uvs else ''}" for k in range(3)]
    lines = ["mtllib m.mtl", *(f"v {k} 0 0\nv {k + 1} 0 0\nv {k} 1 0" for k in range(3))]
    if uvs:
        lines += ["vt 0 0", "vt 1 0", "vt 0 1"]
    lines += [f"usemtl {m}\nf {c}" for m, c in zip("abc", corners, strict=True)]
    path = folder / "m.obj"
    path.write_text("\n".join(lines) + "\n")
    return path


def info_json(path, capsys) -> dict:
    assert main(["info", "--json", str(path)]) == 0
    return json.loads(capsys.readouterr().out)["file"]


def test_info_says_uvs_materials_and_distinct_textures(tmp_path, capsys):
    report = info_json(write_materials_obj(tmp_path), capsys)
    assert report["uvs"] is True and report["textured"] is True
    assert report["materials"] == 3 and report["textures"] == 2  # one.png counted once


def test_info_says_a_mesh_has_no_uvs(tmp_path, capsys):
    report = info_json(write_materials_obj(tmp_path, uvs=False), capsys)
    assert report["uvs"] is False and report["textures"] == 0 and report["textured"] is False


def test_info_text_has_the_uv_and_texture_lines(tmp_path, capsys):
    assert main(["info", str(write_materials_obj(tmp_path))]) == 0
    lines = {line.split(":")[0].strip(): line.split(":", 1)[1].strip()
             for line in capsys.readouterr().out.splitlines()}
    assert lines["uvs"] == "True" and lines["textures"] == "2" and lines["materials"] == "3"


@pytest.mark.parametrize("tech_kind", [
    pytest.param(tk, id=":".join(tk)) for tk in technique_samples()])
def test_messages_name_each_kind_as_its_file_does_not_its_class(gl, tmp_path, tech_kind):
    from reliefkit.io.inputs import kind_of, load_input, what_it_is
    from reliefkit.io.rk import read_manifest, save

    with toy_technique():  # a plugged-in kind is named the same way
        path = save(tmp_path / "x.rk", sample(*tech_kind))
        obj = load_input(str(path))
        kind = read_manifest(path)["kind"]
        assert kind_of(obj) == kind
        said = what_it_is(str(path), obj)
    assert said.endswith(f" {kind} .rk") and type(obj).__name__ not in said


def test_a_mesh_is_a_mesh():
    from reliefkit.io.inputs import what_it_is

    assert what_it_is("demo:blob", make_asset("blob")) == "demo:blob, a mesh"
