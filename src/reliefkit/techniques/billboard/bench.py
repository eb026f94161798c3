"""`reliefkit bench billboard`: Tables 1 and 2 and Fig. 6 of Mantler, Jeschke & Wimmer.

Every asset (the tree, the blob, the vehicle and, when ``RELIEFKIT_BENCH_MESH`` names a mesh
file, that real mesh) is baked as the flat billboard cloud (BBC) and as the three
displacement-mapped billboard clouds (DMBBC) with the same epsilon and texel size, hence the
same planes. Measured side by side in one run:

* Table 1: faces, planes, plane generation and bake seconds; Table 2: bytes of every
  representation, and the mesh decimated (``fast_simplification``) to the same bytes;
* quality at near, medium and far distances (1.5, 3 and 6 bounding radii, all closer than the
  switch distance) against the mesh: mask IoU, SSIM, PSNR, averaged over three azimuths;
* sphere tracing against uniform sampling: iterations per covered pixel (instrumented shader,
  machine-independent), wrong hits against the exact march (`box_reference.wrong_hits`) and
  frame time;
* Fig. 6: frame time against distance for the mesh, the BBC and the DMBBC (lod auto);
* the generation time of the planes of a ~100k-triangle subdivided asset and of a curved one
  (`bumpy_sphere`, 81,920 triangles), and the pop of the DMBBC -> BBC switch along a dolly
  across the switch distance.

Frame times are medians of repeated draws (`bench.timing.time_render`, wall clock after
glFinish); on a software rasterizer read the ratios.
"""

from __future__ import annotations

import math
import os
import platform
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ...bench.report import save_figure, write_report
from ...bench.timing import time_render
from ...gl.context import gl_info
from ...io.meshes import load_mesh
from ...metrics import compare
from ...render import render
from ...scene.assets import make_asset
from ...scene.decimate import decimated, mesh_bytes
from ...scene.mesh import RenderMesh, vertex_normals
from ...scene.views import bounds_radius, orbit_bounds
from ...units import format_bytes
from .bake import bake_billboard_cloud
from .box_bake import bake_boxes
from .box_reference import wrong_hits
from .boxes import VARIANTS
from .cloud import build_billboard_cloud
from .lod import switch_distance

MESH_ENV = "RELIEFKIT_BENCH_MESH"
#: A pixel changes when a channel of its sRGB8 picture moves by more than this.
CHANGE_THRESHOLD = 2
POP_TARGET = 0.01
ITERATION_TARGET = 3.0
WRONG_TARGET = 0.001
GENERATION_TARGET_S = 10.0
DISTANCE_NAMES = ("near", "medium", "far")


@dataclass
class BenchConfig:
    assets: tuple = ("tree", "blob", "vehicle")
    mesh_path: str | None = field(default_factory=lambda: os.environ.get(MESH_ENV) or None)
    epsilon: float = 0.05
    texel_divisor: int = 256          # texel size = bounding-box diagonal / this
    size: int = 256
    distances: tuple = (1.5, 3.0, 6.0)  # bounding radii: near, medium, far
    azimuths: tuple = (30.0, 150.0, 270.0)
    elevation: float = 15.0
    repeats: int = 5
    uniform_samples: tuple = (1, 2, 4, 8)
    big_asset: str = "blob"
    big_subdivisions: int = 1         # each triangle into 4 this often: 28k -> 113k for the blob
    curved_subdivisions: int = 6      # the bumpy sphere's icosphere: 81,920 triangles
    generation_tries: int = 2
    fig6_points: int = 8
    dolly_frames: int = 60
    quick: bool = False

    @classmethod
    def quick_config(cls) -> BenchConfig:
        return cls(texel_divisor=96, size=128, repeats=2, big_subdivisions=0, generation_tries=1,
                   curved_subdivisions=3, fig6_points=5, dolly_frames=24, quick=True)


# -- assets ---------------------------------------------------------------------------

