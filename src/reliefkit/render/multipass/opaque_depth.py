"""The "opaque-depth" kind: a transparent plan drawn once, sampling a copy of the opaque
pass's depth (``u_opaque_depth``, the attached depth cannot be sampled while it is tested;
``u_clip_opaque``: whether any opaque surface was drawn), so that what it marches stops at
opaque surfaces. Params: ``shadow_map`` (optional) lights it with the light's shadow map
(`shadow_map`'s params, the ``caster`` program).

`frame_inputs` gives the same to the other kinds that draw such plans in several passes.
"""

from __future__ import annotations

from contextlib import contextmanager

import moderngl

from ...gl.context import check_gl_error
from ...gl.textures import read_depth
from .shadow_map import shadow_inputs


def draw_with_opaque_depth(executor, plan, camera, light, uniforms: dict,
                           textures: dict) -> dict:
    with frame_inputs(executor, plan, light, uniforms, textures) as (uniforms, textures):
        executor.draw_viewed(plan, camera, light, extra_uniforms=uniforms, textures=textures)
        check_gl_error(executor.ctx, f"drawing {plan.name}")
    return {}


@contextmanager
def frame_inputs(executor, plan, light, uniforms: dict, textures: dict):
    """``uniforms`` and ``textures`` with the light's shadow map (when the plan's params
    ask for one) and a copy of the bound framebuffer's depth, released on exit."""
    outer = executor.ctx.fbo
    shadow_map = plan.multipass.params.get("shadow_map")
    if shadow_map is not None:
        shadow_uniforms, shadow_textures = shadow_inputs(executor, plan, light, shadow_map)
        uniforms, textures = {**uniforms, **shadow_uniforms}, {**textures, **shadow_textures}
    depth = read_depth(outer, top_row_first=False)  # GL rows: texelFetch(gl_FragCoord)
    copy = executor.ctx.texture(outer.size, 1, depth.tobytes(), dtype="f4")
    try:
        copy.filter = (moderngl.NEAREST, moderngl.NEAREST)
        yield ({**uniforms, "u_clip_opaque": bool((depth < 1.0).any())},
               {**textures, "u_opaque_depth": copy})
    finally:
        copy.release()
        outer.use()
