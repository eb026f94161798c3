"""`reliefkit bake --as depth-object|visual-hull`, `render` with every slicing, pass and
texturing option, `compare`, and the one-line errors of bad input."""

from __future__ import annotations

import json

import numpy as np
import pytest
from helpers import assert_one_line_error, run_cli

from reliefkit.io.rk import load
from reliefkit.techniques.slicing.representation import DepthObject, VisualHull


@pytest.fixture(scope="module")
def baked(tmp_path_factory):
    folder = tmp_path_factory.mktemp("depth")
    out = {}
    for kind in ("depth-object", "visual-hull"):
        path = folder / f"{kind}.rk"
        result = run_cli("bake", "demo:cup", "--as", kind, "--res", "32", "-o", path)
        assert result.returncode == 0, result.stderr
        assert "six 32x32 depth images" in result.stdout
        out[kind] = path
    return out


def test_bake_writes_both_kinds(baked):
    obj, hull = load(baked["depth-object"]), load(baked["visual-hull"])
    assert type(obj) is DepthObject and type(hull) is VisualHull
    assert obj.resolution == hull.resolution == 32
    assert np.array_equal(obj.images.mask, hull.images.mask)
    assert (hull.images.depth[hull.images.mask] == 0).all()


@pytest.mark.parametrize("options", [
    ("--slicing", "orthogonal", "--slices", "40"),
    ("--slicing", "screen", "--slices", "40", "--texturing", "nearest"),
    ("--slicing", "orthogonal", "--slices", "20", "--passes", "stencil"),
    ("--slicing", "screen", "--alpha-test", "slab", "--no-visibility"),
    ("--slicing", "raycast", "--unlit"),
])
def test_render_options_stats_and_aovs(baked, tmp_path, options):
    out = run_cli("render", baked["depth-object"], "--size", "64x64", *options,
                  "-o", tmp_path / "a.png", "--stats", tmp_path / "s.json",
                  "--aovs", tmp_path / "a.npz")
    assert out.returncode == 0, out.stderr
    stats = json.loads((tmp_path / "s.json").read_text())
    given = dict(zip(options[::2], options[1::2], strict=False))
    assert stats["slicing"] == given["--slicing"]
    if "--slices" in given:
        assert stats["slices"] == int(given["--slices"])
    if "--passes" in given:
        assert stats["passes"] == "stencil"
    aovs = np.load(tmp_path / "a.npz")
    mask = aovs["mask"]
    assert 200 < mask.sum() < 64 * 64
    assert np.isfinite(aovs["position"][mask]).all()


def test_the_hull_fills_the_cup_seen_from_above(baked, tmp_path):
    ys = {}
    for kind, path in baked.items():
        out = run_cli("render", path, "--size", "32x32", "--view", "0,89,2.5",
                      "--slicing", "raycast", "-o", tmp_path / f"{kind}.png",
                      "--aovs", tmp_path / f"{kind}.npz")
        assert out.returncode == 0, out.stderr
        ys[kind] = np.load(tmp_path / f"{kind}.npz")["position"][16, 16, 1]
    assert ys["visual-hull"] > ys["depth-object"] + 1.0  # rim at 0.8, floor at -0.6


@pytest.mark.parametrize("options, words", [
    (("--slicing", "raycast", "--passes", "stencil"), ("ray casting has no slices",)),
    (("--slicing", "orthogonal", "--alpha-test", "slab", "--passes", "stencil"),
     ("stencil passes test one image",)),
    (("--slices", "8"), ("--slices set the slices", "ray casting (the default)")),
    (("--slicing", "sideways"), ("sideways",)),
    (("--slices", "0"), ("slices",)),
])
def test_bad_render_options_are_one_line_errors(baked, tmp_path, options, words):
    out = run_cli("render", baked["depth-object"], "--size", "32x32", *options,
                  "-o", tmp_path / "x.png")
    assert_one_line_error(out, *words)
    assert not (tmp_path / "x.png").exists()


@pytest.mark.parametrize("res", ["1", "9000", "abc"])
def test_bad_resolution_is_a_one_line_error(tmp_path, res):
    out = run_cli("bake", "demo:cup", "--as", "depth-object", "--res", res,
                  "-o", tmp_path / "x.rk")
    assert_one_line_error(out, "res")
    assert not (tmp_path / "x.rk").exists()


def test_compare_lists_every_variant_with_reference_columns(tmp_path):
    out = run_cli("compare", "demo:cup", "--as", "depth-object", "--res", "24",
                  "--size", "48x48", "--out", tmp_path / "cmp")
    assert out.returncode == 0, out.stderr
    rows = json.loads((tmp_path / "cmp" / "metrics.json").read_text())
    text = json.dumps(rows)
    for name in ("orthogonal slices", "screen slices", "ray cast", "stencil passes",
                 "nearest image", "visual hull"):
        assert name in text
    assert "reference_wrong" in text and (tmp_path / "cmp" / "compare.png").exists()


@pytest.fixture(scope="module")
def flat_van(tmp_path_factory):
    """The van: much flatter than its cube, whose corners lie far outside its bounds."""
    path = tmp_path_factory.mktemp("van") / "van.rk"
    out = run_cli("bake", "demo:vehicle", "--as", "depth-object", "--res", "32", "-o", path)
    assert out.returncode == 0, out.stderr
    return path


@pytest.mark.parametrize("view", ["30,25", "200,-30", "90,0,1.3"])
def test_framed_views_draw_the_whole_object(flat_van, tmp_path, view):
    """The CLI's views hug the object's bounds with their near and far planes: ray casting
    (whose proxy is the object's box, not the cube) and the slab test (exact slices) agree
    pixel for pixel."""
    masks = {}
    for name, options in (("ray", ("--slicing", "raycast")),
                          ("slab", ("--slicing", "orthogonal", "--slices", "24"))):
        out = run_cli("render", flat_van, "--size", "48x48", "--view", view, *options,
                      "-o", tmp_path / f"{name}.png", "--aovs", tmp_path / f"{name}.npz")
        assert out.returncode == 0, out.stderr
        masks[name] = np.load(tmp_path / f"{name}.npz")["mask"]
    assert masks["ray"].sum() > 100
    assert (masks["ray"] != masks["slab"]).sum() <= 2


@pytest.mark.parametrize(("kind", "res", "words"), [
    ("depth-object", "8192", ("12.4 GiB", "at most 4657")),          # images a .rk cannot hold
    ("visual-hull", "4096", ("7.1 GiB of host memory", "at most")),  # a bake past host_limit
])
def test_images_too_large_are_refused_with_their_estimate(tmp_path, kind, res, words):
    """--res 8192 needs 12.4 GiB of images; --res 4096 fits a .rk file but its bake peaks near
    6 x 4096² x 76 B = 7.1 GiB, over the host-memory limit (at most 4 GiB). Both are refused
    before anything is allocated, so a process limited to 3 GiB of address space gets the
    estimate, not a MemoryError or a crash."""
    resource = pytest.importorskip("resource")

    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (3 << 30, 3 << 30))

    out = run_cli("bake", "demo:cup", "--as", kind, "--res", res, "-o", tmp_path / "x.rk",
                  preexec_fn=limit)
    assert_one_line_error(out, f"res {res}", *words, code=2)
    assert not (tmp_path / "x.rk").exists()