def load_assets(cfg: BenchConfig, log) -> tuple[dict, list[str]]:
    """The meshes by name, and notes on what was left out."""
    meshes = {name: make_asset(name) for name in cfg.assets}
    notes = []
    if cfg.mesh_path and Path(cfg.mesh_path).is_file():
        mesh = load_mesh(cfg.mesh_path)
        meshes[Path(cfg.mesh_path).stem] = mesh
        log(f"real mesh {cfg.mesh_path}: {mesh.triangle_count:,} triangles")
    else:
        notes.append(f"no real mesh: set {MESH_ENV} to a mesh file to add one"
                     + (f" ({cfg.mesh_path} is not a file)" if cfg.mesh_path else ""))
    return meshes, notes


def diagonal(mesh) -> float:
    return float(np.linalg.norm(np.subtract(*mesh.bounds[::-1])))


def subdivided(mesh, times: int):
    """``mesh`` with every triangle split into four ``times`` times (same shape, same
    diagonal, so the same epsilon; one colour): a large mesh whose planes are comparable."""
    import trimesh

    if times == 0:
        return mesh
    points, faces = mesh.world_positions, mesh.indices
    for _ in range(times):
        points, faces = trimesh.remesh.subdivide(points, faces)
    faces = faces.astype(np.uint32)
    return RenderMesh(points, faces, vertex_normals(points.astype(np.float32), faces),
                      np.broadcast_to(mesh.colors.mean(axis=0), (len(points), 4)),
                      name=f"{mesh.name} subdivided {times}x")


def boxes_bytes(rep) -> int:
    """A DMBBC's own maps (colour, normal, displacement, distance), without its flat cloud."""
    return sum(v for k, v in rep.memory_bytes().items() if k != "billboard_cloud")


# -- per asset: bake, tables 1 and 2 ----------------------------------------------------

def bake_all(mesh, cfg: BenchConfig) -> tuple[dict, dict]:
    """The BBC and the three DMBBC variants with the same planes; their bake seconds."""
    texel = diagonal(mesh) / cfg.texel_divisor
    reps, seconds = {}, {}
    start = time.perf_counter()
    reps["bbc"] = bake_billboard_cloud(mesh, epsilon=cfg.epsilon, texel_size=texel)
    seconds["bbc"] = time.perf_counter() - start
    for variant in VARIANTS:
        start = time.perf_counter()
        reps[variant] = bake_boxes(mesh, variant, epsilon=cfg.epsilon, texel_size=texel)
        seconds[variant] = time.perf_counter() - start
    return reps, seconds


def tables(name: str, mesh, reps: dict, seconds: dict) -> tuple[dict, dict, dict]:
    """Table 1 and Table 2 rows, and the decimated meshes by the representation they match."""
    generation = reps["bbc"].params["generation"]
    t1 = {"asset": name, "faces": mesh.triangle_count, "planes": reps["bbc"].count,
          "skipped": generation["skipped"], "generation_s": reps["bbc"].generation_seconds,
          "voxels_across": reps["volumetric"].params["voxels_across"],
          "thickness": reps["shell"].thickness,
          **{f"{k}_bake_s": v for k, v in seconds.items()}}
    t2 = {"asset": name, "mesh_bytes": mesh_bytes(mesh),
          "bbc_bytes": sum(reps["bbc"].memory_bytes().values()),
          **{f"{v}_bytes": boxes_bytes(reps[v]) for v in VARIANTS}}
    decimations = {}
    for match in ("bbc", "volumetric"):
        dec = decimated(mesh, t2[f"{match}_bytes"])
        t2[f"decimated_{match}_triangles"] = None if dec is None else dec.triangle_count
        t2[f"decimated_{match}_bytes"] = None if dec is None else mesh_bytes(dec)
        if dec is not None and dec is not mesh:
            decimations[f"mesh @ {match} bytes"] = dec
    return t1, t2, decimations


# -- quality at three distances -------------------------------------------------------------

def camera_at(mesh, azimuth, distance_radii, size, cfg: BenchConfig):
    return orbit_bounds(mesh.bounds, azimuth, cfg.elevation, distance_radii, (size, size))


def switch_radii(mesh, rep, size: int) -> float:
    """The switch distance (`lod.switch_distance`) in bounding radii from the centre."""
    cam = camera_at(mesh, 0.0, 3.0, size, BenchConfig())
    return switch_distance(cam, rep.epsilon) / bounds_radius(mesh.bounds)


