"""`reliefkit bench batch` at a tiny size: every executor and worker count has its row, the
assets it baked (counted from batch.jsonl: all N ok, each line's arrival noted) and the
figures derived from them; the report's json and markdown are written. Times are never
checked."""

from __future__ import annotations

import json
import os

from reliefkit.bench import batch, suites


def test_every_executor_and_worker_count_bakes_the_n_assets(tmp_path, gl):
    markdown, paths = batch.run_suite(True, tmp_path, lambda line: None, faces=400,
                                      kind=("--as", "relief", "--depth-res", "16"))
    assert [p.name for p in paths] == ["batch.json", "batch.md"]
    data = json.loads((tmp_path / "batch.json").read_text())
    assert data["faces"] == 400 and data["count"] == batch.QUICK_COUNT == 3
    assert data["kind"] == "--as relief --depth-res 16"
    rows = data["rows"]
    assert [(r["executor"], r["workers"]) for r in rows] == [
        (executor, workers) for executor in batch.EXECUTORS for workers in batch.WORKERS]
    for row in rows:
        if row["executor"] == "ray" and "not installed" in row.get("refused", ""):
            assert os.environ.get("CI", "").lower() != "true", "CI installs the ray extra"
            continue  # a machine without Ray
        assert "refused" not in row, row
        assert row["assets"] == row["ok"] == len(row["arrivals"]) == 3
        assert row["arrivals"] == sorted(row["arrivals"])
        assert {"seconds", "seconds_per_asset", "assets_per_hour",
                "first_asset_seconds"} <= set(row)
    assert set(data["speedup"]) == set(batch.EXECUTORS)
    assert set(data["ray_overhead_s"]) == {str(w) for w in batch.WORKERS}
    for row in rows:
        assert f"| {row['executor']} | {row['workers']} |" in markdown
    assert (tmp_path / "batch.md").read_text() == markdown
    # 3 assets measure no rate: the figures are not set beside the targets
    assert "A smoke run (3 assets, --quick)" in markdown and "(target" not in markdown
    assert "batch" in suites()
