"""The "depth-peel" kind: a transparent plan composited exactly whatever its order, by depth
peeling (one pass per depth layer), the baseline visibility sorts are measured against.

Pass k draws the whole plan (its program reads ``u_peel_depth``: per pixel the depth and
the cell of layer k - 1, and keeps what lies behind) into its own colour and a float copy of
the nearest fragment's depth (a depth texture would round it, and the layer would be
peeled again), with the depth test picking the nearest; the ``layer`` program (one
full-screen triangle, ``u_layer``) then adds that colour under the layers in front. It stops
when a pass draws nothing (an occlusion query) or after ``max_layers`` passes (param). The
plan samples the opaque depth and may be shadowed as the "opaque-depth" kind's
(`opaque_depth.frame_inputs`; its params).
"""

from __future__ import annotations

from dataclasses import replace

import moderngl
import numpy as np

from ...gl.context import check_gl_error
from ..plan import Raster
from .opaque_depth import frame_inputs

_COMPOSITE = Raster(depth_test=False, depth_write=False, blend="under")


def draw_depth_peeled(executor, plan, camera, light, uniforms: dict, textures: dict) -> dict:
    with frame_inputs(executor, plan, light, uniforms, textures) as (uniforms, textures):
        layers = _peel(executor, plan, camera, light, uniforms, textures)
        check_gl_error(executor.ctx, f"drawing {plan.name}")
    return {"peeled_layers": layers}


def _peel(executor, plan, camera, light, uniforms, textures) -> int:
    ctx = executor.ctx
    outer = ctx.fbo
    width, height = outer.size
    peel_raster = replace(plan.raster, depth_write=True, blend="none")
    made = []
    try:
        color = ctx.texture((width, height), 4, dtype="f4")
        made.append(color)
        peeled = [ctx.texture((width, height), 4, dtype="f4") for _ in range(2)]
        depth = ctx.depth_texture((width, height))
        made.extend([*peeled, depth])
        for tex in peeled:
            tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
        fbos = [ctx.framebuffer(color_attachments=[color, z], depth_attachment=depth)
                for z in peeled]
        made.extend(fbos)
        query = ctx.query(samples=True)  # moderngl cannot release a query: one per frame
        # a pixel no fragment reaches keeps "beyond everything", so nothing comes back
        beyond = np.full((height, width, 4), 2.0, np.float32).tobytes()
        peeled[1].write(np.full((height, width, 4), -1.0, np.float32).tobytes())  # none yet
        layers = 0
        for k in range(int(plan.multipass.params["max_layers"])):
            fbo, before = fbos[k % 2], peeled[(k + 1) % 2]
            fbo.use()
            fbo.viewport = (0, 0, width, height)
            fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
            peeled[k % 2].write(beyond)
            with query:
                executor.draw_viewed(plan, camera, light, extra_uniforms=uniforms,
                                     textures={**textures, "u_peel_depth": before},
                                     raster=peel_raster)
            if query.samples == 0:
                break
            layers += 1
            outer.use()
            executor.draw_full_screen(plan.multipass.programs["layer"], {"u_layer": color},
                                      _COMPOSITE)
    finally:
        outer.use()  # never leave a released framebuffer bound
        for obj in reversed(made):
            obj.release()
    return layers