def quality(name, mesh, reps: dict, decimations: dict, cfg: BenchConfig) -> list[dict]:
    """Mask IoU, SSIM and PSNR of every representation against the mesh, per distance
    (mean over the azimuths)."""
    radius = bounds_radius(mesh.bounds)
    shown = {"bbc": reps["bbc"], **{v: reps[v] for v in VARIANTS}, **decimations}
    rows = []
    for label, dist in zip(DISTANCE_NAMES, cfg.distances, strict=True):
        cameras = [camera_at(mesh, az, dist, cfg.size, cfg) for az in cfg.azimuths]
        truths = render(mesh, cameras)  # every azimuth in one call: one upload
        scores = {}
        for key, rep in shown.items():
            options = {"march": "sphere"} if key in VARIANTS else {}
            scores[key] = [compare(frame, truth, scene_size=radius) for frame, truth
                           in zip(render(rep, cameras, **options), truths, strict=True)]
        row = {"asset": name, "distance": label, "radii": dist}
        for key, runs in scores.items():
            row[key] = {m: float(np.mean([r[m] for r in runs])) for m in ("iou", "ssim", "psnr")}
        rows.append(row)
    return rows


# -- sphere tracing against uniform sampling ---------------------------------------------------

def marches(name, mesh, reps: dict, cfg: BenchConfig) -> list[dict]:
    """At medium distance, first azimuth: iterations, wrong hits and frame time per march."""
    camera = camera_at(mesh, cfg.azimuths[0], cfg.distances[1], cfg.size, cfg)
    rows = []
    for variant in VARIANTS:
        rep = reps[variant]
        runs = [("sphere", {"march": "sphere"}), ("exact", {"march": "exact"})]
        runs += [(f"uniform x{s}", {"march": "uniform", "samples": s})
                 for s in cfg.uniform_samples]
        for label, options in runs:
            frame = render(rep, camera, count_iterations=True, **options)
            rows.append({"asset": name, "variant": variant, "march": label,
                         "samples": options.get("samples"),
                         "iterations": float(frame.stats["iterations_mean_covered"]),
                         "wrong": wrong_hits(frame, rep, camera)["wrong_fraction"],
                         "ms": time_render(rep, camera, repeats=cfg.repeats,
                                           **options)["wall_ms"]})
    return rows


def equal_error(rows: list[dict]) -> list[dict]:
    """Per (asset, variant): sphere against the uniform sample count whose wrong-hit fraction
    is closest to sphere's (``reached``: whether that uniform count is as good or better)."""
    out = []
    for key in sorted({(r["asset"], r["variant"]) for r in rows}):
        sub = [r for r in rows if (r["asset"], r["variant"]) == key]
        sphere = next(r for r in sub if r["march"] == "sphere")
        uniform = [r for r in sub if r["samples"] is not None]
        better = [r for r in uniform if r["wrong"] <= sphere["wrong"]]
        match = (min(better, key=lambda r: r["samples"]) if better
                 else min(uniform, key=lambda r: r["wrong"]))
        out.append({"asset": key[0], "variant": key[1], "uniform_samples": match["samples"],
                    "reached": bool(better), "sphere_iterations": sphere["iterations"],
                    "uniform_iterations": match["iterations"],
                    "ratio": match["iterations"] / max(sphere["iterations"], 1e-9),
                    "sphere_wrong": sphere["wrong"], "uniform_wrong": match["wrong"],
                    "sphere_ms": sphere["ms"], "uniform_ms": match["ms"]})
    return out


# -- Fig. 6: frame time against distance --------------------------------------------------

def fig6(name, mesh, reps: dict, cfg: BenchConfig) -> list[dict]:
    switch = switch_radii(mesh, reps["volumetric"], cfg.size)
    rows = []
    for dist in np.geomspace(cfg.distances[0], 1.5 * switch, cfg.fig6_points):
        camera = camera_at(mesh, cfg.azimuths[0], float(dist), cfg.size, cfg)
        rows.append({"asset": name, "radii": float(dist), "switch_radii": switch,
                     "mesh_ms": time_render(mesh, camera, repeats=cfg.repeats)["wall_ms"],
                     "bbc_ms": time_render(reps["bbc"], camera, repeats=cfg.repeats)["wall_ms"],
                     "dmbbc_ms": time_render(reps["volumetric"], camera, repeats=cfg.repeats,
                                             march="sphere", lod="auto")["wall_ms"]})
    return rows


