"""One drawn object against the full mesh: the project's metrics over the fixed views (one
upload each), and its frame time as a ratio to the mesh's, timed side by side."""

from __future__ import annotations

import math

import numpy as np

from ..bench.timing import time_scenes
from ..metrics import compare
from ..pictures import TILE_BACKGROUND
from ..render import render
from ..render.registry import make_drawables

#: What each view reports (metrics.compare's keys): colour (SSIM, PSNR), coverage (mask IoU),
#: on-surface agreement (world position error where both cover, / bounding radius) and depth.
MEASURES = ("ssim", "iou", "psnr", "position_mean_rel", "depth_mean")
TIMING_REPEATS = 3


def scores(frames, truths, radius: float) -> dict:
    """Per view and the mean over the views of every `MEASURES` figure (NaN views, where
    nothing is covered by both, are left out of a geometric mean; PSNR of identical views is
    infinite and stays so)."""
    views = [{key: float(compare(frame, truth, scene_size=radius)[key]) for key in MEASURES}
             for frame, truth in zip(frames, truths, strict=True)]
    means = {}
    for key in MEASURES:
        values = [v[key] for v in views if not math.isnan(v[key])]
        means[key] = float(np.mean(values)) if values else math.nan
    return means | {"views": views}


def draws_opaque(obj, options: dict) -> bool:
    """Whether every drawable of ``obj`` (with render ``options``) is drawn in the opaque
    pass (what is timed)."""
    return all(plan.render_pass != "transparent"
               for drawable in make_drawables([obj], options, instrument=False)
               for plan in drawable.plans)


def frame_time(obj, mesh, camera, options: dict) -> dict:
    """Milliseconds of ``obj`` and of the full ``mesh`` drawn interleaved in one run, and
    their ratio (None for an object with transparent drawables: only the opaque pass is
    timed)."""
    if not draws_opaque(obj, options):
        return {"frame_ms": None, "mesh_ms": None, "frame_ratio": None}
    mesh_t, obj_t = time_scenes([(mesh, {}), (obj, options)], camera,
                                      repeats=TIMING_REPEATS)
    return {"frame_ms": obj_t["wall_ms"], "mesh_ms": mesh_t["wall_ms"],
            "frame_ratio": obj_t["wall_ms"] / max(mesh_t["wall_ms"], 1e-9)}


def measure(obj, mesh, cameras_by_size: dict, truths_by_size: dict,
            options: dict) -> tuple[dict, dict]:
    """Figures by screen size of ``obj`` drawn with render ``options``, and the first view's
    picture by size (for the sheets)."""
    figures, pictures = {}, {}
    for size, cameras in cameras_by_size.items():
        frames = render(obj, cameras, **options)
        figures[size] = scores(frames, truths_by_size[size], mesh.radius) \
            | frame_time(obj, mesh, cameras[0], options)
        pictures[size] = frames[0].rgba8(TILE_BACKGROUND)
    return figures, pictures
