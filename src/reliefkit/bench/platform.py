"""``reliefkit bench platform``: a turntable drawn as one `render` call with a list of
cameras (one upload) against one call per camera, for every tile of the demo sheet.

Each tile (the demo's meshes and every technique's representations, with their render
options; with ``--quick`` the first tile of each kind) is drawn from 24 cameras around it
at 128 x 128 both ways, the two interleaved and
repeated, the faster of each kept; the figure is one call's time over the separate calls'
(target <= 0.5: what uploading once saves). The frames of both ways are compared too (they
must be bit-identical).
"""

from __future__ import annotations

import platform
import time
from pathlib import Path

import numpy as np

from ..demo import demo_tiles
from ..render.draw import render
from ..scene.light import DirectionalLight
from ..scene.views import framing_bounds, turntable
from .report import machine, machine_line, write_report

VIEWS = 24
SIZE = (128, 128)
REPEATS = 2
TARGET = 0.5


def run_suite(quick: bool, out: Path, log) -> tuple[str, list[Path]]:
    views = VIEWS
    rows, kinds = [], set()
    for tile in demo_tiles():
        obj = tile.make()
        if quick and type(obj) in kinds:
            continue
        kinds.add(type(obj))
        log(f"{tile.title}: {views} views")
        rows.append(_measure(tile, obj, views))
    data = {"views": views, "size": SIZE, "target": TARGET, "machine": machine(), "rows": rows}
    markdown = _markdown(data)
    return markdown, write_report(out, "platform", data, _markdown)


def _markdown(data: dict) -> str:
    views, size, rows = data["views"], data["size"], data["rows"]
    lines = [f"# Multi-view rendering: {views} views at {size[0]}x{size[1]}, one call against "
             f"{views}", "", machine_line(data["machine"]), "",
             "| tile | kind | separate calls (s) | one call (s) | ratio | identical |",
             "|---|---|---|---|---|---|"]
    for row in rows:
        met = "" if row["ratio"] <= TARGET else " (over target)"
        lines.append(f"| {row['name']} | {row['kind']} | {row['separate']:.3f} | "
                     f"{row['one_call']:.3f} | {row['ratio']:.2f}{met} | "
                     f"{'yes' if row['identical'] else 'NO'} |")
    lines += ["", f"Target: one call <= {TARGET} x the separate calls' time. "
              f"{sum(r['ratio'] <= TARGET for r in rows)} of {len(rows)} tiles meet it; "
              f"python {platform.python_version()}."]
    return "\n".join(lines) + "\n"


def _measure(tile, obj, views: int) -> dict:
    options = dict(tile.options or {})
    light = options.pop("light", None) or DirectionalLight()
    cameras = turntable(framing_bounds(obj), views, tile.view[1], tile.view[2], SIZE)
    separate_times, one_call_times = [], []
    for _ in range(REPEATS):
        start = time.perf_counter()
        separate = [render(obj, camera, light=light, **options) for camera in cameras]
        separate_times.append(time.perf_counter() - start)
        start = time.perf_counter()
        together = render(obj, cameras, light=light, **options)
        one_call_times.append(time.perf_counter() - start)
    identical = all(np.array_equal(a.color, b.color) and np.array_equal(a.depth, b.depth)
                    for a, b in zip(separate, together, strict=True))
    best_separate, best_one = min(separate_times), min(one_call_times)
    return {"name": tile.title, "kind": type(obj).__name__, "separate": best_separate,
            "one_call": best_one, "ratio": best_one / best_separate, "identical": identical}
