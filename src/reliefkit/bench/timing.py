"""Side-by-side frame timing of drawables in one framebuffer (no read-back in the loop)."""

from __future__ import annotations

from ..gl.context import bind_home_framebuffer, get_context
from ..gl.targets import FRAME_ATTACHMENTS
from ..gl.textures import render_target
from ..gl.timing import gpu_times_ms
from ..render.draw import Scene
from ..scene.light import DirectionalLight


def time_render(obj, camera, *, repeats: int = 3, light=None, **options) -> dict:
    """Median wall and GPU milliseconds of drawing ``obj`` (clear + draw + finish)."""
    return time_renders(obj, camera, [options], repeats=repeats, light=light)[0]


def time_renders(obj, camera, variants: list[dict], *, repeats: int = 3,
                 light=None) -> list[dict]:
    """`time_render` of ``obj`` with each option set of ``variants``, the draws interleaved
    (`gl.timing.gpu_times_ms`): use it for figures reported as ratios of each other."""
    return time_side_by_side([(obj, options) for options in variants], camera,
                             repeats=repeats, light=light)


def time_side_by_side(drawn: list[tuple[object, dict]], camera, *, repeats: int = 3,
                      light=None) -> list[dict]:
    """`time_render` of each (object, render options) of ``drawn``, the draws interleaved:
    several objects (a representation and its mesh) timed as ratios of each other. Only the
    opaque pass is drawn, as in `time_render`."""
    import moderngl

    ctx = get_context()
    scenes = []
    light = light or DirectionalLight()
    fbo = None
    try:
        for obj, options in drawn:
            scenes.append(Scene([obj], ctx=ctx, **options))
        fbo = render_target(ctx, *camera.size, FRAME_ATTACHMENTS)

        def drawing(scene):
            def draw():
                fbo.use()
                fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
                ctx.enable_only(moderngl.DEPTH_TEST)
                scene.draw_opaque(camera, light)
            return draw

        return gpu_times_ms(ctx, [drawing(s) for s in scenes], repeats=repeats)
    finally:
        bind_home_framebuffer(ctx)
        if fbo is not None:
            for attachment in (*fbo.color_attachments, fbo.depth_attachment):
                attachment.release()
            fbo.release()
        for scene in scenes:
            scene.release()
