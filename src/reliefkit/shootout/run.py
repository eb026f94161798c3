"""The shootout of one or several meshes: every representation sized to every budget, the mesh
decimated to the same bytes, all measured against the full mesh at every screen size."""

from __future__ import annotations

import re
import shutil
import tempfile
import time
from pathlib import Path

from ..builtins import registry
from ..io.atomic import atomic_path
from ..io.inputs import load_mesh
from ..io.rk import load
from ..pictures import TILE_BACKGROUND
from ..progress import progress_bar
from ..render import render
from ..scene.decimate import decimate_to_bytes, gpu_bytes, simplified
from ..scene.sphere_views import VIEWS, cameras
from .measure import measure
from .sizing import Search, unfit_reason

DECIMATED = "decimated mesh"


def slug(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9._-]+", "-", name).strip("-") or "mesh"


def load_meshes(specs: list[str]) -> list:
    """Every mesh, loaded before any work (a bad one stops the run with its error)."""
    registry()
    return [load_mesh(spec) for spec in specs]


def size_rows(mesh, chosen, budgets, probes_dir: Path, out: Path, rk_dir: str,
              advance) -> list[dict]:
    """One row per candidate and budget: the largest knob value whose GPU bytes fit (the file
    copied into ``out``/``rk_dir``, named in the row relative to ``out``), or why none does;
    then the decimated mesh at every budget."""
    rows, done = [], 0
    for candidate in chosen:
        reason = unfit_reason(candidate, mesh)
        search = Search(candidate, mesh, probes_dir) if reason is None else None
        for budget in budgets:
            row = {"label": candidate.label, "kind": candidate.kind, "budget": budget,
                   "knob": candidate.sizing.knob, "render": candidate.sizing.render or {}}
            found = search.largest_fitting(budget) if search else None
            if found is None:
                row |= {"fits": False, "reason": reason or search.failure()}
            else:
                name = f"{rk_dir}/{candidate.label}-{budget}.rk"
                with atomic_path(out / name) as tmp:
                    shutil.copyfile(found.path, tmp)
                row |= {"fits": True, "n": found.n, "bytes": found.bytes,
                        "file_bytes": (out / name).stat().st_size, "file": name,
                        "bake_s": found.bake_s}
            if search:
                row["probes"] = search.measured()
            rows.append(row)
            done += 1
            advance(done)
    for budget in budgets:
        rows.append(decimated_row(mesh, budget))
        done += 1
        advance(done)
    return rows


def decimated_row(mesh, budget: int) -> dict:
    start = time.perf_counter()
    small = decimate_to_bytes(mesh, budget, compact=True)
    row = {"label": DECIMATED, "kind": "mesh", "budget": budget, "render": {},
           "knob": "triangles (quadric decimation; compact GPU bytes)"}
    if small is None:
        return row | {"fits": False, "reason": decimation_floor(mesh)}
    compact, raw = gpu_bytes(small, compact=True), gpu_bytes(small)
    textures = gpu_bytes(mesh, compact=True)["textures"]
    return row | {"fits": True, "n": small.triangle_count, "vertices": len(small.positions),
                  "whole": small.triangle_count == mesh.triangle_count,
                  "textures_reduced": compact["textures"] < textures,
                  "bytes": compact["total"],
                  "raw_bytes": raw["total"], "gpu_bytes": compact,
                  "bake_s": time.perf_counter() - start, "drawn": small}


def decimation_floor(mesh) -> str:
    """Why no decimation fits: where quadric decimation stops (it keeps every part's
    boundary, so a mesh of many parts has a floor), in compact bytes."""
    floor = simplified(mesh, 1)
    if floor is None:
        return "fast_simplification is missing, or decimation leaves nothing"
    return (f"quadric decimation stops at {floor.triangle_count:,} triangles, "
            f"{gpu_bytes(floor, compact=True)['total']:,} bytes compact")


def shoot_mesh(mesh, chosen, budgets, sizes, out: Path, name: str, pictures: dict) -> dict:
    """The rows of one mesh with their figures; its first view's pictures into ``pictures``
    [size][(name, budget)] (the mesh's own under budget None)."""
    rk_dir = f"rk/{name}"
    (out / rk_dir).mkdir(parents=True, exist_ok=True)
    steps = (len(chosen) + 1) * len(budgets)
    with tempfile.TemporaryDirectory(prefix="shootout-") as probes, \
            progress_bar(f"sizing {name}", steps) as advance:
        rows = size_rows(mesh, chosen, budgets, Path(probes), out, rk_dir, advance)
    cams = {size: cameras(mesh.bounds, size) for size in sizes}
    truths = {size: render(mesh, cams[size]) for size in sizes}
    for size in sizes:
        pictures.setdefault(size, {})[(name, None)] = [("mesh", truths[size][0].rgba8(
            TILE_BACKGROUND))]
    measured = [row for row in rows if row["fits"]]
    with progress_bar(f"measuring {name}", len(measured)) as advance:
        for k, row in enumerate(measured):
            drawn = row.pop("drawn", None) or load(out / row["file"])
            row["sizes"], shots = measure(drawn, mesh, cams, truths, row["render"])
            for size, image in shots.items():
                pictures[size].setdefault((name, row["budget"]), []).append(
                    (row["label"], image))
            advance(k + 1)
    full_raw, full_compact = gpu_bytes(mesh), gpu_bytes(mesh, compact=True)
    return {"name": name, "triangles": mesh.triangle_count, "has_uvs": mesh.uvs is not None,
            "gpu_bytes_raw": full_raw["total"], "gpu_bytes_compact": full_compact["total"],
            "rows": rows}


def run_shootout(meshes, names: list[str], chosen, budgets, sizes, out: Path) -> tuple[dict, dict]:
    """Every mesh's results (``{"meshes": [...], "budgets", "sizes", "views"}``) and the first
    view's pictures for the contact sheets."""
    pictures: dict = {}
    results = {"budgets": budgets, "sizes": sizes,
               "views": [{"name": n, "azimuth": a, "elevation": e} for n, a, e in VIEWS],
               "meshes": []}
    for mesh, name in zip(meshes, names, strict=True):
        results["meshes"].append(shoot_mesh(mesh, chosen, budgets, sizes, out, name,
                                            pictures))
    return results, pictures


def unique_names(meshes) -> list[str]:
    """A file-safe name per mesh, distinct (a repeated name gets -2, -3, ...)."""
    names, seen = [], {}
    for mesh in meshes:
        base = slug(mesh.name)
        seen[base] = seen.get(base, 0) + 1
        names.append(base if seen[base] == 1 else f"{base}-{seen[base]}")
    return names
