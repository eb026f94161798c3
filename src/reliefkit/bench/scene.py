"""``reliefkit bench scene``: a field of 1,000 and 10,000 instances of one asset, each drawn
in one instanced draw call per plan, as every representation and as the mesh decimated to
the same error, timed side by side in one run.

The asset (demo:tree, or ``--mesh FILE``) is baked by every baker of every technique with
its defaults; a representation that cannot be drawn instanced (`render.instancing`) is
reported with its reason. **Equal error**: each instanceable representation's SSIM against
the full mesh is measured on one instance at the field's screen size (three views around it
at the field's elevation, orthographic, the mean); the mesh is then decimated
(`scene.decimate`, quadric) to the fewest bytes whose SSIM at those views is at least that,
by bisection on the byte budget. The field: a square grid of instances with jittered
positions and random yaws on the ground, seen from a fixed orthographic camera at 30
degrees' elevation, so every instance's bounding sphere is exactly `INSTANCE_PX` pixels
across; the grid's spacing fills a frame `FIELD_WIDTH` pixels wide (the height follows), so
instances overlap as a forest's do. Each count's frames (the full mesh for scale, every
representation, every decimated mesh) are timed interleaved (`bench.timing.time_scenes`)
with the counts that do not depend on the device: draw calls, primitives, and samples that
passed the depth test.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..core.technique import REGISTRY
from ..errors import ReliefkitError, UsageError
from ..io.inputs import load_mesh
from ..io.rk import array_bytes
from ..metrics import ssim
from ..render.draw import render
from ..render.instancing import NotInstanceable, instanced, placements
from ..render.registry import make_drawables
from ..scene.camera import Camera
from ..scene.decimate import decimated, mesh_bytes
from ..scene.views import bounds_radius
from ..units import format_bytes
from .report import machine, machine_line, write_report
from .timing import time_scenes

ASSET = "demo:tree"
COUNTS, QUICK_COUNTS = (1_000, 10_000), (100, 400)
INSTANCE_PX, QUICK_INSTANCE_PX = 64, 32
FIELD_WIDTH, QUICK_FIELD_WIDTH = 2048, 320
MAX_PIXELS = 4 << 20        # the field's frame is refused above this (memory on llvmpipe)
ELEVATION = 30.0            # degrees, the field's camera and the equal-error views
SSIM_AZIMUTHS = (0.0, 120.0, 240.0)
JITTER = 0.25               # of the grid spacing, each way
BISECT_STEPS = 8
FLOOR = 0.002               # the smallest decimation tried, of the mesh's bytes
REPEATS, QUICK_REPEATS = 2, 1
TARGET = 0.3                # the best representation's 10,000-instance time / the mesh's


def run_suite(quick: bool, out: Path, log, mesh: str | None = None) -> tuple[str, list[Path]]:
    asset = load_mesh(mesh or ASSET)
    px = QUICK_INSTANCE_PX if quick else INSTANCE_PX
    counts = QUICK_COUNTS if quick else COUNTS
    reps, refused = bake_all(asset, log)
    views = [instance_camera(asset, az, px) for az in SSIM_AZIMUTHS]
    truth = render(asset, views)
    rows, decimations = [], {}
    for name, rep in reps.items():
        log(f"{name}: SSIM at {px} px, decimating to it")
        row, decimations[name] = equal_error(name, rep, asset, views, truth)
        rows.append(row)
    fields = []
    for n in counts:
        layout = field(asset, n, px, QUICK_FIELD_WIDTH if quick else FIELD_WIDTH)
        log(f"{n} instances: {layout['camera'].size[0]}x{layout['camera'].size[1]}")
        fields.append(time_field(asset, reps, decimations, layout,
                                 QUICK_REPEATS if quick else REPEATS))
        log(", ".join(f"{name} {t['wall_ms']:.0f} ms"
                      for name, t in fields[-1]["times"].items()))
    data = {"asset": asset.name, "instance_px": px, "elevation": ELEVATION,
            "mesh_bytes": mesh_bytes(asset), "mesh_triangles": asset.triangle_count,
            "rows": rows, "refused": refused, "fields": fields, "target": TARGET,
            "quick": quick, "machine": machine()}
    return markdown(data), write_report(out, "scene", data, markdown)


def bake_all(asset, log) -> tuple[dict, dict]:
    """Every baker's representation of ``asset`` that draws instanced (by baker name), and
    the others' reasons (a bake that fails, or `NotInstanceable`)."""
    from ..bake import bake

    reps, refused = {}, {}
    one = placements(np.zeros((1, 3)))
    for tech in REGISTRY.techniques():
        for baker in tech.bakers:
            if "mesh" not in baker.sources:
                continue
            log(f"baking {baker.name}")
            try:
                rep = bake(asset, baker.name)
                for drawable in make_drawables([rep], {}):
                    instanced(drawable.plans, one)
            except (NotInstanceable, ReliefkitError) as error:
                refused[baker.name] = str(error)
                continue
            reps[baker.name] = rep
    return reps, refused


