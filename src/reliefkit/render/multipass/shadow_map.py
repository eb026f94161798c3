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

from ...core.transforms import translation
from ..plan import Raster
from ..shadows import SHADOW_SIZE, light_camera


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
        if params.get("sampler", "compare") == "depth":
            depth.compare_func = ""
            depth.filter = (moderngl.NEAREST, moderngl.NEAREST)
        if "bias" in params:
            shadow_uniforms["u_shadow_bias"] = float(params["bias"])
        executor.cache[key] = shadow_uniforms, {"u_shadow_map": depth}
    return executor.cache[key]


def render_shadow_map(ctx, bounds, light, origin, draw_depth, size: int = SHADOW_SIZE):
    """Draw ``draw_depth(light_camera)`` into a depth texture from the light; returns the
    texture (the caller releases it) and the uniforms of shadow_map.glsl for geometry
    stored relative to ``origin`` (float64 world point). Leaves the framebuffer and the
    enabled state to the caller to restore."""
    cam = light_camera(bounds, light, size)
    depth = ctx.depth_texture(cam.size)
    fbo = ctx.framebuffer(depth_attachment=depth)
    try:
        fbo.use()
        fbo.viewport = (0, 0, *cam.size)
        fbo.clear(depth=1.0)
        ctx.enable_only(moderngl.DEPTH_TEST)  # both faces cast: open meshes and leaves too
        draw_depth(cam)
    except BaseException:
        depth.release()
        raise
    finally:
        fbo.release()
    depth.compare_func = "<="  # sampler2DShadow: each lookup is a depth test, filtered
    depth.filter = (moderngl.LINEAR, moderngl.LINEAR)
    depth.repeat_x = depth.repeat_y = False
    world_texel = 2.0 * cam.ortho_height / size
    light_matrix = np.asarray(cam.proj) @ np.asarray(cam.view) @ translation(
        np.asarray(origin, np.float64))
    return depth, {"u_light_matrix": light_matrix, "u_shadow_texel": float(world_texel),
                   "u_shadow_bias": float(world_texel / (cam.far - cam.near))}
