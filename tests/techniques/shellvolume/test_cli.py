"""`reliefkit bake --as shell-volume`, `render` with its options and `--animate`, and the
one-line errors of bad input."""

from __future__ import annotations

import json

import numpy as np
import pytest
import trimesh
from helpers import assert_one_line_error, run_cli

from reliefkit.builtins import registry
from reliefkit.io.rk import load
from reliefkit.techniques.shellvolume.representation import TexturedShell


@pytest.fixture(scope="module")
def fur_rk(tmp_path_factory):
    path = tmp_path_factory.mktemp("shell") / "fur.rk"
    out = run_cli("bake", "demo:sphere", "--as", "shell-volume", "--texture", "clouds",
                  "--thickness", "0.15", "--tile", "2,1", "--texture-size", "16,16,8",
                  "-o", path)
    assert out.returncode == 0, out.stderr
    assert "2880 tetrahedra" in out.stdout and "tiled 2x1" in out.stdout
    return path


def test_bake_writes_the_shell(fur_rk):
    rep = load(fur_rk)
    assert isinstance(rep, TexturedShell)
    assert rep.texture.tile == (2, 1) and rep.texture.shape == (8, 16, 16)
    assert np.allclose(rep.thickness, 0.15)


def test_render_with_options_stats_and_aovs(fur_rk, tmp_path):
    out = run_cli("render", fur_rk, "--size", "64x64", "--samples", "4", "--sort", "centroid",
                  "--unlit", "--no-mip", "-o", tmp_path / "a.png", "--stats", tmp_path / "s.json",
                  "--aovs", tmp_path / "a.npz")
    assert out.returncode == 0, out.stderr
    stats = json.loads((tmp_path / "s.json").read_text())
    assert stats["tetrahedra"] == 2880 and stats["sort"] == "centroid"
    assert stats["samples"] == 4 and stats["unlit"] is True
    aovs = np.load(tmp_path / "a.npz", allow_pickle=False)
    assert np.isfinite(aovs["position"][..., 0]).sum() > 100


def test_animate_writes_a_gif(fur_rk, tmp_path):
    from PIL import Image

    out = run_cli("render", fur_rk, "--size", "48x48", "--samples", "2", "--animate", "3",
                  "-o", tmp_path / "a.gif")
    assert out.returncode == 0, out.stderr
    with Image.open(tmp_path / "a.gif") as gif:
        assert gif.n_frames == 3


def test_animate_needs_an_animated_input_and_an_animation_name(fur_rk, tmp_path):
    assert_one_line_error(run_cli("render", "demo:blob", "--animate", "2", "-o",
                                  tmp_path / "a.gif"), "no animation")
    assert_one_line_error(run_cli("render", fur_rk, "--animate", "2", "-o",
                                  tmp_path / "a.jpg"), ".gif", ".webp")
    assert_one_line_error(run_cli("render", fur_rk, "--animate", "2", "--time", "0.5", "-o",
                                  tmp_path / "a.gif"), "--time")


def test_bad_bake_input(tmp_path):
    plain = tmp_path / "box.stl"
    trimesh.creation.box().export(plain)
    assert_one_line_error(run_cli("bake", plain, "--as", "shell-volume", "-o",
                                  tmp_path / "x.rk"), "uvs")
    assert_one_line_error(run_cli("bake", "demo:sphere", "--as", "shell-volume", "--tile",
                                  "1.5,2", "-o", tmp_path / "x.rk"), "whole numbers")
    assert_one_line_error(run_cli("bake", "demo:sphere", "--as", "shell-volume", "--texture",
                                  "furr", "-o", tmp_path / "x.rk"), "not one of fur")
    bad = tmp_path / "bad.npy"
    np.save(bad, np.zeros((4, 4, 4, 3), np.float32))
    assert_one_line_error(run_cli("bake", "demo:sphere", "--as", "shell-volume", "--texture",
                                  bad, "-o", tmp_path / "x.rk"), "(D, H, W, 4)")
    assert not (tmp_path / "x.rk").exists()


