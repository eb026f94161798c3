"""The impostor through the command line: bake, render with --stats, compare with the mesh."""

from __future__ import annotations

import json

from helpers import run_cli


def test_bake_render_and_stats(gl, tmp_path):
    rk = tmp_path / "imp.rk"
    done = run_cli("bake", "demo:vehicle", "--as", "octahedral-impostor", "--grid", "6",
                   "--hemi", "--atlas-res", "192", "-o", rk)
    assert done.returncode == 0, done.stderr
    assert "octahedral impostor: 6 x 6 frames (hemi map) of 32 x 32 texels, atlases 192²: " \
        "colour RGBA8, normals RGB8, depth R8" in done.stdout
    stats = tmp_path / "s.json"
    done = run_cli("render", rk, "--parallax-steps", "3", "--shadows", "--size", "64x64",
                   "--view", "40,20", "--stats", stats, "-o", tmp_path / "v.png")
    assert done.returncode == 0, done.stderr
    counters = json.loads(stats.read_text())
    assert counters["impostor_frames"] == 36 and counters["covered"] > 500
    # depth samples: three frames, each at most the three steps and the front
    assert 3 <= counters["iterations_mean_covered"] <= counters["iterations_max"] <= 3 * 4


def test_the_bake_line_says_what_is_stored_after_compress(gl, tmp_path):
    """Not the raw atlases' bytes: the formats (the ``wrote`` line has the bytes)."""
    done = run_cli("bake", "demo:blob", "--as", "octahedral-impostor", "--grid", "6",
                   "--atlas-res", "96", "--compress", "bc", "-o", tmp_path / "imp.rk")
    assert done.returncode == 0, done.stderr
    line = next(x for x in done.stdout.splitlines() if x.startswith("octahedral impostor:"))
    assert line.endswith("atlases 96²: colour BC7, normals BC7, depth R8")


def test_compare_scores_parallax_against_none_and_the_grid_position(gl, tmp_path):
    done = run_cli("compare", "demo:vehicle", "--as", "octahedral-impostor", "--grid", "8",
                   "--atlas-res", "256", "--size", "64x64", "--out", tmp_path / "cmp")
    assert done.returncode == 0, done.stderr
    rows = json.loads((tmp_path / "cmp" / "metrics.json").read_text())["variants"]
    assert set(rows) == {"parallax", "no parallax", "shadows"}
    assert all(1 / 3 <= row["frame_weight"] <= 1 and row["depth_error_texels"] >= 0
               for row in rows.values())
    assert rows["parallax"]["iou"] > rows["no parallax"]["iou"]
