"""Hostile command lines (issue 8): generated bad values, unwritable outputs, forged inputs.

Each case asserts its outcome class: one ``error:`` line and the documented exit status
(nothing else on stderr: no numpy warning, no progress), or a correct non-empty output.
"""

import dataclasses
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from helpers import assert_one_line_error, run_cli

from reliefkit import cli
from reliefkit.builtins import registry


@pytest.fixture(scope="module")
def heights(tmp_path_factory):
    path = tmp_path_factory.mktemp("hm") / "h.npy"
    np.save(path, np.random.default_rng(0).random((16, 16)).astype(np.float32))
    return path


@pytest.fixture(scope="module")
def small_rk(tmp_path_factory, heights):
    path = tmp_path_factory.mktemp("rk") / "s.rk"
    out = run_cli("bake", heights, "--as", "relief", "-o", path)
    assert out.returncode == 0, out.stderr
    return path


# ------------------------------------------------------------------ 1. values, one line

@pytest.mark.parametrize("box", ["nan,1,1", "inf,1,1", "1,-inf,1", "1e-300,1,1",
                                 "1e300,1e300,1e300", "1e400,1,1", "0,1,1"])
def test_bad_box_values_are_one_usage_line(gl, heights, tmp_path, box):
    result = run_cli("bake", heights, "--as", "relief", "--box", box, "-o", tmp_path / "b.rk")
    assert_one_line_error(result, "--box", code=2)
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("view, words", [
    ("0,0,1e-300", ["--view distance", "0.01"]),
    ("0,0,1e-6", ["--view distance"]),
    ("0,0,1e300", ["--view distance"]),
    ("0,0,nan", ["--view"]),
    ("0,0,inf", ["--view"]),
    ("nan,0", ["--view"]),
    ("0,90", ["elevation"]),
])
def test_degenerate_views_are_one_usage_line(view, words, tmp_path):
    result = run_cli("render", "demo:blob", "--view", view, "--size", "8x8", "-o",
                     tmp_path / "v.png")
    assert_one_line_error(result, *words, code=2)
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("level", ["nan", "inf", "-inf", "1e400", "-0.5", "1.5", "grey"])
def test_bad_backgrounds_are_one_usage_line(level, tmp_path):
    result = run_cli("render", "demo:blob", "--background", level, "-o", tmp_path / "v.png")
    assert_one_line_error(result, "--background", code=2)


@pytest.mark.parametrize("fov", ["0", "180", "-1", "nan", "inf", "1e-300", "179.9999999",
                                 "1e400"])
def test_fovs_outside_the_range_are_one_usage_line(fov, tmp_path):
    result = run_cli("render", "demo:blob", "--fov", fov, "-o", tmp_path / "v.png")
    assert_one_line_error(result, "--fov", code=2)


def test_edge_values_inside_the_ranges_still_render(gl, tmp_path):
    result = run_cli("render", "demo:blob", "--view", "-30,10,0.5", "--fov", "170",
                     "--background", "1", "--size", "16x16", "-o", tmp_path / "v.png")
    assert result.returncode == 0, result.stderr
    assert (tmp_path / "v.png").stat().st_size > 0
    assert "warning" not in result.stderr or "0 pixels" in result.stderr


@pytest.mark.parametrize("scale", [1e20, 1e300])
def test_an_rk_framed_by_a_huge_box_is_one_input_line(gl, small_rk, tmp_path, scale):
    """The camera cannot be built with finite matrices: refused before numpy warns."""
    from reliefkit.io.rk import load, save

    huge = tmp_path / "huge.rk"
    save(huge, dataclasses.replace(load(small_rk),
                                   source_bounds=np.array([[-scale] * 3, [scale] * 3])))
    result = run_cli("render", huge, "--size", "8x8", "-o", tmp_path / "h.png")
    assert_one_line_error(result, "bounds", code=1)
    assert "near=nan" not in result.stderr and "RuntimeWarning" not in result.stderr
    assert not (tmp_path / "h.png").exists()