# -- generation of a large mesh's planes -------------------------------------------------------

def bumpy_sphere(subdivisions: int):
    """A curved, organic mesh: an icosphere (20 x 4^subdivisions triangles; 6: 81,920) with
    smooth bumps along its normals, so no two faces share a plane (the subdivided demo
    assets keep their coarse faces' planes)."""
    import trimesh

    sphere = trimesh.creation.icosphere(subdivisions=subdivisions)
    points = np.asarray(sphere.vertices, np.float64)
    waves = np.random.default_rng(7).normal(size=(6, 3)) * 3.0
    bumps = np.sin(points @ waves.T + np.arange(6)).mean(axis=1)
    points = points * (1.0 + 0.1 * bumps)[:, None]
    faces = np.asarray(sphere.faces, np.uint32)
    return RenderMesh(points, faces, vertex_normals(points.astype(np.float32), faces),
                      np.broadcast_to([0.6, 0.5, 0.4, 1.0], (len(points), 4)),
                      name=f"bumpy sphere {subdivisions}x")


def generation(cfg: BenchConfig, log) -> list[dict]:
    """The plane search's time (best of ``generation_tries``) on the large subdivided asset
    and on the bumpy sphere."""
    rows = []
    for mesh in (subdivided(make_asset(cfg.big_asset), cfg.big_subdivisions),
                 bumpy_sphere(cfg.curved_subdivisions)):
        best, plan = math.inf, None
        for _ in range(cfg.generation_tries):
            plan = build_billboard_cloud(mesh, cfg.epsilon)
            best = min(best, plan.seconds)
        log(f"generation: {mesh.name}, {mesh.triangle_count:,} triangles, "
            f"{len(plan.planes)} planes, {best:.2f} s")
        rows.append({"mesh": mesh.name, "triangles": mesh.triangle_count,
                     "planes": len(plan.planes), "seconds": best,
                     "skipped": int(len(plan.skipped)), "tries": cfg.generation_tries,
                     "cpus": os.cpu_count(), "full_run": not cfg.quick})
    return rows


# -- the pop of the switch ------------------------------------------------------------------

def changed_fraction(a, b) -> float:
    """Pixels whose sRGB8 colour (or coverage) differs by more than `CHANGE_THRESHOLD` in any
    channel, over the pixels either frame covers."""
    diff = np.abs(a.rgba8().astype(np.int16) - b.rgba8().astype(np.int16)).max(axis=-1)
    changed = (diff > CHANGE_THRESHOLD) | (a.mask != b.mask)
    return float(changed.sum() / max(int((a.mask | b.mask).sum()), 1))


def change_detail(a, b) -> dict:
    """How two frames differ: the coverage alone (fraction of the covered pixels whose mask
    flips) and the median / 90th percentile of the largest sRGB8 channel difference there."""
    union = a.mask | b.mask
    diff = np.abs(a.rgba8().astype(np.int16) - b.rgba8().astype(np.int16)).max(axis=-1)[union]
    return {"mask_change": float((a.mask != b.mask).sum() / max(int(union.sum()), 1)),
            "median_diff": float(np.median(diff)) if diff.size else 0.0,
            "p90_diff": float(np.percentile(diff, 90)) if diff.size else 0.0}