def test_a_too_thick_shell_is_thinned_where_it_folds(tmp_path):
    """On a torus of minor radius 0.35, 1.0 folds the inner side: thinner there, with a
    warning, the outer side keeps 1.0."""
    out = run_cli("bake", "demo:torus", "--as", "shell-volume", "--thickness", "1",
                  "-o", tmp_path / "t.rk")
    assert out.returncode == 0, out.stderr
    assert "warning: the shell is thinner" in out.stderr
    thickness = load(tmp_path / "t.rk").thickness
    assert thickness.max() == 1.0 and thickness.min() < 0.5


def test_npy_and_voxelized_textures(tmp_path):
    rgba = np.zeros((4, 8, 8, 4), np.float32)
    rgba[0] = (0.2, 0.8, 0.2, 1.0)
    np.save(tmp_path / "moss.npy", rgba)
    out = run_cli("bake", "demo:plane", "--as", "shell-volume", "--texture",
                  tmp_path / "moss.npy", "-o", tmp_path / "moss.rk")
    assert out.returncode == 0, out.stderr
    assert np.array_equal(load(tmp_path / "moss.rk").texture.rgba, rgba)  # taken as given
    out = run_cli("bake", "demo:plane", "--as", "shell-volume", "--texture", "demo:tree",
                  "--texture-size", "16,16,16", "-o", tmp_path / "trees.rk")
    assert out.returncode == 0, out.stderr
    trees = load(tmp_path / "trees.rk").texture
    assert trees.opaque and 0.01 < trees.rgba[..., 3].mean() < 0.5
    # the trunk stands on the ground (w = 0) and the crown is above it
    filled = trees.rgba[..., 3].mean(axis=(1, 2))
    assert filled[0] > 0 and filled[-1] < filled.max()


def test_corrupt_file_is_refused(fur_rk, tmp_path):
    import zipfile

    broken = tmp_path / "broken.rk"
    with zipfile.ZipFile(fur_rk) as src, zipfile.ZipFile(broken, "w") as dst:
        for item in src.infolist():
            data = src.read(item)
            if item.filename == "thickness.npy":
                data = data[:-8]
            dst.writestr(item, data)
    assert_one_line_error(run_cli("render", broken, "-o", tmp_path / "b.png"))


def test_npy_texture_through_a_symlink_but_not_a_fifo(tmp_path):
    """A symlink to a regular .npy is that file; a FIFO is refused at once (never read)."""
    import os

    rgba = np.zeros((4, 8, 8, 4), np.float32)
    rgba[0] = (0.2, 0.8, 0.2, 1.0)
    np.save(tmp_path / "moss.npy", rgba)
    os.symlink(tmp_path / "moss.npy", tmp_path / "link.npy")
    out = run_cli("bake", "demo:plane", "--as", "shell-volume", "--texture",
                  tmp_path / "link.npy", "-o", tmp_path / "moss.rk")
    assert out.returncode == 0, out.stderr
    assert np.array_equal(load(tmp_path / "moss.rk").texture.rgba, rgba)
    if hasattr(os, "mkfifo"):
        os.mkfifo(tmp_path / "pipe.npy")
        assert_one_line_error(run_cli("bake", "demo:plane", "--as", "shell-volume",
                                      "--texture", tmp_path / "pipe.npy", "-o",
                                      tmp_path / "x.rk"), "not a regular file")


def test_a_texture_without_voxels_is_refused(fur_rk, tmp_path):
    """A forged file whose texture has depth 0: one line, not a division by zero."""
    from reliefkit.io import rk

    rep = load(fur_rk)
    codec = registry().codecs().for_object(rep)  # forging needs the codec's arrays
    arrays, params = codec.to_arrays(rep)
    arrays = {k: v for k, v in arrays.items() if v is not None}
    arrays["texture_rgba"] = np.zeros((0, 16, 16, 4), np.float32)
    arrays["texture_normal"] = np.zeros((0, 16, 16, 3), np.float32)
    forged = rk.write_rk(tmp_path / "empty.rk", "shell-volume", arrays, params)
    assert_one_line_error(run_cli("render", forged, "--size", "32x32", "-o",
                                  tmp_path / "e.png"), "at least 1")


