"""Shared plumbing for renderers: camera uniforms, the AOV render target, read-back."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..gl.context import bind_home_framebuffer, check_gl_error
from ..gl.textures import read_depth, read_rgba, render_target
from .frame import Frame, frame_from_targets

FRAME_ATTACHMENTS = 3  # colour, position + coverage, normal (shaders/include/frame_outputs.glsl)


def set_uniforms(prog, values: dict) -> None:
    """Set the uniforms a program actually uses (the compiler drops unused ones)."""
    for name, value in values.items():
        if name not in prog:
            continue
        if isinstance(value, np.ndarray) and value.shape == (4, 4):
            prog[name].write(value.T.astype(np.float32).tobytes())  # GL is column-major
        else:
            prog[name].value = value


def camera_uniforms(camera) -> dict:
    """u_view, u_proj, u_eye, u_orthographic and u_view_dir for any shader."""
    view_dir = np.asarray(camera.eye) - np.asarray(camera.target)
    view_dir = view_dir / np.linalg.norm(view_dir)
    return {"u_view": camera.view, "u_proj": camera.proj,
            "u_eye": tuple(float(x) for x in camera.eye), "u_orthographic": camera.orthographic,
            "u_view_dir": tuple(float(x) for x in view_dir),
            "u_viewport": tuple(float(x) for x in camera.size)}


def draw_into_frame(ctx, camera, draw: Callable[[], None], *, extra_attachments: int = 0,
                    depth_test: bool = True) -> Frame:
    """Clear a fresh AOV target, call ``draw``, read every attachment back into a Frame.

    Extra attachments (iteration counters, ...) are returned in ``frame.extra["targets"]``.
    """
    import moderngl

    width, height = camera.size
    fbo = render_target(ctx, width, height, FRAME_ATTACHMENTS + extra_attachments)
    try:
        fbo.use()
        fbo.viewport = (0, 0, width, height)
        fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        ctx.enable_only(moderngl.DEPTH_TEST if depth_test else moderngl.NOTHING)
        draw()
        check_gl_error(ctx, "drawing")
        color, position, normal = (read_rgba(fbo, i) for i in range(FRAME_ATTACHMENTS))
        frame = frame_from_targets(camera, color, position, normal, read_depth(fbo))
        frame.extra["targets"] = [read_rgba(fbo, FRAME_ATTACHMENTS + i)
                                  for i in range(extra_attachments)]
        return frame
    finally:
        bind_home_framebuffer(ctx)
        for attachment in (*fbo.color_attachments, fbo.depth_attachment):
            attachment.release()
        fbo.release()
