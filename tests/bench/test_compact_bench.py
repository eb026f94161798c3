"""`reliefkit bench compact`: a compressed representation's row has its bytes from the file
and from its encodings, and its error against the mesh and the uncompressed one."""

from __future__ import annotations

from helpers import sample

from reliefkit.bench import compact
from reliefkit.compact.compact import compress
from reliefkit.render.draw import render
from reliefkit.scene.views import orbit_bounds


def test_a_compressed_row_costs_fewer_bytes_and_is_measured_against_both(gl):
    raw = sample("relief", "relief")
    rep = compress(raw)
    cameras = [orbit_bounds(raw.bounds, az, el, size=(48, 48)) for az, el in compact.VIEWS]
    raw_frames, frames = render(raw, cameras), render(rep, cameras)
    base = compact._row("a", "relief", "raw", raw, raw_frames, raw_frames, raw_frames)
    row = compact._row("a", "relief", "bc7", rep, frames, raw_frames, raw_frames)
    assert row["gpu_bytes"] < row["raw_gpu_bytes"] == base["gpu_bytes"]
    assert row["file_bytes"] < base["file_bytes"]
    assert 0 < row["ssim_raw"] < 1 and row["psnr_raw"] > 20
    markdown = compact._markdown({"views": compact.VIEWS, "size": (48, 48),
                                  "machine": {"renderer": "r", "gl": "g", "platform": "p",
                                              "cpu": "c", "cpus": 2, "python": "3"},
                                  "rows": [base, row]})
    assert "| a | relief | raw |" in markdown and "| a | relief | bc7 |" in markdown