def dolly(name, mesh, reps: dict, cfg: BenchConfig) -> dict:
    """The camera from 0.3x to 1.5x the switch distance in geometric steps: the change
    between consecutive frames of the DMBBC (lod auto, transition 0.5) and of the BBC alone
    (the motion), and just inside the switch distance the boxes (flattened to almost nothing,
    their colours handed over to the BBC's) against the BBC from the same camera (the pop
    without motion)."""
    vol = reps["volumetric"]
    switch = switch_radii(mesh, vol, cfg.size)
    steps = np.geomspace(0.3 * switch, 1.5 * switch, cfg.dolly_frames)
    boxes, flat, lods = [], [], []
    for dist in steps:
        camera = camera_at(mesh, cfg.azimuths[0], float(dist), cfg.size, cfg)
        frame = render(vol, camera, march="sphere", lod="auto", transition=0.5)
        boxes.append(frame)
        lods.append(frame.stats.get("lod"))
        flat.append(render(reps["bbc"], camera))
    dm = [changed_fraction(a, b) for a, b in zip(boxes, boxes[1:], strict=False)]
    bb = [changed_fraction(a, b) for a, b in zip(flat, flat[1:], strict=False)]
    switched = next((k for k in range(1, len(lods)) if lods[k] != lods[k - 1]), None)
    out = {"asset": name, "switch_radii": switch, "frames": len(steps),
           "step_ratio": float(steps[1] / steps[0]), "dmbbc_max": max(dm), "bbc_max": max(bb),
           "switch_step": switched, "switch_change": None, "switch_motion": None,
           "switch_static": None, "covered_at_switch": None}
    if switched is not None:
        # the pop without motion: just inside the switch distance, where lod auto still draws
        # the boxes (flattened to almost nothing, colours handed over), against the BBC there
        camera = camera_at(mesh, cfg.azimuths[0], 0.999 * switch, cfg.size, cfg)
        before = render(vol, camera, march="sphere", lod="auto", transition=0.5)
        after = render(reps["bbc"], camera)
        out |= {"switch_change": dm[switched - 1], "switch_motion": bb[switched - 1],
                "switch_static": changed_fraction(before, after),
                "switch_static_detail": change_detail(before, after),
                "covered_at_switch": int(boxes[switched].mask.sum()),
                "switch_at_radii": float(steps[switched])}
    return out


# -- the run ------------------------------------------------------------------------------------

def run(cfg: BenchConfig, log=print) -> dict:
    info = gl_info()
    results = {"machine": {"renderer": info["renderer"], "gl": info["version"],
                           "cpu": platform.processor() or platform.machine(),
                           "cpus": os.cpu_count(), "python": platform.python_version()},
               "config": {"size": cfg.size, "repeats": cfg.repeats, "epsilon": cfg.epsilon,
                          "texel": f"diagonal / {cfg.texel_divisor}",
                          "distances": list(cfg.distances), "azimuths": list(cfg.azimuths),
                          "elevation": cfg.elevation, "quick": cfg.quick},
               "table1": [], "table2": [], "quality": [], "marches": [], "fig6": [],
               "dolly": []}
    meshes, notes = load_assets(cfg, log)
    try:
        import fast_simplification  # noqa: F401
    except ImportError:
        notes.append("fast_simplification is not installed (pip install fast-simplification):"
                     " no decimated meshes")
    for name, mesh in meshes.items():
        reps, seconds = bake_all(mesh, cfg)
        t1, t2, decimations = tables(name, mesh, reps, seconds)
        results["table1"].append(t1)
        results["table2"].append(t2)
        log(f"{name}: {t1['faces']:,} faces, {t1['planes']} planes, baked in "
            + ", ".join(f"{k} {v:.1f} s" for k, v in seconds.items()))
        results["quality"] += quality(name, mesh, reps, decimations, cfg)
        switch = switch_radii(mesh, reps["volumetric"], cfg.size)
        log(f"{name}: quality at {', '.join(map(str, cfg.distances))} radii "
            f"(switch at {switch:.1f})")
        results["marches"] += marches(name, mesh, reps, cfg)
        log(f"{name}: sphere vs uniform marches")
        results["fig6"] += fig6(name, mesh, reps, cfg)
        log(f"{name}: frame time vs distance")
        results["dolly"].append(dolly(name, mesh, reps, cfg))
        log(f"{name}: dolly, switch change {results['dolly'][-1]['switch_change']}")
    results["equal_error"] = equal_error(results["marches"])
    results["generation"] = generation(cfg, log)
    results["notes"] = notes
    results["targets"] = check_targets(results)
    return results