def test_camera_framing_refuses_non_finite_bounds():
    from reliefkit.errors import FormatError
    from reliefkit.scene.views import orbit_bounds

    for bounds in ([[0, 0, 0], [np.inf, 1, 1]], [[0, 0, 0], [np.nan, 1, 1]],
                   [[-1e300] * 3, [1e300] * 3]):
        with pytest.raises(FormatError, match="bounds"):
            orbit_bounds(np.array(bounds), 30, 25)
    camera = orbit_bounds(np.array([[-1e6] * 3, [1e6] * 3]), 30, 25, 2.0)
    assert np.isfinite(camera.proj).all() and camera.near < camera.far


# ------------------------------------------------------------------ 3. outputs checked first

@pytest.mark.parametrize("flag, name", [("--aovs", "missing/a.npz"), ("--aovs", "adir.npz"),
                                        ("--stats", "missing/s.json"),
                                        ("--stats", "adir.json"), ("-o", "missing/x.png"),
                                        ("-o", "adir.png"), ("-o", "x.png/"),
                                        ("--aovs", "a.npz/"), ("--stats", "s.json/")])
def test_a_bad_output_path_is_refused_before_rendering(tmp_path, flag, name):
    (tmp_path / "adir.npz").mkdir()
    (tmp_path / "adir.json").mkdir()
    (tmp_path / "adir.png").mkdir()
    args = ["render", "demo:blob", "--size", "8x8", "-o", "x.png", flag, name]
    if flag == "-o":
        args = ["render", "demo:blob", "--size", "8x8", "-o", name]
    result = run_cli(*args, cwd=tmp_path)
    assert_one_line_error(result, flag, name, code=2)
    assert not (tmp_path / "x.png").exists()  # nothing rendered, nothing written
    assert "wrote" not in result.stdout
    assert not [p for p in tmp_path.rglob("*") if p.is_file()]


def test_a_read_only_folder_is_refused_before_rendering(tmp_path, monkeypatch, capsys):
    """Simulated (the tests may run as root, for whom every folder is writable)."""
    locked = tmp_path / "locked"
    locked.mkdir()
    real_access = os.access
    monkeypatch.setattr(os, "access", lambda p, mode: False if Path(p) == locked
                        else real_access(p, mode))
    monkeypatch.setattr("reliefkit.cli.commands.load_input",
                        lambda spec: pytest.fail("the input was loaded"))
    status = cli.main(["render", "demo:blob", "-o", str(tmp_path / "x.png"), "--aovs",
                       str(locked / "a.npz")])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1 and "not writable" in err[0], err
    assert not (tmp_path / "x.png").exists()
    status = cli.main(["compare", "demo:blob", "--out", str(locked)])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1 and "--out" in err[0] and "not writable" in err[0]
    status = cli.main(["bake", "demo:blob", "-o", str(locked / "b.rk")])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1 and "not writable" in err[0]


def test_a_bake_output_with_a_trailing_slash_is_refused(tmp_path):
    result = run_cli("bake", "demo:blob", "--as", "relief", "-o", "b.rk/", cwd=tmp_path)
    assert_one_line_error(result, "b.rk/", "names a folder", code=2)
    assert list(tmp_path.iterdir()) == []


def test_compare_out_that_is_a_file_is_refused_before_the_bake(tmp_path):
    (tmp_path / "taken").write_text("")
    result = run_cli("compare", "demo:blob", "--out", "taken", cwd=tmp_path)
    assert_one_line_error(result, "--out", "taken", "not a folder", code=2)
    assert "baking" not in result.stderr


@pytest.mark.parametrize("command", [["demo"], ["bench", "relief", "--quick"]])
def test_demo_and_bench_out_that_is_a_file_is_refused_first(tmp_path, command):
    (tmp_path / "taken").write_text("")
    result = run_cli(*command, "--out", "taken", cwd=tmp_path)
    assert_one_line_error(result, "--out", "taken", "not a folder", code=2)


def test_a_file_size_limit_names_the_output(tmp_path):
    resource = pytest.importorskip("resource")

    def limit():
        resource.setrlimit(resource.RLIMIT_FSIZE, (16 * 1024, 16 * 1024))

    result = run_cli("render", "demo:blob", "--size", "300x300", "-o", "x.png", cwd=tmp_path,
                     preexec_fn=limit, env={**os.environ, "MESA_SHADER_CACHE_DISABLE": "true"})
    assert_one_line_error(result, "x.png", "File too large")
    assert ".tmp" not in result.stderr and os.listdir(tmp_path) == []


