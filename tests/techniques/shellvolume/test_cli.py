"""`reliefkit bake --as shell-volume`, `render` with its options and `--animate`, and the
one-line errors of bad input."""

from __future__ import annotations

import json

import numpy as np
import pytest
import trimesh
from test_cli import assert_one_line_error, run_cli

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