def check_targets(results: dict) -> list[dict]:
    """The bench's four targets (the first per asset and distance), met or not, with the
    figures they were decided on."""
    out = []
    switch = {r["asset"]: r["switch_radii"] for r in results["dolly"]}
    for r in results["quality"]:
        closer = r["radii"] < switch.get(r["asset"], math.inf)
        vol, bbc = r["volumetric"], r["bbc"]
        out.append({"target": f"{r['asset']} {r['distance']} ({r['radii']:g} radii): "
                              "volumetric beats the BBC on IoU and SSIM",
                    "value": f"IoU {vol['iou']:.4f} vs {bbc['iou']:.4f}, SSIM "
                             f"{vol['ssim']:.4f} vs {bbc['ssim']:.4f}"
                             + ("" if closer else " (beyond the switch distance)"),
                    "met": bool(vol["iou"] > bbc["iou"] and vol["ssim"] > bbc["ssim"])})
    eq = results["equal_error"]
    if eq:
        worst = min(eq, key=lambda r: r["ratio"])
        wrong = max(r["sphere_wrong"] for r in eq)
        out.append({"target": f"sphere tracing >= {ITERATION_TARGET:g}x fewer iterations per "
                              "pixel than uniform at equal error",
                    "value": f"worst {worst['ratio']:.2f}x ({worst['asset']} "
                             f"{worst['variant']}, uniform x{worst['uniform_samples']})",
                    "met": worst["ratio"] >= ITERATION_TARGET})
        out.append({"target": f"sphere tracing <= {WRONG_TARGET:.1%} of pixels wrong vs exact",
                    "value": f"worst {wrong:.4%}", "met": wrong <= WRONG_TARGET})
    gens = results["generation"]
    met = all(g["seconds"] <= GENERATION_TARGET_S and g["skipped"] == 0 and g["full_run"]
              for g in gens)
    out.append({"target": f"planes of a 100k-triangle mesh in <= {GENERATION_TARGET_S:g} s, "
                          "no skipped faces",
                "value": "; ".join(f"{g['mesh']}, {g['triangles']:,} triangles: "
                                   f"{g['seconds']:.2f} s, {g['skipped']} skipped"
                                   for g in gens)
                         + f", {gens[0]['cpus']} CPUs"
                         + ("" if all(g["full_run"] for g in gens) else " (full run only)"),
                "met": bool(met)})
    pops = [d for d in results["dolly"] if d["switch_change"] is not None]
    if pops:
        excess = max(d["switch_change"] - d["switch_motion"] for d in pops)
        static = max(d["switch_static"] for d in pops)
        out.append({"target": f"DMBBC -> BBC switch changes <= {POP_TARGET:.0%} of pixels",
                    "value": f"without motion {static:.3%}, in excess of the motion "
                             f"{excess:.3%} (worst asset)",
                    "met": max(static, excess) <= POP_TARGET})
    missing = [d["asset"] for d in results["dolly"] if d["switch_change"] is None]
    if missing:
        out.append({"target": "the dolly crosses the switch distance",
                    "value": f"no switch seen for {', '.join(missing)}", "met": False})
    return out


# -- the report ---------------------------------------------------------------------------

def _bytes(value) -> str:
    return "n/a" if value is None else format_bytes(value)


