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
    return time_scenes([(obj, options) for options in variants], camera, repeats=repeats,
                       light=light)


def time_scenes(entries, camera, *, repeats: int = 3, light=None,
                counts: bool = False) -> list[dict]:
    """`time_render` of each (object, options) of ``entries``, the draws interleaved. With
    ``counts`` each also has what does not depend on the device, from one more draw:
    ``draw_calls`` (the executor's), ``samples_passed`` (fragments that passed the depth
    test, in the order drawn) and ``primitives`` (GL queries); that draw is the warm-up of
    the timed ones."""
    import moderngl

    ctx = get_context()
    scenes = []
    light = light or DirectionalLight()
    fbo = None
    try:
        for obj, options in entries:
            scenes.append(Scene([obj], ctx=ctx, **options))
        fbo = render_target(ctx, *camera.size, FRAME_ATTACHMENTS)

        def drawing(scene):
            def draw():
                fbo.use()
                fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
                ctx.enable_only(moderngl.DEPTH_TEST)
                scene.draw_opaque(camera, light)
            return draw

        draws = [drawing(s) for s in scenes]
        counted = [_counts(ctx, scene, draw) for scene, draw in zip(scenes, draws,
                                                                    strict=True)] \
            if counts else [{} for _ in draws]
        times = gpu_times_ms(ctx, draws, repeats=repeats, warmup=0 if counts else 1)
        return [t | c for t, c in zip(times, counted, strict=True)]
    finally:
        bind_home_framebuffer(ctx)
        if fbo is not None:
            for attachment in (*fbo.color_attachments, fbo.depth_attachment):
                attachment.release()
            fbo.release()
        for scene in scenes:
            scene.release()


def _counts(ctx, scene, draw) -> dict:
    """One draw of ``scene`` under GL queries: its draw calls, samples passed, primitives."""
    before = scene.executor.draw_calls
    query = ctx.query(samples=True, primitives=True)
    with query:
        draw()
    return {"draw_calls": scene.executor.draw_calls - before, "samples_passed": query.samples,
            "primitives": query.primitives}
