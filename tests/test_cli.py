"""The command line: each command end to end, and the error path (one line, no traceback)."""

import json
import subprocess
import sys

import numpy as np
import pytest
import trimesh
from helpers import assert_one_line_error, run_cli


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
    out = run_cli("bake", "demo:terrain", "--as", "relief", "--depth-res", "32", "--safety",
                  "-o", rk)  # --safety: a 32² field gets no radii by default
    assert out.returncode == 0, out.stderr
    # sizes with units: 32 x 32 float32 heights are 4 KiB
    assert "height 4.0 KiB" in out.stdout and "on disk" in out.stdout, out.stdout
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
                                  tmp_path / "m.png"),
                          "--method does not apply to demo:tree, a mesh")
    assert_one_line_error(run_cli("render", rk, "--method", "magic", "-o", tmp_path / "m.png"),
                          "method must be one of binary, exact, robust")
    assert_one_line_error(run_cli("bake", "demo:tree", "--as", "relief-cube", "--spread", "9",
                                  "-o", tmp_path / "c.rk"), "--spread does not apply")


@pytest.mark.parametrize("args, words", [
    (["render", "missing.obj", "-o", "x.png"], ["missing.obj", "no such file"]),
    (["render", "missing.rk", "-o", "x.png"], ["missing.rk: no such file"]),
    (["bake", "missing.png", "--as", "relief", "-o", "x.rk"], ["missing.png: no such file"]),
    (["render", "demo:nope", "-o", "x.png"], ["nope"]),
    (["render", "demo:tree", "--view", "1,2,3,4", "-o", "x.png"], ["--view"]),
    (["render", "demo:tree", "--size", "0x5", "-o", "x.png"], ["--size"]),
    (["render", "demo:tree", "-o", "x.jpg"], [".png"]),
    (["render", "demo:tree", "--turntable", "3", "-o", "x.jpg"], [".gif", ".webp", ".mp4"]),
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
                  "--size", "64x64", "--light", "-40,30", "--out", tmp_path / "cmp")
    assert out.returncode == 0, out.stderr
    progress = [line for line in out.stderr.splitlines() if line.startswith("compare: ")]
    assert progress and "done in" in progress[-1], out.stderr
    report = json.loads((tmp_path / "cmp" / "metrics.json").read_text())
    assert set(report["variants"]) == {"binary", "exact", "robust", "maxmip", "cone"}
    assert report["variants"]["exact"]["wrong_hit_fraction"] <= 0.001
    assert report["variants"]["maxmip"]["wrong_hit_fraction"] <= 0.001
    assert (tmp_path / "cmp" / "compare.png").stat().st_size > 1000
    assert "| robust |" in (tmp_path / "cmp" / "metrics.md").read_text()


@pytest.fixture(scope="module")
def small_rk(tmp_path_factory):
    path = tmp_path_factory.mktemp("rk") / "small.rk"
    out = run_cli("bake", "demo:terrain", "--as", "relief", "--depth-res", "16", "-o", path)
    assert out.returncode == 0, out.stderr
    return path


def test_values_starting_with_a_dash_parse(gl, tmp_path):
    rk = tmp_path / "down.rk"
    out = run_cli("bake", "demo:terrain", "--as", "relief", "--axis", "-y", "--depth-res", "16",
                  "-o", rk)
    assert out.returncode == 0, out.stderr
    from reliefkit.io.rk import read_manifest

    assert read_manifest(rk)["params"]["axis"] == "-y"
    out = run_cli("render", "demo:tree", "--view", "-30,20", "--light", "-40,30", "--size",
                  "24x24", "-o", tmp_path / "t.png")
    assert out.returncode == 0, out.stderr
    # a real option after a flag is still an option, not its value
    assert_one_line_error(run_cli("bake", "demo:terrain", "--axis", "-o", "x.rk", cwd=tmp_path),
                          "--axis", code=2)


@pytest.mark.parametrize("args, words", [
    (["bake", "demo:terrain", "--as", "relief", "--depth-res", "0", "-o", "x.rk"],
     ["--depth-res", "[8, 8192]", "got 0"]),
    (["bake", "demo:terrain", "--as", "relief", "--color-res", "0", "-o", "x.rk"],
     ["--color-res", "got 0"]),
    (["bake", "demo:terrain", "--as", "relief", "--depth-res", "many", "-o", "x.rk"],
     ["--depth-res", "'many'"]),
    (["bake", "demo:tree", "--as", "relief-cube", "--spread", "9", "-o", "x.rk"],
     ["--spread does not apply to --as relief-cube"]),
    (["render", "demo:tree", "--turntable", "3", "--aovs", "a.npz", "-o", "x.gif"],
     ["--aovs", "--turntable"]),
    (["render", "demo:tree", "--turntable", "3", "--stats", "s.json", "-o", "x.gif"],
     ["--stats", "--turntable"]),
    (["render", "demo:tree", "--background", "2", "-o", "x.png"], ["--background", "[0, 1]"]),
    (["render", "demo:tree", "--background", "grey", "-o", "x.png"], ["--background"]),
    (["render", "demo:tree", "--method", "exact", "-o", "x.png"],
     ["--method does not apply to demo:tree, a mesh"]),
    (["render", "demo:tree", "--light", "1", "-o", "x.png"], ["--light", "AZ,EL"]),
    (["render", "demo:tree", "--light", "10,95", "-o", "x.png"], ["--light", "[-90, 90]"]),
    (["render", "demo:tree", "--fov", "0", "-o", "x.png"], ["--fov"]),
    (["render", "demo:tree", "--msaa", "3", "-o", "x.png"], ["--msaa"]),
    (["compare", "demo:tree", "--light", "x,y", "--out", "c"], ["--light"]),
    (["render", "demo:tree", "--view", "1,2,3,4", "-o", "x.png"], ["--view"]),
    (["bench", "nope"], ["invalid choice"]),
])
def test_usage_errors_exit_2_naming_the_flag(tmp_path, args, words):
    result = run_cli(*args, cwd=tmp_path)
    assert_one_line_error(result, *words, code=2)
    assert not list(tmp_path.iterdir()), "a refused command wrote nothing"


def test_render_options_name_the_typed_flag(gl, small_rk, tmp_path):
    result = run_cli("render", small_rk, "--linear-steps", "0", "-o", tmp_path / "x.png")
    assert_one_line_error(result, "--linear-steps must be within", code=2)
    assert "linear_steps" not in result.stderr


def test_a_flag_that_does_not_apply_names_the_kind_not_its_class(gl, tmp_path):
    rk = tmp_path / "imp.rk"
    assert run_cli("bake", "demo:blob", "--as", "octahedral-impostor", "--grid", "4",
                   "--atlas-res", "48", "-o", rk).returncode == 0
    assert_one_line_error(run_cli("render", rk, "--method", "robust", "-o", tmp_path / "x.png"),
                          f"--method does not apply to {rk}, an octahedral-impostor .rk", code=2)
    assert_one_line_error(run_cli("render", rk, "--animate", "2", "-o", tmp_path / "x.png"),
                          "an octahedral-impostor .rk, has no animation", code=2)


def test_bake_refuses_an_rk_input(gl, small_rk, tmp_path):
    for command in (["bake", small_rk, "-o", tmp_path / "x.rk"],
                    ["compare", small_rk, "--out", tmp_path / "c"]):
        assert_one_line_error(run_cli(*command), "needs a mesh or heightmap, not an .rk file",
                              code=2)


@pytest.mark.parametrize("name, command", [
    ("zero.obj", ["render", "{}", "-o", "x.png"]),
    ("zero.glb", ["render", "{}", "-o", "x.png"]),
    ("zero.rk", ["render", "{}", "-o", "x.png"]),
    ("zero.rk", ["info", "{}"]),
    ("zero.png", ["bake", "{}", "--as", "relief", "-o", "x.rk"]),
    ("zero.ply", ["compare", "{}", "--out", "c"]),
])
def test_an_empty_file_says_it_is_empty(tmp_path, name, command):
    (tmp_path / name).write_bytes(b"")
    result = run_cli(*[c.replace("{}", name) for c in command], cwd=tmp_path)
    assert_one_line_error(result, name, "empty", code=1)


def test_bad_input_files_exit_1(tmp_path):
    bad = tmp_path / "nan.obj"
    bad.write_text("v 0 0 0\nv 1 0 nan\nv 0 1 0\nf 1 2 3\n")
    assert_one_line_error(run_cli("render", bad, "-o", tmp_path / "x.png"), code=1)
    assert_one_line_error(run_cli("render", tmp_path / "missing.obj", "-o", tmp_path / "x.png"),
                          code=1)


def flip_a_byte_inside(path, member: str):
    """Flip one bit in the middle of an array's stored bytes (the zip member's data)."""
    import struct
    import zipfile

    with zipfile.ZipFile(path) as zf:
        info = zf.getinfo(member)
    data = bytearray(path.read_bytes())
    name_len, extra_len = struct.unpack("<HH", data[info.header_offset + 26:
                                                    info.header_offset + 30])
    start = info.header_offset + 30 + name_len + extra_len
    data[start + info.compress_size // 2] ^= 0x10
    path.write_bytes(bytes(data))


def test_info_verifies_checksums(gl, small_rk, tmp_path):
    out = run_cli("info", small_rk)
    assert out.returncode == 0, out.stderr
    assert any(line.split() == ["checksums:", "ok"] for line in out.stdout.splitlines())
    arrays = json.loads(run_cli("info", "--json", small_rk).stdout)["file"]["arrays"]
    for name, record in arrays.items():  # one line per array: its dtype and shape, then its
        shape = "x".join(map(str, record["shape"])) or "scalar"  # GPU format and bytes
        assert [name, record["dtype"], shape] in [line.split()[:3]
                                                  for line in out.stdout.splitlines()]
    assert json.loads(run_cli("info", "--json", small_rk).stdout)["file"]["checksums"] == "ok"
    import shutil

    for member in ("height.npy", "color.npy"):
        bad = tmp_path / f"bad-{member}.rk"
        shutil.copy(small_rk, bad)
        flip_a_byte_inside(bad, member)
        for args in (["info", bad], ["info", "--json", bad]):
            result = run_cli(*args)
            assert_one_line_error(result, bad.name, code=1)
            assert "ok" not in result.stdout


def test_a_closed_stdout_is_no_error(gl, small_rk):
    """``reliefkit info --json x.rk | head -1``: the reader leaves before reliefkit writes."""
    proc = subprocess.Popen([sys.executable, "-m", "reliefkit.cli", "info", "--json", "--gl",
                             str(small_rk)], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    proc.stdout.close()
    err = proc.stderr.read().decode()
    proc.wait(timeout=300)
    assert proc.returncode in (0, 141), err
    assert err == ""


@pytest.fixture(scope="module")
def edge_on(tmp_path_factory):
    """A flat triangle in the xz plane: seen at elevation 0 it covers no pixel at all."""
    path = tmp_path_factory.mktemp("flat") / "flat.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 2 3\n")
    return path


def test_a_render_of_nothing_warns(gl, edge_on, tmp_path):
    out = run_cli("render", edge_on, "--view", "20,0", "--size", "32x32", "-o", tmp_path / "f.png")
    assert out.returncode == 0, out.stderr
    assert (tmp_path / "f.png").is_file()
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("warning: "), out.stderr
    assert "nothing visible" in lines[0] and "0 pixels" in lines[0]
    out = run_cli("render", edge_on, "--view", "20,0", "--turntable", "4", "--size", "16x16",
                  "-o", tmp_path / "f.gif")
    assert out.returncode == 0, out.stderr
    warnings = [line for line in out.stderr.splitlines() if line.startswith("warning: ")]
    assert len(warnings) == 1 and "views 1, 2, 3, 4 of 4" in warnings[0], out.stderr
    assert "nothing visible" in warnings[0]
    visible = run_cli("render", edge_on, "--view", "20,30", "--size", "32x32", "-o",
                      tmp_path / "v.png")
    assert visible.returncode == 0 and "warning" not in visible.stderr


def test_light_flag_moves_the_light(gl, box_obj, tmp_path):
    """The box's +x face is brighter than its +z face under light from +x, and the reverse."""
    brightness = {}
    for light in ("90,0", "0,0"):
        out = run_cli("render", box_obj, "--view", "45,20", "--size", "48x48", "--light", light,
                      "-o", tmp_path / "b.png", "--aovs", tmp_path / "b.npz")
        assert out.returncode == 0, out.stderr
        with np.load(tmp_path / "b.npz") as aovs:
            lum = aovs["color"][..., :3].mean(axis=-1)
            p = aovs["position"]
            faces = (np.isclose(p[..., 0], 1.0, atol=1e-4), np.isclose(p[..., 2], 0.25, atol=1e-4))
            assert all(face.sum() > 20 for face in faces)
            brightness[light] = [lum[face].mean() for face in faces]
    assert brightness["90,0"][0] > brightness["90,0"][1] + 0.2
    assert brightness["0,0"][1] > brightness["0,0"][0] + 0.2


def test_msaa_flag_smooths_edges_only(gl, box_obj, tmp_path):
    aovs = {}
    for n in (1, 4):
        out = run_cli("render", box_obj, "--size", "48x48", "--msaa", n, "-o",
                      tmp_path / f"m{n}.png", "--aovs", tmp_path / f"m{n}.npz")
        assert out.returncode == 0, out.stderr
        with np.load(tmp_path / f"m{n}.npz") as data:
            aovs[n] = {name: data[name] for name in data.files}
    def fractional(alpha):
        return int(((alpha > 0.05) & (alpha < 0.95)).sum())

    assert fractional(aovs[4]["color"][..., 3]) > 20
    assert fractional(aovs[1]["color"][..., 3]) == 0
    for name in ("mask", "depth", "normal"):
        np.testing.assert_array_equal(aovs[4][name], aovs[1][name])


def test_bake_progress_is_plain_lines_off_a_terminal(gl, tmp_path):
    out = run_cli("bake", "demo:terrain", "--as", "relief", "--depth-res", "16", "-o",
                  tmp_path / "p.rk")
    assert out.returncode == 0, out.stderr
    lines = out.stderr.strip().splitlines()
    assert lines and lines[-1].startswith("baking relief: ") and "done in" in lines[-1], lines
    assert all(line.startswith("baking relief: ") for line in lines), lines
    assert "\x1b" not in out.stderr and "\r" not in out.stderr


def test_what_a_bake_refuses_of_a_file_names_the_file(tmp_path, capsys):
    """A flat triangle baked as a relief (edge-on along the default axis) was 'error: the
    heightfield is empty ...', without the file: in a library's worth of bakes, which one?"""
    from reliefkit import cli

    mesh = tmp_path / "flat.stl"
    trimesh.Trimesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]]).export(mesh)
    assert cli.main(["bake", str(mesh), "--as", "relief", "-o", str(tmp_path / "f.rk")]) == 2
    err = capsys.readouterr().err
    assert err == f"error: {mesh}: the mesh is flat across z: seen along --axis y it is " \
                  "edge-on and covers nothing; bake it along --axis z\n"