def markdown(results: dict) -> str:
    m, c = results["machine"], results["config"]
    lines = [f"Machine: {m['renderer']}, {m['gl']}, CPU {m['cpu']} x {m['cpus']}, Python "
             f"{m['python']}; images {c['size']}², median of {c['repeats']} draws; epsilon "
             f"{c['epsilon']} of the diagonal, texel {c['texel']}; views at elevation "
             f"{c['elevation']}°, azimuths {', '.join(f'{a:g}' for a in c['azimuths'])}."
             + (" Quick run." if c["quick"] else ""), ""]
    lines += [f"Note: {n}." for n in results["notes"]] + [""] * bool(results["notes"])
    lines += ["#### Table 1: planes and generation", "",
              "| asset | faces | planes | skipped | generation s | BBC bake s | "
              + " | ".join(f"{v} bake s" for v in VARIANTS) + " | voxels across |",
              "|---" * (7 + len(VARIANTS)) + "|"]
    for r in results["table1"]:
        lines.append(f"| {r['asset']} | {r['faces']:,} | {r['planes']} | {r['skipped']} | "
                     f"{r['generation_s']:.2f} | {r['bbc_bake_s']:.2f} | "
                     + " | ".join(f"{r[f'{v}_bake_s']:.2f}" for v in VARIANTS)
                     + f" | {r['voxels_across']} |")
    lines += ["", "#### Table 2: memory (arrays as stored; DMBBC: its boxes' maps incl. "
              "distance textures, without the BBC it keeps for lod)", "",
              "| asset | mesh | BBC | " + " | ".join(VARIANTS)
              + " | mesh @ BBC bytes | mesh @ volumetric bytes |", "|---" * (5 + len(VARIANTS))
              + "|"]
    for r in results["table2"]:
        dec = []
        for match in ("bbc", "volumetric"):
            tri = r[f"decimated_{match}_triangles"]
            if tri is None:
                dec.append("n/a")
            elif r[f"decimated_{match}_bytes"] == r["mesh_bytes"]:
                dec.append("the full mesh is smaller")
            else:
                dec.append(f"{tri:,} tris, {_bytes(r[f'decimated_{match}_bytes'])}")
        lines.append(f"| {r['asset']} | {_bytes(r['mesh_bytes'])} | {_bytes(r['bbc_bytes'])} | "
                     + " | ".join(_bytes(r[f"{v}_bytes"]) for v in VARIANTS) + " | "
                     + " | ".join(dec) + " |")
    switch = {d["asset"]: d["switch_radii"] for d in results["dolly"]}
    lines += ["", "#### Quality against the mesh (mask IoU / SSIM / PSNR dB, mean over the "
              "azimuths; DMBBC sphere-traced)", "",
              "| asset | distance | switch at | representation | IoU | SSIM | PSNR |",
              "|---" * 7 + "|"]
    for r in results["quality"]:
        keys = [k for k in r if isinstance(r[k], dict)]
        for k in keys:
            s = r[k]
            lines.append(f"| {r['asset']} | {r['distance']} ({r['radii']:g} r) | "
                         f"{switch.get(r['asset'], math.nan):.1f} r | {k} | {s['iou']:.4f} | "
                         f"{s['ssim']:.4f} | {s['psnr']:.2f} |")
    lines += ["", "#### Sphere tracing vs uniform sampling (medium distance): iterations per "
              "covered pixel, wrong hits vs exact, frame ms", "",
              "| asset | variant | march | iterations | wrong | ms |", "|---" * 6 + "|"]
    for r in results["marches"]:
        lines.append(f"| {r['asset']} | {r['variant']} | {r['march']} | {r['iterations']:.2f} "
                     f"| {r['wrong']:.4%} | {r['ms']:.2f} |")
    lines += ["", "At equal error (the fewest uniform samples with no more wrong hits than "
              "sphere tracing; else the uniform count with the fewest, marked 'not reached'):",
              "", "| asset | variant | uniform samples | sphere it | uniform it | ratio | "
              "sphere wrong | uniform wrong | sphere ms | uniform ms |", "|---" * 10 + "|"]
    for r in results["equal_error"]:
        reached = "" if r["reached"] else " (not reached)"
        lines.append(f"| {r['asset']} | {r['variant']} | {r['uniform_samples']}{reached} | "
                     f"{r['sphere_iterations']:.2f} | {r['uniform_iterations']:.2f} | "
                     f"{r['ratio']:.2f} | {r['sphere_wrong']:.4%} | {r['uniform_wrong']:.4%} | "
                     f"{r['sphere_ms']:.2f} | {r['uniform_ms']:.2f} |")
    lines += ["", "#### Fig. 6: frame time (ms) against distance (DMBBC: volumetric, sphere, "
              "lod auto)", "", "| asset | radii | mesh | BBC | DMBBC |", "|---" * 5 + "|"]
    for r in results["fig6"]:
        beyond = " (beyond switch)" if r["radii"] >= r["switch_radii"] else ""
        lines.append(f"| {r['asset']} | {r['radii']:.1f}{beyond} | {r['mesh_ms']:.2f} | "
                     f"{r['bbc_ms']:.2f} | {r['dmbbc_ms']:.2f} |")
    lines += ["", "#### The DMBBC -> BBC switch along a dolly", "",
              "Changed pixels: any sRGB8 channel (or the coverage) differs by more than "
              f"{CHANGE_THRESHOLD}/255, over the pixels either frame covers. 'switch' is the "
              "step where the DMBBC's lod turns to the BBC; 'motion' the BBC's own change at "
              "that step; 'no motion' the boxes just inside the switch distance (lod auto: "
              "flattened to almost nothing, colours handed over to the BBC's) against the "
              "BBC from the same camera.", "",
              "| asset | switch at | frames (x per step) | DMBBC max | BBC max | switch | "
              "motion | no motion | no motion: coverage flips, median / p90 diff | covered px |",
              "|---" * 10 + "|"]
    for d in results["dolly"]:
        def pct(v):
            return "n/a" if v is None else f"{v:.3%}"

        def detail(v):
            return "n/a" if v is None else (f"{v['mask_change']:.2%}, {v['median_diff']:.0f} / "
                                             f"{v['p90_diff']:.0f} of 255")
        lines.append(f"| {d['asset']} | {d['switch_radii']:.1f} r | {d['frames']} "
                     f"({d['step_ratio']:.3f}) | {pct(d['dmbbc_max'])} | {pct(d['bbc_max'])} | "
                     f"{pct(d['switch_change'])} | {pct(d['switch_motion'])} | "
                     f"{pct(d['switch_static'])} | {detail(d.get('switch_static_detail'))} | "
                     f"{d['covered_at_switch']} |")
    lines.append("")
    lines += [f"Generation: {g['mesh']} ({g['triangles']:,} triangles), {g['planes']} planes "
              f"in {g['seconds']:.2f} s (best of {g['tries']}), {g['skipped']} faces skipped."
              for g in results["generation"]]
    lines += ["", "#### Targets", "", "| target | figure | met |", "|---|---|---|"]
    for t in results["targets"]:
        lines.append(f"| {t['target']} | {t['value']} | {'yes' if t['met'] else 'no'} |")
    return "\n".join(lines) + "\n"


