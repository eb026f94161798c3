"""The AOV render targets and the two passes every `render()` runs.

Opaque pass: colour, world position + coverage, world normal (``FRAME_ATTACHMENTS``, see
shaders/include/frame_outputs.glsl), then any extra attachments (iteration counters, see
shaders/include/iterations.glsl), and a float depth texture; depth test and write.

Transparent pass (only when a transparent drawable is present): a second framebuffer that
shares the opaque depth texture (tested, never written) with three attachments — colour
accumulated front to back with the *under* operator (premultiplied), and the world position
and normal of the point where the accumulated opacity first reaches 0.5, each with a gate in
alpha. The blend function ``(ONE_MINUS_DST_ALPHA, ONE)`` composites colour and, because a
gated write is ``(value * g, g)`` with ``g`` 0 or 1, turns the AOV attachments into
"first gated write wins": no AOV is ever blended. Between transparent drawables the
accumulated opacity is copied to a texture the next one samples (shaders/include/
transparency.glsl), so the 0.5 point is exact across drawables.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .context import bind_home_framebuffer, check_gl_error
from .textures import read_depth, read_rgba, render_target

FRAME_ATTACHMENTS = 3  # colour, position + coverage, normal
FRONT_OPACITY_UNIT = 15  # texture unit of u_front_opacity (drawables use the low units)


@dataclass
class PassImages:
    """Read-back images of both passes, row 0 at the top."""

    color: np.ndarray       # (H, W, 4) straight colour of the opaque pass
    position: np.ndarray    # (H, W, 4) position + coverage
    normal: np.ndarray      # (H, W, 4)
    depth: np.ndarray       # (H, W)
    extra: list             # extra attachments of the opaque pass
    transparent: tuple | None = None  # (premultiplied colour, position + gate, normal + gate)


def draw_passes(ctx, size, opaque: Callable[[], None], transparent: list[Callable[[], None]],
                *, extra_attachments: int = 0) -> PassImages:
    """Clear fresh targets, run the opaque draw, then each transparent draw front to back.

    While a transparent draw runs, the opacity accumulated in front of it is bound to texture
    unit ``FRONT_OPACITY_UNIT`` (``u_front_opacity`` of shaders/include/transparency.glsl).
    Every GL object made here is released, even when a draw fails.
    """
    import moderngl

    width, height = size
    fbo = render_target(ctx, width, height, FRAME_ATTACHMENTS + extra_attachments)
    depth = fbo.depth_attachment
    made = [fbo]
    try:
        fbo.use()
        fbo.viewport = (0, 0, width, height)
        fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        ctx.enable_only(moderngl.DEPTH_TEST)
        opaque()
        check_gl_error(ctx, "drawing the opaque pass")
        images = PassImages(*(read_rgba(fbo, i) for i in range(FRAME_ATTACHMENTS)),
                            depth=read_depth(fbo),
                            extra=[read_rgba(fbo, FRAME_ATTACHMENTS + i)
                                   for i in range(extra_attachments)])
        if transparent:
            images.transparent = _transparent_pass(ctx, fbo, transparent, made)
        return images
    finally:
        bind_home_framebuffer(ctx)
        ctx.disable(moderngl.BLEND)
        for target in made:
            for attachment in target.color_attachments:
                attachment.release()
            target.release()
        depth.release()


class _Owned:
    """A lone texture in the list of framebuffers to release (it has no attachments)."""

    color_attachments = ()

    def __init__(self, texture):
        self.texture = texture

    def release(self) -> None:
        self.texture.release()


def _transparent_pass(ctx, opaque_fbo, draws, made) -> tuple:
    import moderngl

    width, height = opaque_fbo.size
    # cleared by uploading zeros: fbo.clear() would also clear the shared opaque depth
    zeros = np.zeros((height, width, 4), np.float32).tobytes()
    colors = [ctx.texture((width, height), 4, zeros, dtype="f4") for _ in range(3)]
    fbo = ctx.framebuffer(color_attachments=colors, depth_attachment=opaque_fbo.depth_attachment)
    made.append(fbo)
    front = ctx.texture((width, height), 4, zeros, dtype="f4")
    front.filter = (moderngl.NEAREST, moderngl.NEAREST)
    made.append(_Owned(front))
    fbo.depth_mask = False
    fbo.use()
    fbo.viewport = (0, 0, width, height)
    for draw in draws:
        fbo.use()
        ctx.enable_only(moderngl.DEPTH_TEST | moderngl.BLEND)
        ctx.blend_func = moderngl.ONE_MINUS_DST_ALPHA, moderngl.ONE
        front.use(FRONT_OPACITY_UNIT)
        draw()
        ctx.disable(moderngl.BLEND)
        ctx.copy_framebuffer(front, fbo)  # attachment 0: the opacity accumulated so far
    check_gl_error(ctx, "drawing the transparent pass")
    return tuple(read_rgba(fbo, i) for i in range(3))