def instance_camera(asset, azimuth: float, px: int) -> Camera:
    """One instance as the field shows it: orthographic at `ELEVATION`, its bounding sphere
    ``px`` pixels across."""
    r = bounds_radius(asset.bounds)
    return Camera.orbit(np.mean(asset.bounds, axis=0), azimuth, ELEVATION, 3 * r,
                        size=(px, px), near=r, far=5 * r, ortho_height=r)


def mean_ssim(obj, views, truth) -> float:
    return float(np.mean([ssim(f, t) for f, t in zip(render(obj, views), truth, strict=True)]))


def equal_error(name: str, rep, asset, views, truth) -> tuple[dict, object]:
    """``rep``'s SSIM against the mesh at ``views``, and the mesh decimated to the fewest
    bytes (bisection, `BISECT_STEPS` halvings of the log of the budget) that is as good:
    its row and that mesh."""
    target = mean_ssim(rep, views, truth)
    full = mesh_bytes(asset)

    def scored(budget: float):
        mesh = decimated(asset, int(budget))  # None: nothing left at that budget
        return mesh, (-1.0 if mesh is None else mean_ssim(mesh, views, truth))

    lo, hi = FLOOR * full, float(full)
    best, best_ssim = asset, 1.0
    floor_mesh, floor_ssim = scored(lo)
    if floor_ssim >= target:
        best, best_ssim, hi = floor_mesh, floor_ssim, lo
    else:
        for _ in range(BISECT_STEPS):
            mid = math.sqrt(lo * hi)
            candidate, score = scored(mid)
            if score >= target:
                best, best_ssim, hi = candidate, score, mid
            else:
                lo = mid
    return {"name": name, "kind": type(rep).__name__, "ssim": target,
            "bytes": sum(array_bytes(rep).values()), "decimated_ssim": best_ssim,
            "decimated_bytes": mesh_bytes(best), "decimated_triangles": best.triangle_count,
            "at_floor": hi <= FLOOR * full}, best


