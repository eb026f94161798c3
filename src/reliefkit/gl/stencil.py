"""Stencil-buffer passes, which moderngl does not expose: an offscreen framebuffer with a
depth + stencil renderbuffer, and the stencil state, through raw GL entry points.

The entry points come from `gl.raw` (the context's own loader).
A drawable that needs a stencil (the slicing technique's multi-pass test, §4.1 of the
Kautz-Seidel paper) renders into a `StencilTarget` inside its ``draw`` and then writes the
result into the frame's own target.
"""

from __future__ import annotations

import ctypes

from ..errors import GPUError
from .context import check_gl_error
from .raw import raw_gl

_u = ctypes.c_uint

GL_FRAMEBUFFER = 0x8D40
GL_RENDERBUFFER = 0x8D41
GL_DEPTH24_STENCIL8 = 0x88F0
GL_DEPTH_STENCIL_ATTACHMENT = 0x821A
GL_COLOR_ATTACHMENT0 = 0x8CE0
GL_TEXTURE_2D = 0x0DE1
GL_FRAMEBUFFER_COMPLETE = 0x8CD5
GL_STENCIL_TEST = 0x0B90
GL_COLOR_BUFFER_BIT, GL_DEPTH_BUFFER_BIT, GL_STENCIL_BUFFER_BIT = 0x4000, 0x0100, 0x0400

#: Stencil comparison functions (GL enums), glStencilFunc(func, ref, mask) passes when
#: ``ref & mask  FUNC  stencil & mask``.
NEVER, LESS, EQUAL, LEQUAL, GREATER, NOTEQUAL, GEQUAL, ALWAYS = range(0x0200, 0x0208)
#: Stencil operations.
KEEP, ZERO, REPLACE, INCR = 0x1E00, 0x0000, 0x1E01, 0x1E02



class StencilTarget:
    """RGBA32F colour textures (moderngl ones, to sample afterwards) and a depth24-stencil8
    renderbuffer in one framebuffer of ``size`` (W, H). `use` binds it and restores nothing:
    rebind the frame's target (``ctx.fbo.use()`` of the caller's) when done."""

    def __init__(self, ctx, size, attachments: int):
        from .context import check_framebuffer_size

        self.ctx, self.gl, self.size = ctx, raw_gl(ctx), tuple(int(s) for s in size)
        width, height = self.size
        check_framebuffer_size(ctx, width, height)
        self.textures = []
        self._fbo = self._rbo = None
        try:
            for _ in range(attachments):
                self.textures.append(ctx.texture((width, height), 4, dtype="f4"))
            gl = self.gl
            ident = _u(0)
            gl.GenRenderbuffers(1, ctypes.byref(ident))
            self._rbo = ident.value
            gl.BindRenderbuffer(GL_RENDERBUFFER, self._rbo)
            gl.RenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH24_STENCIL8, width, height)
            gl.GenFramebuffers(1, ctypes.byref(ident))
            self._fbo = ident.value
            gl.BindFramebuffer(GL_FRAMEBUFFER, self._fbo)
            for i, tex in enumerate(self.textures):
                gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0 + i, GL_TEXTURE_2D,
                                        tex.glo, 0)
            gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT,
                                       GL_RENDERBUFFER, self._rbo)
            buffers = (_u * attachments)(*(GL_COLOR_ATTACHMENT0 + i for i in range(attachments)))
            gl.DrawBuffers(attachments, buffers)
            status = gl.CheckFramebufferStatus(GL_FRAMEBUFFER)
            if status != GL_FRAMEBUFFER_COMPLETE:
                raise GPUError(f"a {width}x{height} framebuffer with a stencil buffer is "
                               f"incomplete (status 0x{status:04X}) on this driver")
            check_gl_error(ctx, "creating a stencil framebuffer")
        except BaseException:
            self.release()
            raise

    def use(self) -> None:
        """Bind it, full viewport."""
        self.gl.BindFramebuffer(GL_FRAMEBUFFER, self._fbo)
        self.gl.Viewport(0, 0, *self.size)

    def clear(self) -> None:
        gl = self.gl
        gl.ClearColor(0.0, 0.0, 0.0, 0.0)
        gl.ClearStencil(0)
        gl.StencilMask(0xFF)
        gl.ColorMask(1, 1, 1, 1)
        gl.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT)

    def stencil(self, func: int, ref: int, op_pass: int, *, color: bool) -> None:
        """Stencil test ``ref FUNC stencil``; where a fragment passes it (and survives its
        shader) apply ``op_pass``, else keep; write colour only when ``color``."""
        gl = self.gl
        gl.Enable(GL_STENCIL_TEST)
        gl.StencilFunc(func, ref, 0xFF)
        gl.StencilOp(KEEP, KEEP, op_pass)
        flag = 1 if color else 0
        gl.ColorMask(flag, flag, flag, flag)

    def end(self) -> None:
        """Stencil test off, colour writes on (the state everyone else expects)."""
        self.gl.Disable(GL_STENCIL_TEST)
        self.gl.ColorMask(1, 1, 1, 1)

    def release(self) -> None:
        from .context import bind_home_framebuffer

        gl = self.gl
        if self._fbo is not None:
            bind_home_framebuffer(self.ctx)
            gl.DeleteFramebuffers(1, ctypes.byref(_u(self._fbo)))
            self._fbo = None
        if self._rbo is not None:
            gl.DeleteRenderbuffers(1, ctypes.byref(_u(self._rbo)))
            self._rbo = None
        for tex in self.textures:
            tex.release()
        self.textures = []