# ------------------------------------------------------------------ 4. compare and info agree

def test_compare_refuses_a_heightmap_with_a_clear_line_and_help_says_so(heights, tmp_path):
    result = run_cli("compare", heights, "--out", tmp_path / "c")
    assert_one_line_error(result, "not a heightmap", "no mesh to compare", code=2)
    assert not (tmp_path / "c").exists()
    helptext = run_cli("compare", "--help").stdout
    assert "not a heightmap" in " ".join(helptext.split())


def test_info_says_ok_only_for_files_render_loads(gl, small_rk, tmp_path):
    out = run_cli("info", small_rk)
    assert out.returncode == 0, out.stderr
    pairs = [line.split() for line in out.stdout.splitlines()]
    assert ["checksums:", "ok"] in pairs and ["valid:", "ok"] in pairs
    report = json.loads(run_cli("info", "--json", small_rk).stdout)["file"]
    assert report["checksums"] == report["valid"] == "ok"
    # a forged file whose checksums are right but whose representation is invalid
    from reliefkit.io.rk import load, write_rk

    rep = load(small_rk)
    codec = registry().codecs().for_object(rep)
    arrays, params = codec.to_arrays(rep)
    arrays = dict(arrays)
    arrays["box_to_world"] = (np.diag([1e300] * 3 + [1.0]) @ arrays["box_to_world"]).astype(
        arrays["box_to_world"].dtype)
    forged = tmp_path / "forged.rk"
    write_rk(forged, codec.kind, arrays, params)
    rendered = run_cli("render", forged, "--size", "8x8", "-o", tmp_path / "f.png")
    assert_one_line_error(rendered, "forged.rk", code=1)
    for args in (["info", forged], ["info", "--json", forged]):
        result = run_cli(*args)
        assert_one_line_error(result, "forged.rk", code=1)
        assert "ok" not in result.stdout


# ------------------------------------------------------------------ 5. host memory

def test_a_render_over_the_host_memory_cap_is_refused_before_allocating(gl, tmp_path):
    result = run_cli("render", "demo:blob", "--size", "6000x6000", "-o", tmp_path / "b.png",
                     "--aovs", tmp_path / "b.npz")
    assert_one_line_error(result, "host memory", "GiB", code=1)
    assert not list(tmp_path.iterdir())


def test_host_memory_estimate_and_cap(monkeypatch):
    from reliefkit.errors import GPUError
    from reliefkit.gl import targets

    assert targets.host_limit() <= targets.MAX_HOST_BYTES
    assert targets.host_bytes(6000, 6000) > 4 << 30 > targets.host_bytes(4096, 4096)
    assert targets.host_bytes(64, 64, 1, msaa=4, transparent=True) > \
        targets.host_bytes(64, 64)
    targets.check_host_memory(4096, 4096)
    monkeypatch.setattr(targets, "host_limit", lambda: 1 << 20)
    with pytest.raises(GPUError, match="host memory"):
        targets.check_host_memory(512, 512)


# ------------------------------------------------------------------ 6. loader warnings

@pytest.fixture
def warned_mesh(monkeypatch):
    """``load_input`` returns a mesh that carries two loader warnings."""
    from reliefkit.scene.assets import make_asset

    mesh = make_asset("blob")
    mesh.extra["warnings"] = ["model.mtl is missing: the default material is used",
                              "texture a.png cannot be read\n(truncated): material colour"]
    monkeypatch.setattr("reliefkit.cli.commands.load_input", lambda spec: mesh)
    return mesh


def _warnings_of(err: str) -> list[str]:
    lines = [line for line in err.splitlines() if line.strip()]
    assert all(line.startswith("warning: ") or ": " in line for line in lines), lines
    return [line for line in lines if line.startswith("warning: ")]