def plot(results: dict, path: Path) -> bool:
    """Fig. 6 per asset (frame ms against distance); False when matplotlib is missing."""
    try:
        import matplotlib
    except ImportError:
        return False
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import NullFormatter

    assets = list(dict.fromkeys(r["asset"] for r in results["fig6"]))
    fig, axes = plt.subplots(1, len(assets), figsize=(4.2 * len(assets), 3.8), squeeze=False)
    for ax, name in zip(axes[0], assets, strict=True):
        rows = [r for r in results["fig6"] if r["asset"] == name]
        x = [r["radii"] for r in rows]
        for key, label in (("mesh_ms", "mesh"), ("bbc_ms", "BBC"), ("dmbbc_ms", "DMBBC")):
            ax.plot(x, [r[key] for r in rows], "-o", label=label)
        ax.axvline(rows[0]["switch_radii"], color="gray", ls="--", lw=1, label="switch")
        ax.set(xscale="log", xlabel="distance (bounding radii)", ylabel="frame ms",
               title=f"Fig. 6: {name}")
        ax.set_xticks([1.5, 3, 6, 12, 25, 50], ["1.5", "3", "6", "12", "25", "50"])
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.legend(fontsize=7)
    save_figure(fig, path)
    return True


def write(results: dict, out: Path) -> list[Path]:
    paths = write_report(out, "billboard-bench", results, markdown)
    if plot(results, out / "billboard-bench.png"):
        paths.append(out / "billboard-bench.png")
    return paths


def run_suite(quick: bool, out: Path, log) -> tuple[str, list[Path]]:
    """The ``billboard`` bench suite: run, write json/md/png into ``out``, return the
    markdown."""
    cfg = BenchConfig.quick_config() if quick else BenchConfig()
    results = run(cfg, log=log)
    return markdown(results), write(results, out)
