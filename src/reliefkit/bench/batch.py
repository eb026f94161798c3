"""``reliefkit bench batch``: assets per hour of `reliefkit batch`, local and on Ray.

The assets are generated tori of 10,000 triangles (100 x 50 sections), one shape each
turned by its own angle about its axis (so no two share a cache key, and each is the same
work), baked as the first registered baker that takes a mesh (the relief) with its
defaults. Each executor (local, ray) and worker count (1, 2) runs `reliefkit batch` on the
same N assets as the user does (a fresh process; Ray: a local cluster started for the
run), and the bench notes when each asset's line reaches ``batch.jsonl``. The steady-state
time per asset is the span from the first asset's line to the last over the N - 1 assets
between (the start-up: the interpreter, the workers and Ray's cluster, then the first
asset, falls outside it); assets per hour come from it. Ray's per-asset overhead is Ray's
seconds per asset minus local's at the same worker count. A first run (discarded) warms
the caches. The load average before and after says how busy the machine was (timings on a
shared machine are only as quiet as it is). ``--quick``: N = 3 instead of 10.
"""

from __future__ import annotations

import importlib.util
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from ..core.technique import bakers
from .report import machine, machine_line, write_report

FACES = 10_000
MINOR_SECTIONS = 50
EXECUTORS = ("local", "ray")
WORKERS = (1, 2)
COUNT, QUICK_COUNT = 10, 3
RUN_LIMIT_S = 1800  # one batch run; a hung one fails the row instead of the bench
POLL_S = 0.05


