"""Turntables and animations in every format the output's name picks, each read back by an
independent reader (Pillow for PNG, APNG, WebP and GIF; ffmpeg for MP4) and held to the
still render of the same view."""

import numpy as np
import pytest
import trimesh
from helpers import assert_one_line_error, run_cli
from PIL import Image

VIEWS, SIZE = 3, (32, 24)


@pytest.fixture(scope="module")
def box_and_first_view(tmp_path_factory):
    """A box, and the still render of the turntable's first view (azimuth 0) as RGBA."""
    folder = tmp_path_factory.mktemp("anim")
    box = folder / "box.obj"
    trimesh.creation.box(extents=(1.0, 0.6, 0.8)).export(box)
    out = run_cli("render", box, "--view", "0,25", "--size", "x".join(map(str, SIZE)), "-o",
                  folder / "first.png")
    assert out.returncode == 0, out.stderr
    first = np.asarray(Image.open(folder / "first.png").convert("RGBA"))
    assert (first[..., 3] == 0).any() and (first[..., 3] == 255).any()
    return box, first


def turntable(box, output):
    return run_cli("render", box, "--turntable", VIEWS, "--view", "0,25", "--size",
                   "x".join(map(str, SIZE)), "-o", output)


def frames_of(path) -> list[np.ndarray]:
    with Image.open(path) as image:
        assert getattr(image, "n_frames", 1) == VIEWS
        out = []
        for k in range(VIEWS):
            image.seek(k)
            out.append(np.asarray(image.convert("RGBA")))
    return out


@pytest.mark.parametrize("name", ["spin.png", "spin.apng", "spin.webp"])
def test_apng_and_webp_keep_alpha_exactly(gl, box_and_first_view, tmp_path, name):
    box, first = box_and_first_view
    out = turntable(box, tmp_path / name)
    assert out.returncode == 0, out.stderr
    frames = frames_of(tmp_path / name)
    np.testing.assert_array_equal(frames[0], first)
    assert not np.array_equal(frames[1], frames[0])  # another view, not a copy


def test_gif_is_transparent_where_nothing_was_drawn(gl, box_and_first_view, tmp_path):
    box, first = box_and_first_view
    out = turntable(box, tmp_path / "spin.gif")
    assert out.returncode == 0, out.stderr
    frame = frames_of(tmp_path / "spin.gif")[0]
    covered = first[..., 3] >= 128
    np.testing.assert_array_equal(frame[..., 3], np.where(covered, 255, 0))
    colour_error = np.abs(frame[covered, :3].astype(int) - first[covered, :3]).max()
    assert colour_error <= 8  # 255 colours


@pytest.mark.parametrize("pattern", ["frames/%03d.png", "folder/"])
def test_png_sequence(gl, box_and_first_view, tmp_path, pattern):
    box, first = box_and_first_view
    out = turntable(box, f"{tmp_path}/{pattern}")
    assert out.returncode == 0, out.stderr
    names = ["000", "001", "002"] if "%" in pattern else ["0000", "0001", "0002"]
    folder = tmp_path / pattern.split("/")[0]
    assert sorted(p.name for p in folder.iterdir()) == [f"{n}.png" for n in names]
    np.testing.assert_array_equal(np.asarray(Image.open(folder / f"{names[0]}.png")), first)


def test_mp4_frames_and_size(gl, box_and_first_view, tmp_path):
    imageio_ffmpeg = pytest.importorskip("imageio_ffmpeg")
    box, first = box_and_first_view
    out = turntable(box, tmp_path / "spin.mp4")
    assert out.returncode == 0, out.stderr
    reader = imageio_ffmpeg.read_frames(str(tmp_path / "spin.mp4"))
    meta = next(reader)
    frames = [np.frombuffer(f, np.uint8).reshape(SIZE[1], SIZE[0], 3) for f in reader]
    assert tuple(meta["size"]) == SIZE and len(frames) == VIEWS
    # no alpha in H.264: the box over the tile background (linear grey, sRGB-encoded here),
    # lossy but close
    from reliefkit.pictures import TILE_BACKGROUND

    linear = np.array(TILE_BACKGROUND)
    background = 255 * (1.055 * linear ** (1 / 2.4) - 0.055)
    covered, empty = first[..., 3] == 255, first[..., 3] == 0
    assert np.abs(frames[0][covered].astype(int) - first[covered, :3]).mean() < 12
    assert np.abs(frames[0][empty] - background).mean() < 4


def test_animation_names_are_checked_first(box_and_first_view, tmp_path):
    box, _ = box_and_first_view
    assert_one_line_error(run_cli("render", box, "-o", tmp_path / "x.gif"), "--turntable",
                          "--animate", code=2)
    assert_one_line_error(run_cli("render", box, "--turntable", "3", "-o", tmp_path / "x.mkv"),
                          ".webp", ".mp4", code=2)
    assert_one_line_error(run_cli("render", box, "--turntable", "3", "--size", "33x24", "-o",
                                  tmp_path / "x.mp4"), "even", "33x24", code=2)
    assert not list(tmp_path.iterdir())
