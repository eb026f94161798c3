"""The "half-opacity-search" kind: a transparent plan of instanced cells composited in
visibility order (its view hook's), whose AOVs belong to the point where the opacity
accumulated over the drawables in front and this plan first reaches 0.5.

A fragment cannot read what lies in front of it inside one draw, so the point is found in
extra passes: per pixel, a base-16 search over the rank (instance number) of the cell where
it lies, the ``bins`` program summing optical depths order-independently with additive
blending into 16 rank bins per pass (``u_search``: the rank range; four RGBA32F
attachments), ceil(log16 N) passes with a read-back each; then the ``final`` program's
fragment of that rank (``u_search``: the rank and the optical depth still needed) marches
its segment and writes the point into the transparent pass. The plan itself is drawn
first, as the "opaque-depth" kind draws it (`opaque_depth.frame_inputs`; its params).
"""

from __future__ import annotations

from dataclasses import replace

import moderngl
import numpy as np

from ...gl.context import check_gl_error
from ...gl.textures import read_rgba
from .opaque_depth import frame_inputs

SEARCH_BINS = 16  # rank bins per pass: four RGBA attachments of the bins program


def draw_half_opacity_search(executor, plan, camera, light, uniforms: dict,
                             textures: dict) -> dict:
    outer = executor.ctx.fbo
    with frame_inputs(executor, plan, light, uniforms, textures) as (uniforms, textures):
        front = read_rgba(outer, 0, top_row_first=False)[..., 3].astype(np.float64)
        executor.draw_viewed(plan, camera, light, extra_uniforms=uniforms, textures=textures)
        passes = _search(executor, plan, camera, light, uniforms, textures, front)
        check_gl_error(executor.ctx, f"drawing {plan.name}")
    return {"half_opacity_passes": passes}


def _search(executor, plan, camera, light, uniforms, textures, front) -> int:
    """Find, per pixel, the rank where the opacity reaches 0.5 and draw that point's
    position and normal (the ``final`` program); returns the passes drawn."""
    ctx = executor.ctx
    outer = ctx.fbo
    width, height = outer.size
    programs = plan.multipass.programs
    bins_raster = replace(plan.raster, depth_write=False, blend="add")
    need = needed_optical_depth(front)
    made = []
    try:
        bins = [ctx.texture((width, height), 4, dtype="f4") for _ in range(4)]
        made.extend(bins)
        fbo = ctx.framebuffer(color_attachments=bins, depth_attachment=outer.depth_attachment)
        made.append(fbo)
        search = ctx.texture((width, height), 2, dtype="f4")
        made.append(search)
        search.filter = (moderngl.NEAREST, moderngl.NEAREST)
        lo = np.zeros((height, width))
        hi = np.where(np.isfinite(need), float(plan.geometry.instances), 0.0)
        zeros = np.zeros((height, width, 4), np.float32).tobytes()
        passes = 0
        while (hi - lo > 1).any():
            search.write(np.stack([lo, hi], axis=-1).astype(np.float32).tobytes())
            fbo.use()
            fbo.viewport = (0, 0, width, height)
            for tex in bins:
                tex.write(zeros)
            executor.draw_viewed(plan, camera, light, extra_uniforms=uniforms,
                                 textures={**textures, "u_search": search},
                                 program_override=programs["bins"], raster=bins_raster)
            sums = np.concatenate([read_rgba(fbo, k, top_row_first=False)
                                   for k in range(4)], axis=-1)
            lo, hi, need = narrow(lo, hi, need, sums.astype(np.float64))
            passes += 1
        found = (hi - lo == 1) & np.isfinite(need)
        rank = np.where(found, lo, -1.0)
        search.write(np.stack([rank, np.where(found, need, 0.0)], axis=-1)
                     .astype(np.float32).tobytes())
        outer.use()
        executor.draw_viewed(plan, camera, light, extra_uniforms=uniforms,
                             textures={**textures, "u_search": search},
                             program_override=programs["final"])
    finally:
        outer.use()  # never leave a released framebuffer bound
        for obj in reversed(made):
            obj.release()
    return passes + 1


def needed_optical_depth(front: np.ndarray) -> np.ndarray:
    """Per pixel, the optical depth a plan behind opacity ``front`` must accumulate to bring
    the total to 0.5: -ln(1 - a) with front + (1 - front) a = 0.5 (inf where front >= 0.5)."""
    safe = np.minimum(front, 0.5)
    target = (0.5 - safe) / (1.0 - safe)
    return np.where(front < 0.5, -np.log1p(-np.minimum(target, 1.0 - 1e-12)), np.inf)


def narrow(lo, hi, need, sums):
    """One step of the base-16 rank search: ``sums[..., k]`` is the optical depth of the
    ranks in [lo, t_k), t_k = lo + ceil((hi - lo)(k + 1) / 16); keep the first bin whose
    sum reaches ``need`` (the optical depth still needed), or give up where none does."""
    k = np.arange(1, SEARCH_BINS + 1)
    thresholds = lo[..., None] + np.ceil((hi - lo)[..., None] * k / SEARCH_BINS)
    active = hi - lo > 1
    reached = sums >= need[..., None]
    first = np.argmax(reached, axis=-1)
    some = reached.any(axis=-1)
    below = np.take_along_axis(sums, np.maximum(first - 1, 0)[..., None], -1)[..., 0]
    prev = np.take_along_axis(thresholds, np.maximum(first - 1, 0)[..., None], -1)[..., 0]
    new_lo = np.where(first > 0, prev, lo)
    new_hi = np.take_along_axis(thresholds, first[..., None], -1)[..., 0]
    new_need = need - np.where(first > 0, below, 0.0)
    lo = np.where(active & some, new_lo, np.where(active, 0.0, lo))
    hi = np.where(active & some, new_hi, np.where(active, 0.0, hi))
    need = np.where(active & ~some, np.inf, np.where(active, new_need, need))
    return lo, hi, need