def test_a_texture_that_would_take_minutes_is_refused_with_the_estimate(tmp_path):
    """256^3 voxels of fur took minutes and GBs; refused at once, with the estimate."""
    out = run_cli("bake", "demo:sphere", "--as", "shell-volume", "--texture-size",
                  "256,256,256", "-o", tmp_path / "x.rk")
    assert_one_line_error(out, "16,777,216 voxels", "minutes", "GiB", "128,128,128")
    assert not (tmp_path / "x.rk").exists()


def test_a_shell_no_gpu_is_sure_to_hold_is_refused_before_it_is_built():
    """A grid of 700,928 triangles (2.1M tetrahedra, over OpenGL 4.3's 16384 texture rows of
    128): refused by the bake and by the representation, before the shell is built."""
    from reliefkit.errors import UsageError
    from reliefkit.scene.mesh import RenderMesh
    from reliefkit.techniques.shellvolume.bakers import ShellVolumeParams, bake_shell
    from reliefkit.techniques.shellvolume.textures import make_absorption

    n = 593
    x, y = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n), indexing="ij")
    at = np.arange(n * n).reshape(n, n)
    a, b, c, d = at[:-1, :-1].ravel(), at[1:, :-1].ravel(), at[1:, 1:].ravel(), at[:-1, 1:].ravel()
    faces = np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    positions = np.column_stack([x.ravel(), y.ravel(), np.zeros(n * n)])
    grid = RenderMesh(positions, faces, np.tile([0.0, 0.0, 1.0], (n * n, 1)),
                      np.ones((n * n, 4)), positions[:, :2])
    with pytest.raises(UsageError, match="at most 699,050 triangles"):
        bake_shell(grid, ShellVolumeParams(texture="absorption", thickness=0.01))
    with pytest.raises(UsageError, match="700,928 triangles"):
        TexturedShell(grid, 0.01, make_absorption(size=(4, 4, 4)))


def test_render_warns_when_the_order_breaks_cycles(tmp_path):
    """Two spheres passing through each other: the render says how many cycles its sort
    broke and names the exact --sort peel, on one warning line."""
    from shell_scenes import sphere_mesh

    sphere = sphere_mesh(2)
    lines = []
    for shift in (0.0, 0.8):
        lines += [f"v {x + shift:.6f} {y:.6f} {z:.6f}" for x, y, z in sphere.world_positions]
        lines += [f"vt {u:.6f} {v:.6f}" for u, v in sphere.uvs]
    count = len(sphere.positions)
    for k in range(2):
        lines += ["f " + " ".join(f"{i + 1 + k * count}/{i + 1 + k * count}" for i in tri)
                  for tri in sphere.indices]
    (tmp_path / "two.obj").write_text("\n".join(lines) + "\n")
    out = run_cli("bake", tmp_path / "two.obj", "--as", "shell-volume", "--texture", "clouds",
                  "--texture-size", "16,16,8", "--thickness", "0.2", "-o", tmp_path / "two.rk")
    assert out.returncode == 0, out.stderr
    out = run_cli("render", tmp_path / "two.rk", "--size", "48x48", "--samples", "2", "-o",
                  tmp_path / "two.png")
    assert out.returncode == 0, out.stderr
    warned = [line for line in out.stderr.splitlines() if "cycles" in line]
    assert len(warned) == 1 and warned[0].startswith("warning: the visibility order broke")
    assert "--sort peel" in warned[0]
    out = run_cli("compare", tmp_path / "two.obj", "--as", "shell-volume", "--texture",
                  "clouds", "--texture-size", "16,16,8", "--thickness", "0.2", "--size",
                  "48x48", "--out", tmp_path / "cmp")
    assert out.returncode == 0, out.stderr
    warned = [line for line in out.stderr.splitlines() if "cycles" in line]
    assert warned and all(line.startswith("warning: ") and "--sort peel" in line
                          for line in warned)
    assert any(line.startswith("warning: sxmpvo: ") for line in warned)
