"""The "shadow-map" kind: a plan lit by a directional light whose shadows come from a depth
map drawn from the light (`render.shadows`), once per light, of every plan that shares its
geometry (all the materials of a mesh cast), each with its ``caster`` program.

Params: ``bounds`` (2, 3) the world box the map covers, ``size`` its texels on a side.
"""

from __future__ import annotations

import numpy as np

from ..plan import Raster
from ..shadows import SHADOW_UNIT, render_shadow_map

_CASTER_RASTER = Raster(depth_test=True, depth_write=True)  # both faces cast


def draw_shadow_mapped(executor, plan, camera, light, uniforms: dict, textures: dict) -> dict:
    depth, shadow_uniforms = _shadow_map(executor, plan, light)
    depth.use(SHADOW_UNIT)
    executor.draw_viewed(plan, camera, light,
                         extra_uniforms={**uniforms, **shadow_uniforms}, textures=textures)
    return {}


def _shadow_map(executor, plan, light):
    """The depth texture and uniforms of ``light`` for ``plan``'s group, drawn on first use."""
    key = ("shadow-map", id(plan.geometry), tuple(np.asarray(light.unit_direction).tolist()))
    if key not in executor.cache:
        casters = executor.groups.get(id(plan.geometry), [plan])
        params = plan.multipass.params
        outer = executor.ctx.fbo

        def draw_depth(light_camera):
            for caster in casters:
                viewed, _ = executor.view(caster, light_camera, light)
                executor.draw_viewed(viewed, light_camera, light,
                                     program_override=caster.multipass.programs["caster"],
                                     raster=_CASTER_RASTER)

        try:
            depth, shadow_uniforms = render_shadow_map(
                executor.ctx, params["bounds"], light, plan.origin, draw_depth,
                int(params["size"]))
        finally:
            outer.use()
        executor.keep(depth)
        shadow_uniforms.pop("u_shadow_map", None)
        executor.cache[key] = depth, {**shadow_uniforms, "u_shadow_map": SHADOW_UNIT}
    return executor.cache[key]