def field(asset, n: int, px: int, width: int) -> dict:
    """``n`` placements on a jittered square grid (seeded) whose spacing fills ``width``
    pixels, random yaws, and the orthographic camera that sees them all with every
    bounding sphere ``px`` pixels across."""
    rng = np.random.default_rng(30)
    r = bounds_radius(asset.bounds)
    side = math.ceil(math.sqrt(n))
    spacing = max(width * 2 * r / px - 2 * r, 0.0) / max(side - 1, 1)
    k = np.arange(n)
    grid = np.column_stack([k % side, np.zeros(n), k // side]) - [(side - 1) / 2, 0,
                                                                    (side - 1) / 2]
    xz = spacing * (grid + JITTER * rng.uniform(-1, 1, (n, 3)) * [1, 0, 1])
    yaws = rng.uniform(0, 2 * np.pi, n)
    placed = placements(xz, 1.0, yaws)
    centre = np.mean(asset.bounds, axis=0)
    c, s = np.cos(yaws), np.sin(yaws)
    centres = xz + np.column_stack([c * centre[0] + s * centre[2], np.full(n, centre[1]),
                                    -s * centre[0] + c * centre[2]])
    el = math.radians(ELEVATION)
    right, up = np.array([1.0, 0, 0]), np.array([0, math.cos(el), -math.sin(el)])
    u, v = centres @ right, centres @ up
    size = [math.ceil((a.max() - a.min() + 2 * r) * px / (2 * r)) for a in (u, v)]
    if size[0] * size[1] > MAX_PIXELS:
        raise UsageError(f"a field of {n} instances at {px} px needs a {size[0]}x{size[1]} "
                             f"frame, over {MAX_PIXELS} pixels")
    target = right * (u.max() + u.min()) / 2 + up * (v.max() + v.min()) / 2
    reach = float(np.linalg.norm(centres - target, axis=1).max()) + r
    camera = Camera.orbit(target, 0.0, ELEVATION, 2 * reach, size=tuple(size),
                          near=0.5 * reach, far=3.5 * reach,
                          ortho_height=size[1] * r / px)
    return {"placements": placed, "camera": camera, "spacing": spacing, "radius": r}


def time_field(asset, reps: dict, decimations: dict, layout: dict, repeats: int) -> dict:
    """The field's frame of the full mesh, each representation and its decimated mesh,
    timed interleaved, with their device-independent counts."""
    entries = [("full mesh", asset)]
    for name, rep in reps.items():
        entries += [(name, rep), (f"{name} decimated", decimations[name])]
    options = {"instances": layout["placements"]}
    times = time_scenes([(obj, options) for _, obj in entries], layout["camera"],
                        repeats=repeats, counts=True)
    return {"instances": len(layout["placements"]), "size": layout["camera"].size,
            "spacing_radii": layout["spacing"] / layout["radius"],
            "times": {name: t for (name, _), t in zip(entries, times, strict=True)}}


def markdown(data: dict) -> str:
    px = data["instance_px"]
    lines = [f"# Many instances: {data['asset']} at {px} px, one draw call per plan", "",
             machine_line(data["machine"]), "",
             f"The mesh: {data['mesh_triangles']:,} triangles, "
             f"{format_bytes(data['mesh_bytes'])}. Equal error: the mesh decimated to the "
             f"fewest bytes whose SSIM against the full mesh, on one instance at {px} px from "
             f"{len(SSIM_AZIMUTHS)} views at {data['elevation']:g} degrees, is at least the "
             "representation's.", "",
             "| representation | SSIM | bytes | decimated mesh: SSIM | bytes | triangles |",
             "|---|---|---|---|---|---|"]
    for row in data["rows"]:
        floor = " (floor)" if row["at_floor"] else ""
        lines.append(f"| {row['name']} | {row['ssim']:.3f} | {format_bytes(row['bytes'])} | "
                     f"{row['decimated_ssim']:.3f}{floor} | "
                     f"{format_bytes(row['decimated_bytes'])} | "
                     f"{row['decimated_triangles']:,} |")
    for name, why in data["refused"].items():
        lines.append(f"| {name} | not instanced: {why} | | | | |")
    best = []
    for fld in data["fields"]:
        w, h = fld["size"]
        times = fld["times"]
        full = times["full mesh"]
        lines += ["", f"## {fld['instances']:,} instances ({w}x{h}, grid spacing "
                  f"{fld['spacing_radii']:.2f} bounding radii)", "",
                  "| drawn | ms | x its decimated mesh | x full mesh | draw calls | "
                  "primitives | samples passed |", "|---|---|---|---|---|---|---|"]
        lines.append(_time_row("full mesh", full, None, full))
        for row in data["rows"]:
            mine, mesh = times[row["name"]], times[f"{row['name']} decimated"]
            lines.append(_time_row(row["name"], mine, mesh, full))
            lines.append(_time_row(f"{row['name']}: decimated mesh", mesh, None, full))
        if data["rows"]:
            ratios = {r["name"]: times[r["name"]]["wall_ms"]
                      / times[f"{r['name']} decimated"]["wall_ms"] for r in data["rows"]}
            name = min(ratios, key=ratios.get)
            best.append((fld["instances"], name, ratios[name]))
    lines.append("")
    for n, name, ratio in best:
        met = "meets" if ratio <= data["target"] else "misses"
        lines.append(f"{n:,} instances: the fastest against its decimated mesh is {name} at "
                     f"{ratio:.3g}x, which {met} the target of {data['target']}x.")
    return "\n".join(lines) + "\n"


def _time_row(name: str, t: dict, mesh: dict | None, full: dict) -> str:
    ratio = f"{t['wall_ms'] / mesh['wall_ms']:.2f}" if mesh else ""
    return (f"| {name} | {t['wall_ms']:.1f} | {ratio} | {t['wall_ms'] / full['wall_ms']:.2f} | "
            f"{t['draw_calls']} | {t['primitives']:,} | {t['samples_passed']:,} |")
