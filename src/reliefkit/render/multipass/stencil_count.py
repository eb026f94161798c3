"""The "stencil-count" kind: a fragment is kept where every one of several tests passes,
counted in a stencil buffer one pass per test, group after group of the plan's triangles
(the first complete group wins, no depth test), then copied into the frame's target.

Per group: one pass of the ``test`` program per value of ``values`` (its int uniform
``uniform`` set to the value) increments the stencil where the count so far is complete and
the shader keeps the fragment; one pass of the ``color`` program writes the frame's outputs
where the count is complete and marks the pixel done; one more resets the incomplete
counts. The target (RGBA32F outputs and a depth + stencil buffer, `gl.stencil`) is then
drawn into the frame's own by the ``copy`` program (a full-screen triangle that samples
``u_src_color``, ``u_src_position`` and ``u_src_normal``), which writes the depth.

Params: ``uniform`` (str) and ``values`` (the tests), ``ranges`` ((G, 2) first index and
index count of each group, in draw order; usually per view, from the plan's hook).
Stats: ``draws``, the passes drawn.
"""

from __future__ import annotations

import moderngl

from ...gl import stencil as st
from ...gl.context import check_gl_error
from ...gl.targets import FRAME_ATTACHMENTS
from ..plan import DrawPlan, Geometry, Raster

_COUNT_RASTER = Raster(depth_test=False)  # the stencil decides, front to back
_FULLSCREEN = Geometry(vertices=3)        # the copy's full-screen triangle
_SOURCES = ("u_src_color", "u_src_position", "u_src_normal")


def draw_stencil_counted(executor, plan, camera, light, uniforms: dict,
                         textures: dict) -> dict:
    ctx = executor.ctx
    programs, params = plan.multipass.programs, plan.multipass.params
    values = tuple(int(v) for v in params["values"])
    complete = len(values)
    common = {"extra_uniforms": uniforms, "textures": textures}
    test = executor.bind(plan, camera, light, program_override=programs["test"], **common)
    color = executor.bind(plan, camera, light, program_override=programs["color"], **common)
    choose = executor.program(programs["test"])[params["uniform"]]
    frame_fbo = ctx.fbo
    target = st.StencilTarget(ctx, camera.size, FRAME_ATTACHMENTS)
    draws = 0
    try:
        target.use()
        target.clear()
        executor.set_raster(_COUNT_RASTER)
        for first, count in params["ranges"]:
            span = {"vertices": int(count), "first": int(first)}
            for i, value in enumerate(values):
                target.stencil(st.EQUAL, i, st.INCR, color=False)
                choose.value = value
                test.render(moderngl.TRIANGLES, **span)
            target.stencil(st.EQUAL, complete, st.INCR, color=True)
            color.render(moderngl.TRIANGLES, **span)
            target.stencil(st.GREATER, complete, st.ZERO, color=False)
            color.render(moderngl.TRIANGLES, **span)
            draws += complete + 2
        target.end()
        frame_fbo.use()
        copy = DrawPlan(f"{plan.name}: copy", programs["copy"], _FULLSCREEN)
        executor.draw_viewed(copy, camera, light,
                             textures=dict(zip(_SOURCES, target.textures, strict=True)))
        check_gl_error(ctx, f"drawing {plan.name} with stencil passes")
    finally:
        target.end()
        frame_fbo.use()
        target.release()
        frame_fbo.use()
    return {"draws": draws}