@pytest.mark.parametrize("command", ["render", "bake", "info", "compare"])
def test_loader_warnings_are_one_line_each(gl, warned_mesh, tmp_path, capsys, command):
    args = {"render": ["render", "model.obj", "--size", "16x16", "-o", str(tmp_path / "x.png")],
            "bake": ["bake", "model.obj", "--as", "relief", "--depth-res", "16", "-o",
                     str(tmp_path / "x.rk")],
            "info": ["info", "model.obj"],
            "compare": ["compare", "model.obj", "--depth-res", "16", "--size", "16x16",
                        "--out", str(tmp_path / "c")]}[command]
    status = cli.main(args)
    err = capsys.readouterr().err
    assert status == 0, err
    assert _warnings_of(err) == [
        "warning: model.mtl is missing: the default material is used",
        "warning: texture a.png cannot be read (truncated): material colour"], err
    assert "error" not in err


def test_python_warnings_become_one_warning_line(capsys):
    """What `main` runs under: a library's warning is one line, numpy's float warnings none."""
    import warnings

    with np.errstate(all="warn"), cli._one_line_warnings():
        warnings.warn("a big\ntexture", UserWarning, stacklevel=1)
        np.array([1e39]).astype(np.float32)  # "overflow encountered in cast": silenced
        np.float32(3e38) * np.float32(10)
        np.zeros(1) / np.zeros(1)
        from PIL import Image

        warnings.warn("Image size (200000000 pixels) exceeds limit of 178956970 pixels, "
                      "could be decompression bomb DOS attack.", Image.DecompressionBombWarning,
                      stacklevel=1)
    err = capsys.readouterr().err.strip().splitlines()
    assert err[0] == "warning: a big texture" and len(err) == 2, err
    assert err[1].startswith("warning: Image size (200000000 pixels)"), err


# ------------------------------------------------------------------ 7. signals at any moment

SIGNAL_OUTCOMES = {"SIGINT": (130, "error: interrupted"),
                   "SIGTERM": (143, "error: terminated (SIGTERM)")}


def _wait_for_numpy(proc) -> None:
    """Until the child has mapped numpy's core library: by then its own code runs (the CLI
    imports numpy only after taking the signals), past the interpreter's startup, however
    loaded the machine is."""
    import time

    maps = Path(f"/proc/{proc.pid}/maps")
    while "_multiarray_umath" not in maps.read_text():
        assert proc.poll() is None, "the command ended before importing numpy"
        time.sleep(0.005)


