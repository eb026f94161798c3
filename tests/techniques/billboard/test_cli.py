"""The billboard kinds through the command line, as the issue names the commands."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
from PIL import Image


def run_cli(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "reliefkit.cli", *map(str, args)],
                          capture_output=True, text=True, timeout=300, cwd=cwd)


def test_bake_reports_the_planes_and_says_which_faces_max_planes_left(gl, tmp_path):
    done = run_cli("bake", "demo:vehicle", "--as", "billboard-cloud", "--max-planes", "2",
                   "--texel-size", "0.05", "-o", tmp_path / "bbc.rk")
    assert done.returncode == 0, done.stderr
    assert "billboard cloud: 2 planes" in done.stdout
    warning = [line for line in done.stderr.splitlines() if line.startswith("warning:")]
    assert len(warning) == 1 and "max_planes=2" in warning[0]


def test_bake_render_and_stats_of_a_dmbbc(gl, tmp_path):
    rk = tmp_path / "box.rk"
    done = run_cli("bake", "demo:vehicle", "--as", "dmbbc", "--variant", "thick-shell",
                   "--texel-size", "0.05", "-o", rk)
    assert done.returncode == 0, done.stderr
    assert "dmbbc thick-shell:" in done.stdout and "billboard cloud:" in done.stdout
    for march in ("sphere", "uniform", "exact"):
        out, stats = tmp_path / f"{march}.png", tmp_path / f"{march}.json"
        done = run_cli("render", rk, "--march", march, "--samples", "2", "--size", "64x64",
                       "--view", "40,20,2.2", "--aovs", tmp_path / f"{march}.npz",
                       "--stats", stats, "-o", out)
        assert done.returncode == 0, done.stderr
        counters = json.loads(stats.read_text())
        assert counters["covered"] > 300 and counters["boxes"] > 0
        assert counters["iterations_mean_covered"] > 0
        assert (np.asarray(Image.open(out))[..., 3] > 0).sum() == counters["covered"]
    # flags of other techniques are refused once the input's technique is known
    done = run_cli("render", rk, "--method", "exact", "-o", tmp_path / "x.png")
    assert done.returncode != 0 and "--method" in done.stderr


def test_compare_as_dmbbc_scores_the_cloud_and_every_variant(gl, tmp_path):
    done = run_cli("compare", "demo:vehicle", "--as", "dmbbc", "--texel-size", "0.06",
                   "--size", "64x64", "--out", tmp_path / "cmp")
    assert done.returncode == 0, done.stderr
    rows = json.loads((tmp_path / "cmp" / "metrics.json").read_text())["variants"]
    assert set(rows) == {"billboard cloud", "sphere", "uniform", "exact", "shell",
                         "thick-shell"}
    assert rows["exact"]["wrong_hit_fraction"] == 0.0
    assert all(0 < row["iou"] <= 1 and row["psnr"] > 0 for row in rows.values())
    assert all(row["depth_error_voxels"] >= 0 for row in rows.values())
    # the compared (volumetric) boxes carry their cloud; the shells are far smaller
    assert rows["sphere"]["bytes"] > rows["shell"]["bytes"] > rows["billboard cloud"]["bytes"]