def run_suite(quick: bool, out: Path, log, *, faces: int = FACES, count: int | None = None,
              kind: tuple | None = None) -> tuple[str, list[Path]]:
    """The table of ``EXECUTORS`` x ``WORKERS`` on ``count`` tori of about ``faces``
    triangles baked with the ``kind`` arguments (default: the first registered baker that
    takes a mesh, the relief, with its defaults: about 2.5 s a torus on a quiet machine
    here; tests pass small ones)."""
    count = count or (QUICK_COUNT if quick else COUNT)
    kind = kind or ("--as", next(name for name, (_, b) in bakers().items()
                                 if "mesh" in b.sources))
    load_before = os.getloadavg()
    rows = []
    with tempfile.TemporaryDirectory(prefix="reliefkit-bench-batch-") as folder:
        library = _library(Path(folder) / "library", faces, count)
        log("warming up (a first run compiles and caches what later runs reuse)")
        _timed(library, Path(folder) / "warm-up", "local", 1, kind)
        for executor in EXECUTORS:
            for workers in WORKERS:
                row = {"executor": executor, "workers": workers, "assets": count}
                if executor == "ray" and importlib.util.find_spec("ray") is None:
                    rows.append(row | {"refused": "Ray is not installed: pip install "
                                                  "'reliefkit[ray]'"})
                    continue
                log(f"{executor}, {workers} worker(s): {count} assets")
                out_k = Path(folder) / f"out-{executor}-{workers}"
                rows.append(row | _timed(library, out_k, executor, workers, kind))
    data = {"faces": 2 * max(3, faces // (2 * MINOR_SECTIONS)) * MINOR_SECTIONS,
            "kind": " ".join(kind), "count": count, "machine": machine(),
            "load_average": {"before": load_before, "after": os.getloadavg()},
            "rows": rows, "speedup": _speedups(rows), "ray_overhead_s": _overheads(rows)}
    return _markdown(data), write_report(out, "batch", data, _markdown)


def _library(folder: Path, faces: int, count: int) -> Path:
    """``count`` tori of about ``faces`` triangles in ``folder``."""
    import trimesh  # slow to import

    folder.mkdir()
    major = max(3, faces // (2 * MINOR_SECTIONS))
    for k in range(count):  # one shape, turned about its axis: other bytes, same work
        torus = trimesh.creation.torus(1.0, 0.3, major_sections=major,
                                       minor_sections=MINOR_SECTIONS)
        torus.apply_transform(trimesh.transformations.rotation_matrix(0.1 + 0.37 * k,
                                                                      (0, 0, 1)))
        torus.export(folder / f"torus{k:03d}.ply")
    return folder


def _timed(library: Path, out: Path, executor: str, workers: int, kind: tuple) -> dict:
    """One `reliefkit batch` run in a fresh process: its wall time, its ok assets, when
    each asset's line came (seconds from the start) and the steady-state figures."""
    command = [sys.executable, "-m", "reliefkit.cli", "batch", str(library), *kind, "--out",
               str(out), "--workers", str(workers), "--executor", executor]
    lines = out / "batch.jsonl"
    arrivals: list[float] = []
    start = time.perf_counter()
    with subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                          text=True) as process:
        while process.poll() is None and time.perf_counter() - start < RUN_LIMIT_S:
            seen = len(lines.read_text().splitlines()) if lines.exists() else 0
            arrivals += [time.perf_counter() - start] * (seen - len(arrivals))
            time.sleep(POLL_S)
        if process.poll() is None:
            process.kill()
        err = process.communicate()[1]
    seconds = time.perf_counter() - start
    records = [json.loads(line) for line in lines.read_text().splitlines()] \
        if lines.exists() else []
    row = {"seconds": seconds, "ok": sum(r["status"] == "ok" for r in records),
           "arrivals": arrivals}
    if process.returncode != 0:
        return row | {"refused": (err.strip().splitlines() or
                                  [f"exit status {process.returncode}"])[-1]}
    if len(arrivals) < 2:
        return row
    per_asset = (arrivals[-1] - arrivals[0]) / (len(arrivals) - 1)
    return row | {"seconds_per_asset": per_asset,
                  "assets_per_hour": 3600 / per_asset if per_asset > 0 else None,
                  "first_asset_seconds": arrivals[0]}


def _speedups(rows: list[dict]) -> dict:
    """Per executor: seconds per asset with 1 worker over those with 2."""
    per = _measured(rows)
    return {ex: per[(ex, 1)] / per[(ex, 2)] if (ex, 1) in per and (ex, 2) in per else None
            for ex in EXECUTORS}


def _overheads(rows: list[dict]) -> dict:
    """Per worker count: Ray's seconds per asset minus local's."""
    per = _measured(rows)
    return {str(w): per[("ray", w)] - per[("local", w)]
            if ("ray", w) in per and ("local", w) in per else None for w in WORKERS}


def _measured(rows: list[dict]) -> dict:
    """Seconds per asset by (executor, workers), where the run measured one."""
    return {(r["executor"], r["workers"]): r["seconds_per_asset"] for r in rows
            if r.get("seconds_per_asset", 0) > 0}


def _figure(value, unit: str = "", digits: int = 2) -> str:
    return "-" if value is None else f"{value:.{digits}f}{unit}"


def _markdown(data: dict) -> str:
    n = data["count"]
    load = data["load_average"]
    lines = [f"# bench batch: assets per hour, {data['faces']:,}-triangle tori, "
             f"`{data['kind']}`", "",
             machine_line(data["machine"]),
             f"Load average (1, 5, 15 min) before {', '.join(f'{x:.1f}' for x in load['before'])}"
             f", after {', '.join(f'{x:.1f}' for x in load['after'])}.", "",
             f"Each row: `reliefkit batch` on the same {n} assets in a fresh process; seconds "
             f"per asset = the span from the first asset's line in batch.jsonl to the last, "
             f"over {n - 1} (start-up and the first asset fall outside it).", "",
             "| executor | workers | wall s | first asset after s | s/asset | assets/hour |",
             "|---|---|---|---|---|---|"]
    for r in data["rows"]:
        if "seconds_per_asset" not in r:
            lines.append(f"| {r['executor']} | {r['workers']} | "
                         f"{r.get('refused', 'too few assets')} | | | |")
            continue
        lines.append(f"| {r['executor']} | {r['workers']} | {r['seconds']:.1f} | "
                     f"{r['first_asset_seconds']:.1f} | {_figure(r['seconds_per_asset'])} | "
                     f"{_figure(r['assets_per_hour'], digits=0)} |")
    smoke = n < COUNT  # two workers finish 2 of 3 assets together: the gaps say nothing
    lines += ["", "Speedup 1 -> 2 workers: " + ", ".join(
        f"{ex} {_figure(s, 'x')}" for ex, s in data["speedup"].items())
              + (" (smoke run)." if smoke else " (target >= 1.7x)."),
              "Ray's overhead per asset (Ray's s/asset - local's): " + ", ".join(
        f"{w} worker(s) {_figure(s, ' s')}" for w, s in data["ray_overhead_s"].items())
              + (" (smoke run)." if smoke else " (target <= 0.5 s)."), ""]
    if smoke:
        lines += [f"A smoke run ({n} assets, --quick): it checks that every executor bakes, "
                  f"but {n - 1} gaps between assets measure no rate; the figures above are not "
                  f"to be held against the targets (>= 1.7x, <= 0.5 s). Run without --quick "
                  f"({COUNT} assets) for those.", ""]
    return "\n".join(lines)
