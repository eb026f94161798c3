"""The viewer's site: every input's GLB carries, for every program its plans draw with, the
GLSL ES sources reliefkit's shader loader builds (one source of truth with the OpenGL
path); --export-html writes all of its files or none."""

from __future__ import annotations

import json

import pytest

from reliefkit.errors import UsageError
from reliefkit.export.draw import read_plans
from reliefkit.gl.shaders import stage_sources
from reliefkit.io.gltf.glb import read_glb
from reliefkit.viewer.site import export_html, load_inputs, site_files


def test_each_input_carries_the_loaders_shader_sources(tmp_path):
    (made,) = load_inputs(["demo:cup"])
    (tmp_path / "cup.glb").write_bytes(made.glb)
    glb = read_glb(tmp_path / "cup.glb")
    (node,) = glb.document["nodes"]
    (extension,) = node["extensions"].values()
    draw = extension["draw"]
    embedded = {(p["program"], tuple(sorted(p["defines"].items()))): p for p in draw["programs"]}
    plans = read_plans(glb, draw)
    assert plans
    for plan in plans:
        defines = dict(sorted(dict(plan.program.defines).items()))
        sources = stage_sources(plan.program.name, defines, es=True)
        program = embedded[(plan.program.name, tuple(defines.items()))]
        assert program["vertex"] == sources["vertex_shader"]
        assert program["fragment"] == sources["fragment_shader"]


def test_the_page_has_no_glsl_of_its_own():
    """Its own two programs (the picture, the depth copy) come from the shader loader in
    inputs.json; the bundle holds no shader source."""
    import json

    files = site_files(load_inputs(["demo:cup"]))
    programs = json.loads(files["inputs.json"])["programs"]
    assert set(programs) == {"present", "copy_depth"}
    for program in programs.values():
        sources = stage_sources(program["name"], program["defines"], es=True)
        assert program["vertex"] == sources["vertex_shader"]
        assert program["fragment"] == sources["fragment_shader"]
    bundle = files["viewer.js"].decode()
    assert "#version" not in bundle and "gl_FragCoord" not in bundle


def test_export_html_refuses_a_file_in_the_way(tmp_path):
    files = site_files(load_inputs(["demo:cup"]))
    (tmp_path / "site").write_text("a file")
    with pytest.raises(UsageError, match="not a folder"):
        export_html(files, tmp_path / "site")
    written = export_html(files, tmp_path / "out")
    assert {p.name for p in written} == set(files)
    assert all(p.read_bytes() == files[p.name] for p in written)


def test_export_html_again_leaves_no_other_inputs_and_names_files_without_folders(tmp_path):
    """A second export of fewer inputs into the same folder removed nothing (the first's
    megabytes stayed), and inputs.json published the exporting machine's folders."""
    mesh = tmp_path / "secret" / "cube.obj"
    mesh.parent.mkdir()
    mesh.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n")
    export_html(site_files(load_inputs(["demo:cup", str(mesh)])), tmp_path / "site")
    (tmp_path / "site" / "input-7.txt").write_text("not ours")
    export_html(site_files(load_inputs([str(mesh)])), tmp_path / "site")
    assert sorted(p.name for p in (tmp_path / "site").iterdir()) == [
        "index.html", "input-0.glb", "input-7.txt", "inputs.json", "viewer.js"]
    published = json.loads((tmp_path / "site" / "inputs.json").read_text())
    assert [i["name"] for i in published["inputs"]] == ["cube.obj"]
    live = json.loads(site_files(load_inputs([str(mesh)]), live=True)["inputs.json"])
    assert live["inputs"][0]["name"] == str(mesh)  # served on 127.0.0.1: as the user gave it