@pytest.mark.skipif(not Path("/proc/self/maps").exists(), reason="needs /proc")
@pytest.mark.parametrize("name", sorted(SIGNAL_OUTCOMES))
@pytest.mark.parametrize("delay", [0.0, 0.5, 1.2, 3.0])
def test_a_signal_at_any_moment_is_one_line_and_no_output(tmp_path, name, delay):
    """Delays from numpy's import fall in the libraries' imports (the first ~2 s), the
    parser's and the bake: each ends in the documented line and exit status, no file left."""
    import signal
    import time

    out = tmp_path / "t.rk"
    proc = subprocess.Popen([sys.executable, "-m", "reliefkit.cli", "bake", "demo:terrain",
                             "--as", "relief", "--depth-res", "512", "-o", out],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    _wait_for_numpy(proc)
    time.sleep(delay)
    proc.send_signal(getattr(signal, name))
    _, err = proc.communicate(timeout=300)
    code, line = SIGNAL_OUTCOMES[name]
    assert proc.returncode == code, err
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith(line), err
    assert list(tmp_path.iterdir()) == []


def _swallow(exc):
    return None  # an import guard (trimesh's ``except BaseException``)


def _wrap(exc):
    raise RuntimeError("Error calling __set_name__") from exc  # what dataclasses does


@pytest.mark.parametrize("library", [_swallow, _wrap])
def test_an_interrupt_a_library_swallows_or_wraps_still_stops_the_command(
        tmp_path, capsys, monkeypatch, library):
    """A Ctrl-C that a library swallows, or turns into its own exception, must neither let
    the command go on to write its output nor be reported as an internal error."""
    import importlib
    import signal

    bake_module = importlib.import_module("reliefkit.cli.commands")  # where the CLI finds bake
    real_bake = bake_module.bake

    def bake_inside_a_library(*args, **kwargs):
        try:
            os.kill(os.getpid(), signal.SIGINT)
        except BaseException as exc:
            library(exc)
        return real_bake(*args, **kwargs)

    monkeypatch.setattr(bake_module, "bake", bake_inside_a_library)
    out = tmp_path / "h.rk"
    status = cli.main(["bake", "demo:blob", "--as", "relief", "--depth-res", "16",
                       "--no-safety", "-o", str(out)])
    assert (status, capsys.readouterr().err.strip().splitlines()[-1]) == \
        (130, "error: interrupted")
    assert list(tmp_path.iterdir()) == []


# ------------------------------------------------------------------ 8. exit statuses

@pytest.mark.parametrize("args, code", [
    (["render", "missing.obj", "-o", "x.png"], 1),
    (["render", "demo:nope", "-o", "x.png"], 1),
    (["bake", "demo:sphere", "--as", "shell-volume", "--texture", "missing.npy", "-o",
      "x.rk"], 1),
    (["bake", "demo:sphere", "--as", "shell-volume", "--texture", "missing.obj", "-o",
      "x.rk"], 1),
    (["bake", "demo:sphere", "--as", "shell-volume", "--texture", "demo:nope", "-o",
      "x.rk"], 1),
    (["bake", "demo:sphere", "--as", "shell-volume", "--texture", "furr", "-o", "x.rk"], 2),
    (["render", "demo:blob", "--view", "1,2,3,4", "-o", "x.png"], 2),
])
def test_exit_statuses_follow_the_table(tmp_path, args, code):
    """docs/cli.md: 1 for a missing input, whichever flag names it; 2 for a bad value."""
    assert_one_line_error(run_cli(*args, cwd=tmp_path), code=code)
    assert list(tmp_path.iterdir()) == []


# ------------------------------------------------------------------ 9. forged values out

def _with_manifest(path, out, edit):
    """A copy of the .rk ``path`` whose manifest text went through ``edit``."""
    import zipfile

    with zipfile.ZipFile(path) as src, zipfile.ZipFile(out, "w") as dst:
        for info in src.infolist():
            data = src.read(info)
            if info.filename == "manifest.json":
                data = edit(data.decode()).encode()
            dst.writestr(info, data)
    return out


def test_info_json_is_strict_json_for_forged_non_finite_params(small_rk, tmp_path):
    def add_params(text):
        manifest = json.loads(text)
        manifest["params"].update(forged_nan="@NaN", forged_inf=["@Infinity", 1.5])
        return json.dumps(manifest).replace('"@NaN"', "NaN").replace('"@Infinity"',
                                                                     "-Infinity")

    forged = _with_manifest(small_rk, tmp_path / "nan.rk", add_params)
    result = run_cli("info", "--json", forged)
    assert result.returncode == 0, result.stderr

    def refuse(constant):
        raise ValueError(f"not JSON: {constant}")

    params = json.loads(result.stdout, parse_constant=refuse)["file"]["params"]
    assert params["forged_nan"] is None and params["forged_inf"] == [None, 1.5]


# ------------------------------------------------------------------ 10. sequences

@pytest.mark.parametrize("name", ["a.gif", "seq/%02d.png", "a.mp4"])
def test_streamed_animations_are_written_frame_by_frame(tmp_path, name):
    """Each frame is encoded and released before the next is drawn (a 1,000-view turntable
    at 2048x2048 needs one frame's memory), and decodes to what was given."""
    import weakref

    from PIL import Image

    from reliefkit.animation import save_animation

    rng = np.random.default_rng(1)
    palette = rng.integers(0, 256, (200, 3), dtype=np.uint8)  # few colours: exact in a GIF
    given, alive = [], []

    def frame(k):
        assert not any(ref() is not None for ref in alive), f"a frame before {k} is kept"
        rgba = np.full((24, 32, 4), 255, np.uint8)
        rgba[..., :3] = palette[rng.integers(0, 200, (24, 32))]
        given.append(rgba[..., :3].copy())
        alive.append(weakref.ref(rgba))
        return rgba

    def frames():
        for k in range(5):
            yield frame(k)

    save_animation(frames(), tmp_path / name, 5)
    assert len(given) == 5
    if name.endswith(".mp4"):
        import imageio_ffmpeg

        assert imageio_ffmpeg.count_frames_and_secs(str(tmp_path / name))[0] == 5
        return
    if name.endswith(".gif"):
        with Image.open(tmp_path / name) as gif:
            assert gif.n_frames == 5 and gif.info["loop"] == 0
            decoded = []
            for k in range(5):
                gif.seek(k)
                decoded.append(np.asarray(gif.convert("RGB")))
    else:
        decoded = [np.asarray(Image.open(tmp_path / (name % k)).convert("RGB"))
                   for k in range(5)]
    for got, expected in zip(decoded, given, strict=True):
        np.testing.assert_array_equal(got, expected)


def test_held_formats_are_refused_when_their_frames_would_not_fit(tmp_path):
    """APNG and WebP writers take every frame at once: refused up front with the estimate,
    pointing at the formats that stream."""
    result = run_cli("render", "demo:blob", "--turntable", "3600", "--size", "2048x2048",
                     "-o", tmp_path / "spin.webp")
    assert_one_line_error(result, "GiB", ".gif", ".mp4", code=2)
    assert not (tmp_path / "spin.webp").exists()


@pytest.mark.parametrize("flag", ["--turntable", "--animate"])
def test_sequence_lengths_follow_the_docs(tmp_path, flag):
    result = run_cli("render", "demo:blob", flag, "3601", "-o", tmp_path / "s.gif")
    assert_one_line_error(result, flag, "1..3600", code=2)


@pytest.mark.parametrize("sequence", [["demo:blob", "--turntable", "6"],
                                      ["demo:sphere:shell", "--animate", "6"]])
def test_a_gif_over_the_file_size_limit_is_one_line(tmp_path, sequence):
    resource = pytest.importorskip("resource")
    if sequence[0] == "demo:sphere:shell":
        shell = tmp_path / "s.rk"
        baked = run_cli("bake", "demo:sphere", "--as", "shell-volume", "--texture-size",
                        "8,8,4", "-o", shell)
        assert baked.returncode == 0, baked.stderr
        sequence = [shell, *sequence[1:]]

    def limit():
        resource.setrlimit(resource.RLIMIT_FSIZE, (8 * 1024, 8 * 1024))

    out = tmp_path / "out"
    out.mkdir()
    result = run_cli("render", *sequence, "--size", "96x96", "-o", "x.gif", cwd=out,
                     preexec_fn=limit, env={**os.environ, "MESA_SHADER_CACHE_DISABLE": "true"})
    result.stderr = "".join(line for line in result.stderr.splitlines(keepends=True)
                            if not line.startswith(("turntable: ", "animate: ")))  # progress
    assert_one_line_error(result, "x.gif", "File too large", code=2)
    assert os.listdir(out) == []


# ------------------------------------------------------------------ 11. several outputs

def _full_disk_for(monkeypatch, name: str):
    """Writing the temporary file of the output ``name`` fails as on a full disk."""
    import errno

    real = Path.write_text

    def write_text(self, *args, **kwargs):
        if self.name.startswith(f".{name}."):
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return real(self, *args, **kwargs)

    monkeypatch.setattr(Path, "write_text", write_text)


def test_a_render_whose_stats_cannot_be_written_leaves_none_of_its_outputs(
        gl, tmp_path, capsys, monkeypatch):
    _full_disk_for(monkeypatch, "s.json")
    status = cli.main(["render", "demo:blob", "--size", "16x16", "-o", str(tmp_path / "x.png"),
                       "--aovs", str(tmp_path / "a.npz"), "--stats", str(tmp_path / "s.json")])
    captured = capsys.readouterr()
    assert status == 2 and "wrote" not in captured.out, captured
    assert captured.err.strip().splitlines() == [
        f"error: cannot write {tmp_path / 's.json'}: No space left on device; nothing was "
        "written"]
    assert list(tmp_path.iterdir()) == []


def test_a_compare_whose_json_cannot_be_written_leaves_none_of_its_files(
        gl, tmp_path, capsys, monkeypatch):
    _full_disk_for(monkeypatch, "metrics.json")
    out = tmp_path / "c"
    status = cli.main(["compare", "demo:blob", "--depth-res", "16", "--size", "16x16",
                       "--out", str(out)])
    assert status == 2, capsys.readouterr().err
    assert "No space left" in capsys.readouterr().err
    assert list(out.iterdir()) == []


# ------------------------------------------------------------------ 12. sizes before inflating

def _forge_shape(small, out, name: str, shape: tuple) -> Path:
    """A copy of the .rk ``small`` whose array ``name`` declares ``shape`` (zeros, deflated
    level 9 as they stream: a few hundred KB for hundreds of MB)."""
    import zipfile

    with zipfile.ZipFile(small) as src, \
            zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED, compresslevel=9) as dst:
        manifest = json.loads(src.read("manifest.json"))
        dtype = np.dtype(manifest["arrays"][name]["dtype"])
        manifest["arrays"][name]["shape"] = list(shape)
        for info in src.infolist():
            if info.filename == "manifest.json":
                dst.writestr(info, json.dumps(manifest))
            elif info.filename != f"{name}.npy":
                dst.writestr(info, src.read(info))
        with dst.open(f"{name}.npy", "w") as member:
            np.lib.format.write_array_header_1_0(
                member, {"descr": dtype.str, "fortran_order": False, "shape": shape})
            left = int(np.prod(shape)) * dtype.itemsize
            while left:
                member.write(bytes(min(left, 1 << 22)))
                left -= min(left, 1 << 22)
    return out


