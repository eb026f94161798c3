"""``reliefkit bench batch``: assets per hour of `reliefkit batch`, local and on Ray.

The assets are generated tori of 10,000 triangles (100 x 50 sections, each with its own
radii, so no two share a cache key), baked as ``relief`` with its defaults. Each executor
(local, ray) and worker count (1, 2) runs `reliefkit batch` as the user does (a fresh
process; Ray: a local cluster started for the run) on the first N assets and then on 2N,
into empty folders. The difference of the two wall times is N assets' steady-state time
(each run's start-up, the interpreter, its workers and Ray's cluster, cancels out): seconds
per asset and assets per hour come from it, the start-up is what is left of the first run.
Ray's per-asset overhead is Ray's seconds per asset minus local's at the same worker
count. A first run (discarded) warms the caches. The load average before and after says
how busy the machine was (timings on a shared machine are only as quiet as it is).
``--quick``: N = 1 instead of 4.
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

from .report import machine, machine_line, write_report

FACES = 10_000
MINOR_SECTIONS = 50
KIND = ("--as", "relief")  # its defaults: about 7 s a torus here, most of it the safety radii
EXECUTORS = ("local", "ray")
WORKERS = (1, 2)
COUNT, QUICK_COUNT = 4, 1
RUN_LIMIT_S = 1800  # one batch run; a hung one fails the row instead of the bench


def run_suite(quick: bool, out: Path, log, *, faces: int = FACES, count: int | None = None,
              kind: tuple = KIND) -> tuple[str, list[Path]]:
    """The table of ``EXECUTORS`` x ``WORKERS`` on ``count`` and 2 x ``count`` tori of
    about ``faces`` triangles baked with the ``kind`` arguments (tests pass small ones)."""
    count = count or (QUICK_COUNT if quick else COUNT)
    load_before = os.getloadavg()
    rows = []
    with tempfile.TemporaryDirectory(prefix="reliefkit-bench-batch-") as folder:
        libraries = _libraries(Path(folder), faces, count)
        log("warming up (a first run compiles and caches what later runs reuse)")
        _timed(libraries[0], Path(folder) / "warm-up", "local", 1, kind)
        for executor in EXECUTORS:
            for workers in WORKERS:
                if executor == "ray" and importlib.util.find_spec("ray") is None:
                    rows.append({"executor": executor, "workers": workers,
                                 "refused": "Ray is not installed: pip install "
                                            "'reliefkit[ray]'"})
                    continue
                log(f"{executor}, {workers} worker(s): {count} then {2 * count} assets")
                rows.append(_row(libraries, Path(folder), executor, workers, count, kind))
    data = {"faces": 2 * max(3, faces // (2 * MINOR_SECTIONS)) * MINOR_SECTIONS,
            "kind": " ".join(kind), "count": count, "machine": machine(),
            "load_average": {"before": load_before, "after": os.getloadavg()},
            "rows": rows, "speedup": _speedups(rows), "ray_overhead_s": _overheads(rows)}
    return _markdown(data), write_report(out, "batch", data, _markdown)


def _libraries(folder: Path, faces: int, count: int) -> list[Path]:
    """Two folders: the first ``count`` tori, and those with ``count`` more."""
    import trimesh  # slow to import

    major = max(3, faces // (2 * MINOR_SECTIONS))
    libraries = [folder / "first", folder / "all"]
    for library in libraries:
        library.mkdir()
    for k in range(2 * count):
        torus = trimesh.creation.torus(1.0 + 0.05 * k, 0.25 + 0.01 * k, major_sections=major,
                                       minor_sections=MINOR_SECTIONS)
        for library in libraries[k // count:]:
            torus.export(library / f"torus{k:03d}.ply")
    return libraries


def _row(libraries: list[Path], folder: Path, executor: str, workers: int, count: int,
         kind: tuple) -> dict:
    runs = [_timed(library, folder / f"out-{executor}-{workers}-{k}", executor, workers, kind)
            for k, library in enumerate(libraries)]
    row = {"executor": executor, "workers": workers, "assets": [count, 2 * count],
           "seconds": [r["seconds"] for r in runs], "ok": [r["ok"] for r in runs]}
    failed = [r["error"] for r in runs if r["error"]]
    if failed:
        return row | {"refused": failed[0]}
    per_asset = (runs[1]["seconds"] - runs[0]["seconds"]) / count
    return row | {"seconds_per_asset": per_asset,
                  "assets_per_hour": 3600 / per_asset if per_asset > 0 else None,
                  "startup_seconds": runs[0]["seconds"] - count * per_asset}


def _timed(library: Path, out: Path, executor: str, workers: int, kind: tuple) -> dict:
    """One `reliefkit batch` run in a fresh process: its wall time and ok assets."""
    command = [sys.executable, "-m", "reliefkit.cli", "batch", str(library), *kind, "--out",
               str(out), "--workers", str(workers), "--executor", executor]
    start = time.perf_counter()
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=RUN_LIMIT_S)
    except subprocess.TimeoutExpired:
        return {"seconds": RUN_LIMIT_S, "ok": 0, "error": f"ran past {RUN_LIMIT_S} s"}
    seconds = time.perf_counter() - start
    lines = (out / "batch.jsonl").read_text().splitlines() if (out / "batch.jsonl").exists() \
        else []
    ok = sum(json.loads(line)["status"] == "ok" for line in lines)
    error = None
    if done.returncode != 0:
        error = (done.stderr.strip().splitlines() or [f"exit status {done.returncode}"])[-1]
    return {"seconds": seconds, "ok": ok, "error": error}


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
    """Seconds per asset by (executor, workers), where the run measured a positive time (a
    noisy machine can make the difference of two runs meaningless)."""
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
             f"Each row: `reliefkit batch` on {n} then {2 * n} assets in fresh processes; "
             f"seconds per asset = the difference of the two wall times / {n} (start-up "
             "cancels out).", "",
             "| executor | workers | wall s (N, 2N) | s/asset | assets/hour | start-up s |",
             "|---|---|---|---|---|---|"]
    for r in data["rows"]:
        if "seconds_per_asset" not in r:
            lines.append(f"| {r['executor']} | {r['workers']} | {r.get('refused')} | | | |")
            continue
        walls = ", ".join(f"{s:.1f}" for s in r["seconds"])
        lines.append(f"| {r['executor']} | {r['workers']} | {walls} | "
                     f"{_figure(r['seconds_per_asset'])} | "
                     f"{_figure(r['assets_per_hour'], digits=0)} | "
                     f"{_figure(r['startup_seconds'], digits=1)} |")
    lines += ["", "Speedup 1 -> 2 workers: " + ", ".join(
        f"{ex} {_figure(s, 'x')}" for ex, s in data["speedup"].items()) + " (target >= 1.7x).",
              "Ray's overhead per asset (Ray's s/asset - local's): " + ", ".join(
        f"{w} worker(s) {_figure(s, ' s')}" for w, s in data["ray_overhead_s"].items())
              + " (target <= 0.5 s).", ""]
    return "\n".join(lines)
