"""`reliefkit export`: an .rk to .glb / .gltf and back, LOD chains from a mesh, and its
errors as one line. References: the .rk the test bakes, pygltflib's reading of the output,
the Khronos validator."""

from __future__ import annotations

import numpy as np
import pygltflib
import pytest
from gltf_validator import problems, validate
from helpers import assert_one_line_error, run_cli

import reliefkit as rk
from reliefkit.builtins import registry


@pytest.fixture(scope="module")
def cube_rk(tmp_path_factory):
    path = tmp_path_factory.mktemp("rk") / "cube.rk"
    out = run_cli("bake", "demo:blob", "--as", "relief-cube", "--depth-res", "32",
                  "--color-res", "32", "-o", path)
    assert out.returncode == 0, out.stderr
    return path


def same_arrays(a, b) -> bool:
    codec = registry().codecs().for_object(a)
    (x, p), (y, q) = codec.to_arrays(a), codec.to_arrays(b)
    return p == q and set(x) == set(y) and all(
        x[k] is None and y[k] is None or np.asarray(x[k]).tobytes() == np.asarray(y[k]).tobytes()
        for k in x)


@pytest.mark.parametrize("suffix", [".glb", ".gltf"])
def test_export_writes_a_file_that_loads_back_and_validates(gl, cube_rk, tmp_path, suffix):
    out = tmp_path / f"cube{suffix}"
    result = run_cli("export", cube_rk, "-o", out, "--embed-shaders")
    assert result.returncode == 0, result.stderr
    assert f"wrote {out}" in result.stdout
    assert same_arrays(rk.load(out), rk.load(cube_rk))
    gltf = pygltflib.GLTF2().load(str(out))
    assert [n.mesh for n in gltf.nodes if n.mesh is not None], "no fallback mesh"
    node = next(n for n in gltf.nodes if n.extras)
    assert node.extras["reliefkit"]["sourceHash"] == rk.io.rk.read_manifest(cube_rk)[
        "source_hash"]
    assert problems(validate(out)) == []
    rendered = run_cli("render", out, "-o", tmp_path / "r.png", "--size", "64x64")
    assert rendered.returncode == 0, rendered.stderr


def test_no_fallback_writes_the_extension_alone(gl, cube_rk, tmp_path):
    out = tmp_path / "bare.glb"
    assert run_cli("export", cube_rk, "-o", out, "--no-fallback").returncode == 0
    gltf = pygltflib.GLTF2().load(str(out))
    assert not gltf.meshes and gltf.extensionsUsed == ["RELIEFKIT_relief_object"]
    assert not gltf.extensionsRequired


def test_lod_chain_of_a_mesh(gl, tmp_path):
    out = tmp_path / "lod.glb"
    result = run_cli("export", "demo:blob", "--lod", "relief-cube,billboard-cloud",
                     "--depth-res", "32", "--color-res", "32", "-o", out)
    assert result.returncode == 0, result.stderr
    assert result.stdout.count("LOD ") == 3
    gltf = pygltflib.GLTF2().load(str(out))
    root = gltf.nodes[gltf.scenes[0].nodes[0]]
    ids = root.extensions["MSFT_lod"]["ids"]
    coverage = root.extras["MSFT_screencoverage"]
    assert len(ids) == 2 and len(coverage) == 3 and coverage[-1] == 0
    assert coverage == sorted(coverage, reverse=True)
    kinds = [gltf.nodes[i].extras["reliefkit"]["kind"] for i in ids]
    assert kinds == ["relief-object", "billboard-cloud"]  # the most accurate first
    # the cloud takes over where its epsilon projects to one pixel of a 1080-pixel screen
    cloud, mesh = rk.load(out, node=ids[1]), rk.load_mesh("demo:blob")
    radius = 0.5 * np.linalg.norm(mesh.bounds[1] - mesh.bounds[0])
    assert coverage[1] == pytest.approx(2 * radius / (cloud.epsilon * 1080), abs=1e-6)
    assert "MSFT_lod" in gltf.extensionsUsed and not gltf.extensionsRequired
    info = run_cli("info", out)
    assert "representations: " in info.stdout and "billboard-cloud" in info.stdout
    assert problems(validate(out)) == []


@pytest.mark.parametrize("args, words, code", [
    (["export", "{rk}", "-o", "{tmp}/x.obj"], [".glb or .gltf"], 2),
    (["export", "{rk}", "-o", "{tmp}/x.glb", "--depth-res", "8"], ["--depth-res", "--lod"], 2),
    (["export", "{rk}", "-o", "{tmp}/x.glb", "--lod", "relief"], ["needs a mesh"], 2),
    (["export", "demo:blob", "-o", "{tmp}/x.glb", "--lod", "nope"], ["--lod", "nope"], 2),
    (["export", "demo:blob", "-o", "{tmp}/x.glb", "--lod", "relief-cube", "--grid", "8"],
     ["--grid"], 2),
    (["export", "{rk}", "-o", "{tmp}/x.glb", "--fallback-triangles", "1"], ["at least 2"], 2),
    (["export", "{tmp}/missing.rk", "-o", "{tmp}/x.glb"], ["missing.rk"], 1),
])
def test_export_errors_are_one_line(gl, cube_rk, tmp_path, args, words, code):
    filled = [a.format(rk=cube_rk, tmp=tmp_path) for a in args]
    result = run_cli(*filled)
    assert_one_line_error(result, *words, code=code)
    assert not (tmp_path / "x.glb").exists()


def test_a_plain_mesh_exports_as_a_mesh(gl, tmp_path):
    out = tmp_path / "mesh.glb"
    assert run_cli("export", "demo:blob", "-o", out).returncode == 0
    mesh = rk.load(out)
    assert mesh.triangle_count == rk.load_mesh("demo:blob").triangle_count


def test_info_reads_an_export_and_a_re_export_keeps_the_source_hash(gl, cube_rk, tmp_path):
    first, second = tmp_path / "a.glb", tmp_path / "b.glb"
    assert run_cli("export", cube_rk, "-o", first).returncode == 0
    info = run_cli("info", first)
    assert info.returncode == 0, info.stderr
    for words in ("kind: relief-object", "RELIEFKIT_relief_object", "p0_height",
                  "checksums: ok"):
        assert words in info.stdout, info.stdout
    assert run_cli("export", first, "-o", second).returncode == 0
    assert second.read_bytes() == first.read_bytes()