def test_an_array_over_its_kinds_limit_is_refused_before_inflating(tmp_path):
    """A 0.3 MB displacement file declaring a 268 MB height field (one row over 8192 x 8192
    texels, under the container's 4 GiB cap) is refused from its declared shape, having
    allocated a few megabytes; info says so in one line."""
    import tracemalloc

    from reliefkit.errors import FormatError
    from reliefkit.io.rk import load, save
    from reliefkit.scene.assets import make_asset
    from reliefkit.techniques.slicing import DisplacementMap

    small = tmp_path / "small.rk"
    save(small, DisplacementMap(make_asset("plane"), np.ones((4, 4, 4), np.float32),
                                np.zeros((4, 4), np.float32), 0.1))
    forged = _forge_shape(small, tmp_path / "forged.rk", "height", (8193, 8192))
    assert forged.stat().st_size < 1 << 20
    tracemalloc.start()
    try:
        with pytest.raises(FormatError, match="height.*at most 67,108,864"):
            load(forged)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < 4 << 20, peak
    assert_one_line_error(run_cli("info", forged), "forged.rk", "at most", code=1)


def test_a_billboard_cloud_over_its_rectangles_is_refused_from_its_manifest(tmp_path):
    """``read_manifest`` reads no array data: the limit is on the declared rows."""
    from reliefkit import bake
    from reliefkit.errors import FormatError
    from reliefkit.io.rk import read_manifest, save
    from reliefkit.scene.assets import make_asset

    small = tmp_path / "small.rk"
    save(small, bake(make_asset("plane"), "billboard-cloud"))
    forged = _forge_shape(small, tmp_path / "forged.rk", "corners", (4097, 3))
    with pytest.raises(FormatError, match="corners.*at most 12,288"):
        read_manifest(forged)


@pytest.mark.parametrize("kind, params, name, shape, words", [
    ("depth-object", {"res": 8}, "depth", (6, 2048, 2048), "depth object: mask must have"),
    ("displacement", {}, "color", (2048, 2048, 4), "'color' (2048, 2048, 4) and 'height'"),
])
def test_arrays_whose_shapes_disagree_are_refused_before_inflating(tmp_path, kind, params,
                                                                   name, shape, words):
    """One array declared 100 MB, the others its kind's small ones: the disagreement is in
    the declared shapes, so ``read_manifest`` (no array data) refuses it."""
    from reliefkit import bake
    from reliefkit.errors import FormatError
    from reliefkit.io.rk import read_manifest, save
    from reliefkit.scene.assets import make_asset

    small = tmp_path / "small.rk"
    save(small, bake(make_asset("blob" if kind == "depth-object" else "plane"), kind,
                     **params))
    forged = _forge_shape(small, tmp_path / "forged.rk", name, shape)
    with pytest.raises(FormatError, match=re.escape(words)):
        read_manifest(forged)
