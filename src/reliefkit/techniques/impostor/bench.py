"""``reliefkit bench impostor``: the impostor against its mesh on grid frames and between
them, from grazing to steep elevations, for several grid sizes.

For every elevation and azimuth of a ring of views, two cameras: one exactly on the frame
nearest that direction, one at the middle of the three frames around it (each weighs 1/3),
the case where the frames disagree most. Each is scored against the mesh from the same
camera (mask IoU, SSIM, surface-point distance in frame texels). The atlas stays at its
default side, so a larger grid trades resolution per frame for closer frames. The worst
view between frames at the lowest elevation is saved as a picture per asset.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...bench.report import machine, machine_line, write_report
from ...colorspace import to_rgba8
from ...io.meshes import load_mesh
from ...metrics import mask_iou, ssim
from ...pictures import contact_sheet, save_image
from ...render import render
from ...scene.assets import make_asset
from ...scene.views import orbit_bounds
from ...units import format_bytes
from . import octahedral
from .bake import bake_impostor

GRIDS, QUICK_GRIDS = (8, 12, 16), (12,)
ELEVATIONS, QUICK_ELEVATIONS = (0.0, 10.0, 30.0, 60.0), (0.0, 30.0)
AZIMUTHS, QUICK_AZIMUTHS = 8, 3
SIZE, QUICK_SIZE = 256, 128


def view_pairs(rep, elevation: float, azimuths: int) -> list[tuple[str, np.ndarray]]:
    """("on", direction) of the frame nearest each azimuth at ``elevation`` and ("between",
    direction) of the middle of the three frames around it."""
    frames = octahedral.frame_directions(rep.grid, rep.hemi).reshape(-1, 3)
    el = np.radians(elevation)
    pairs = []
    for az in np.radians(np.arange(azimuths) * 360.0 / azimuths + 7.0):
        d = np.array([np.cos(el) * np.sin(az), np.sin(el), np.cos(el) * np.cos(az)])
        cell, _ = octahedral.blend_frames(d, rep.grid, rep.hemi)
        middle = octahedral.frame_point(*cell.mean(axis=0), rep.grid)
        pairs += [("on", frames[np.argmax(frames @ d)]),
                  ("between", octahedral.decode(middle, rep.hemi))]
    return pairs


def _camera(rep, direction, size: int):
    az = float(np.degrees(np.arctan2(direction[0], direction[2])))
    el = float(np.degrees(np.arcsin(np.clip(direction[1], -1.0, 1.0))))
    return orbit_bounds(rep.source_bounds, az, el, None, size=(size, size))


def measure(name: str, mesh, grid: int, elevations, azimuths: int, size: int) -> dict:
    """One asset at one grid: its bake and a row per elevation and kind of view."""
    import time

    start = time.perf_counter()
    rep = bake_impostor(mesh, grid=grid)
    seconds = time.perf_counter() - start
    texel = 2.0 * rep.frame_radius / rep.frame
    rows, worst = [], None
    for elevation in elevations:
        pairs = view_pairs(rep, elevation, azimuths)
        cameras = [_camera(rep, d, size) for _, d in pairs]
        got, want = render(rep, cameras), render(mesh, cameras)
        scores = {"on": [], "between": []}
        for (kind, d), g, w in zip(pairs, got, want, strict=True):
            both = g.mask & w.mask
            gap = np.linalg.norm(g.position[both] - w.position[both], axis=-1) / texel
            iou = mask_iou(g, w)
            scores[kind].append((iou, ssim(g, w), float(gap.mean()) if both.any() else 0.0))
            if kind == "between" and elevation == elevations[0] and \
                    (worst is None or iou < worst[0]):
                worst = (iou, g, w, float(np.degrees(np.arcsin(d[1]))))
        for kind, values in scores.items():
            v = np.array(values)
            rows.append({"elevation": elevation, "views": kind, "iou_mean": v[:, 0].mean(),
                         "iou_min": v[:, 0].min(), "ssim_mean": v[:, 1].mean(),
                         "ssim_min": v[:, 1].min(), "depth_texels": v[:, 2].mean()})
    return {"asset": name, "grid": grid, "frame": rep.frame, "bytes": rep.nbytes,
            "bake_seconds": seconds, "rows": rows, "worst": worst}


def run(quick: bool, out: Path, log, mesh: str | None = None) -> dict:
    assets = {Path(mesh).stem: load_mesh(mesh)} if mesh else \
        {name: make_asset(name) for name in ("tree", "vehicle")}
    grids = QUICK_GRIDS if quick else GRIDS
    elevations = QUICK_ELEVATIONS if quick else ELEVATIONS
    size = QUICK_SIZE if quick else SIZE
    results, pictures = [], []
    Path(out).mkdir(parents=True, exist_ok=True)
    for name, asset in assets.items():
        for grid in grids:
            log(f"impostor: {name}, grid {grid}")
            result = measure(name, asset, grid, elevations,
                             QUICK_AZIMUTHS if quick else AZIMUTHS, size)
            iou, got, want, el = result.pop("worst")
            if grid == grids[len(grids) // 2]:
                path = Path(out) / f"impostor-worst-{name}.png"
                save_image(contact_sheet([
                    (f"impostor, grid {grid}, between frames at {el:.0f} deg: IoU {iou:.3f}",
                     to_rgba8(got.color)), ("mesh", to_rgba8(want.color))], columns=2), path)
                pictures.append(path)
            results.append(result)
    return {"machine": machine(), "size": size, "quick": quick, "results": results,
            "pictures": [str(p) for p in pictures]}


def markdown(data: dict) -> str:
    lines = ["# Octahedral impostors against the mesh: on grid frames and between them", "",
             machine_line(data["machine"]), "",
             f"Perspective views at {data['size']}² fitting the bounding sphere; 'on': the "
             "camera exactly on a frame, 'between': at the middle of three frames (weights "
             "1/3 each). Depth: mean surface-point distance in frame texels.", "",
             "| asset | grid | frame | atlases | bake s | elevation | views | IoU mean | "
             "IoU min | SSIM mean | SSIM min | depth (texels) |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in data["results"]:
        for row in r["rows"]:
            lines.append(
                f"| {r['asset']} | {r['grid']} | {r['frame']}² | {format_bytes(r['bytes'])} | "
                f"{r['bake_seconds']:.1f} | {row['elevation']:.0f} | {row['views']} | "
                f"{row['iou_mean']:.3f} | {row['iou_min']:.3f} | {row['ssim_mean']:.3f} | "
                f"{row['ssim_min']:.3f} | {row['depth_texels']:.2f} |")
    lines += ["", "Worst view between frames at the lowest elevation, per asset: "
              + ", ".join(Path(p).name for p in data["pictures"]), ""]
    return "\n".join(lines)


def run_suite(quick: bool, out: Path, log, mesh: str | None = None) -> tuple[str, list[Path]]:
    """The ``impostor`` bench suite: run, write json/md and the pictures into ``out``."""
    data = run(quick, out, log, mesh)
    paths = write_report(out, "impostor", data, markdown)
    return markdown(data), paths + [Path(p) for p in data["pictures"]]
