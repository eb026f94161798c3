"""The "shadow-map" kind: a plan lit by a directional light whose shadows come from a depth
map drawn from the light (`render.shadows`), once per light, of every plan that shares its
geometry (all the materials of a mesh cast), each with its ``caster`` program. Other kinds
light their plans with it too (`shadow_inputs`).

Params: ``bounds`` (2, 3) the world box the map covers, ``size`` its texels on a side; and
optionally ``cull`` the faces casters skip ("none": both faces cast), ``sampler``
"compare" (linear, compared on lookup: shaders/include/shadow_map.glsl's) or "depth" (the
nearest depth, which the shader compares itself), ``bias`` a window-depth bias in place of
one texel's depth, and ``caster_hooks`` False to draw the casters without their view hooks
(a hook that only orders instances changes no depth).
"""

from __future__ import annotations

import moderngl
import numpy as np

from ..plan import Raster
from ..shadows import render_shadow_map


def draw_shadow_mapped(executor, plan, camera, light, uniforms: dict, textures: dict) -> dict:
    shadow_uniforms, shadow_textures = shadow_inputs(executor, plan, light,
                                                     plan.multipass.params)
    executor.draw_viewed(plan, camera, light, extra_uniforms={**uniforms, **shadow_uniforms},
                         textures={**textures, **shadow_textures})
    return {}


def shadow_inputs(executor, plan, light, params) -> tuple[dict, dict]:
    """The uniforms and the texture (``u_shadow_map``) of ``light``'s shadow map for
    ``plan``'s group, drawn on first use with ``params`` (the module docstring's)."""
    key = ("shadow-map", id(plan.geometry), tuple(np.asarray(light.unit_direction).tolist()))
    if key not in executor.cache:
        casters = executor.groups.get(id(plan.geometry), [plan])
        raster = Raster(depth_test=True, depth_write=True, cull=params.get("cull", "none"))
        outer = executor.ctx.fbo

        def draw_depth(light_camera):
            for caster in casters:
                viewed = executor.view(caster, light_camera, light)[0] \
                    if params.get("caster_hooks", True) else caster
                executor.draw_viewed(viewed, light_camera, light,
                                     program_override=caster.multipass.programs["caster"],
                                     raster=raster)

        try:
            depth, shadow_uniforms = render_shadow_map(
                executor.ctx, params["bounds"], light, plan.origin, draw_depth,
                int(params["size"]))
        finally:
            outer.use()
        executor.keep(depth)
        shadow_uniforms.pop("u_shadow_map", None)  # bound with the plan's textures
        if params.get("sampler", "compare") == "depth":
            depth.compare_func = ""
            depth.filter = (moderngl.NEAREST, moderngl.NEAREST)
        if "bias" in params:
            shadow_uniforms["u_shadow_bias"] = float(params["bias"])
        executor.cache[key] = shadow_uniforms, {"u_shadow_map": depth}
    return executor.cache[key]
