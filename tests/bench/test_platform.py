"""`reliefkit bench platform`: a list of views in one render call against one call per view,
with the frames of both ways compared."""

from __future__ import annotations

from reliefkit.bench import platform
from reliefkit.core.technique import DemoTile
from reliefkit.scene.assets import make_asset


def test_one_call_and_separate_calls_are_timed_and_compared(gl):
    tile = DemoTile("tree (mesh)", "tree-mesh", lambda: make_asset("tree"), (20.0, 10.0, 2.4))
    row = platform._measure(tile, tile.make(), 3)
    assert row["identical"] is True
    assert row["separate"] > 0 and row["one_call"] > 0
    assert row["ratio"] == row["one_call"] / row["separate"]
    markdown = platform._markdown({"views": 3, "size": platform.SIZE, "target": 0.5,
                                   "machine": {"renderer": "r", "gl": "g", "platform": "p",
                                               "cpu": "c", "cpus": 2, "python": "3"},
                                   "rows": [row]})
    assert "| tree (mesh) | RenderMesh |" in markdown
