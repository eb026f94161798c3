"""The command line: each command end to end, and the error path (one line, no traceback)."""

import json
import subprocess
import sys

import numpy as np
import pytest
import trimesh


def run_cli(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "reliefkit.cli", *map(str, args)],
                          capture_output=True, text=True, timeout=300, cwd=cwd)


def assert_one_line_error(result, *words):
    assert result.returncode != 0
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), result.stderr
    assert "Traceback" not in result.stderr
    for word in words:
        assert word in lines[0], lines[0]


@pytest.fixture(scope="module")
def box_obj(tmp_path_factory):
    path = tmp_path_factory.mktemp("mesh") / "box.obj"
    trimesh.creation.box(extents=(2.0, 1.0, 0.5)).export(path)
    return path


def test_help_lists_every_command():
    out = run_cli("--help")
    assert out.returncode == 0
    for command in ("render", "info", "demo", "bake", "compare", "bench"):
        assert command in out.stdout
    assert "examples:" in out.stdout


def test_render_png_and_aovs(gl, box_obj, tmp_path):
    out = run_cli("render", box_obj, "--view", "30,20,3", "--size", "40x30", "-o",
                  tmp_path / "b.png", "--aovs", tmp_path / "b.npz")
    assert out.returncode == 0, out.stderr
    from PIL import Image

    assert Image.open(tmp_path / "b.png").size == (40, 30)
    with np.load(tmp_path / "b.npz", allow_pickle=False) as aovs:
        assert set(aovs.files) == {"color", "mask", "depth", "position", "normal", "view",
                                   "proj", "viewport"}
        mask, pos = aovs["mask"], aovs["position"]
        assert mask.shape == (30, 40) and mask.sum() > 100
        # AOV positions lie on the box surface: one coordinate at its half extent
        p = pos[mask]
        on_face = np.isclose(np.abs(p), [1.0, 0.5, 0.25], atol=1e-4).any(axis=1)
        assert on_face.all()


def test_render_turntable_gif(gl, tmp_path):
    out = run_cli("render", "demo:vehicle", "--turntable", "3", "--size", "32x32", "-o",
                  tmp_path / "spin.gif")
    assert out.returncode == 0, out.stderr
    from PIL import Image

    with Image.open(tmp_path / "spin.gif") as gif:
        assert gif.n_frames == 3


def test_info_gl_and_mesh(gl, box_obj):
    out = run_cli("info", "--gl", "--json", box_obj)
    assert out.returncode == 0, out.stderr
    report = json.loads(out.stdout)
    assert report["gl"]["max_texture_size"] >= 1024
    assert report["file"]["triangles"] == 12
    np.testing.assert_allclose(report["file"]["bounds_max"], [1.0, 0.5, 0.25])


def test_bake_render_info_relief(gl, tmp_path):
    rk = tmp_path / "t.rk"
    out = run_cli("bake", "demo:terrain", "--as", "relief", "--depth-res", "32", "-o", rk)
    assert out.returncode == 0, out.stderr
    info = json.loads(run_cli("info", "--json", rk).stdout)
    assert info["file"]["kind"] == "relief" and "safety" in info["file"]["arrays"]
    out = run_cli("render", rk, "--method", "exact", "--shadows", "--size", "32x32", "-o",
                  tmp_path / "t.png", "--stats", tmp_path / "s.json")
    assert out.returncode == 0, out.stderr
    from PIL import Image

    stats = json.loads((tmp_path / "s.json").read_text())
    covered = int((np.asarray(Image.open(tmp_path / "t.png"))[..., 3] > 0).sum())
    assert stats["covered"] == covered > 0
    assert stats["fragments"] >= stats["covered"]
    assert stats["iterations_max"] >= stats["iterations_mean"] > 0
    assert_one_line_error(run_cli("render", "demo:tree", "--method", "exact", "-o",
                                  tmp_path / "m.png"), "--method does not apply", "RenderMesh")
    assert_one_line_error(run_cli("render", rk, "--method", "magic", "-o", tmp_path / "m.png"),
                          "method must be one of binary, exact, robust")
    assert_one_line_error(run_cli("bake", "demo:tree", "--as", "relief-cube", "--spread", "9",
                                  "-o", tmp_path / "c.rk"), "--spread does not apply")


@pytest.mark.parametrize("args, words", [
    (["render", "missing.obj", "-o", "x.png"], ["missing.obj", "no such file"]),
    (["render", "demo:nope", "-o", "x.png"], ["nope"]),
    (["render", "demo:tree", "--view", "1,2", "-o", "x.png"], ["--view"]),
    (["render", "demo:tree", "--size", "0x5", "-o", "x.png"], ["--size"]),
    (["render", "demo:tree", "-o", "x.jpg"], [".png"]),
    (["render", "demo:tree", "--turntable", "3", "-o", "x.png"], [".gif"]),
    (["info"], ["--gl"]),
    (["render"], ["required"]),
    (["bake", "demo:tree", "--as", "volume", "-o", "x.rk"], ["invalid choice"]),
])
def test_errors_are_one_line(tmp_path, args, words):
    assert_one_line_error(run_cli(*args, cwd=tmp_path), *words)


def test_bad_mesh_and_bad_rk_are_one_line_errors(tmp_path):
    bad = tmp_path / "nan.obj"
    bad.write_text("v 0 0 0\nv 1 0 nan\nv 0 1 0\nf 1 2 3\n")
    assert_one_line_error(run_cli("render", bad, "-o", tmp_path / "x.png"), "NaN")
    forged = tmp_path / "forged.rk"
    forged.write_bytes(b"PK\x03\x04 not really a zip")
    assert_one_line_error(run_cli("render", forged, "-o", tmp_path / "x.png"), "forged.rk")
    assert not (tmp_path / "x.png").exists()


def test_bake_heightmap_png16_and_npy(gl, tmp_path):
    from PIL import Image

    y, x = np.mgrid[0:24, 0:32]
    heights = (np.sin(x / 5.0) * np.cos(y / 4.0) + 1) / 2
    Image.fromarray(np.round(heights * 65535).astype(np.uint16)).save(tmp_path / "h.png")
    np.save(tmp_path / "h.npy", heights)
    for name in ("h.png", "h.npy"):
        out = run_cli("bake", tmp_path / name, "--as", "relief", "--box", "3,0.5,2", "-o",
                      tmp_path / "h.rk")
        assert out.returncode == 0, out.stderr
        from reliefkit.io.rk import load

        relief = load(tmp_path / "h.rk")
        assert relief.height.shape == (24, 32)
        np.testing.assert_allclose(relief.bounds[1] - relief.bounds[0], [3, 0.5, 2])
    assert_one_line_error(run_cli("bake", tmp_path / "h.npy", "--as", "relief-cube", "-o",
                                  tmp_path / "c.rk"), "heightmap")


def test_compare_writes_picture_and_metrics(gl, tmp_path):
    out = run_cli("compare", "demo:terrain", "--as", "relief", "--depth-res", "32",
                  "--size", "64x64", "--out", tmp_path / "cmp")
    assert out.returncode == 0, out.stderr
    report = json.loads((tmp_path / "cmp" / "metrics.json").read_text())
    assert set(report["variants"]) == {"binary", "exact", "robust"}
    assert report["variants"]["exact"]["wrong_hit_fraction"] <= 0.001
    assert (tmp_path / "cmp" / "compare.png").stat().st_size > 1000
    assert "| robust |" in (tmp_path / "cmp" / "metrics.md").read_text()
