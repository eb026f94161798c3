"""Raw GL entry points that moderngl does not expose (stencil passes, compressed textures),
resolved through the context's own loader (glcontext's ``load``, the same one moderngl
resolves its functions with), so they act on the context moderngl made current. The one
copy of that lookup: `raw_gl(ctx)`, once per context.
"""

from __future__ import annotations

import ctypes

from ..errors import GPUError

_u, _i, _f = ctypes.c_uint, ctypes.c_int, ctypes.c_float
_SIGNATURES = {
    "glGenFramebuffers": (None, _i, ctypes.POINTER(_u)),
    "glDeleteFramebuffers": (None, _i, ctypes.POINTER(_u)),
    "glBindFramebuffer": (None, _u, _u),
    "glFramebufferTexture2D": (None, _u, _u, _u, _u, _i),
    "glFramebufferRenderbuffer": (None, _u, _u, _u, _u),
    "glCheckFramebufferStatus": (_u, _u),
    "glGenRenderbuffers": (None, _i, ctypes.POINTER(_u)),
    "glDeleteRenderbuffers": (None, _i, ctypes.POINTER(_u)),
    "glBindRenderbuffer": (None, _u, _u),
    "glRenderbufferStorage": (None, _u, _u, _i, _i),
    "glDrawBuffers": (None, _i, ctypes.POINTER(_u)),
    "glViewport": (None, _i, _i, _i, _i),
    "glClearColor": (None, _f, _f, _f, _f),
    "glClearStencil": (None, _i),
    "glClear": (None, _u),
    "glEnable": (None, _u),
    "glDisable": (None, _u),
    "glStencilFunc": (None, _u, _i, _u),
    "glStencilOp": (None, _u, _u, _u),
    "glStencilMask": (None, _u),
    "glColorMask": (None, ctypes.c_ubyte, ctypes.c_ubyte, ctypes.c_ubyte, ctypes.c_ubyte),
    "glGenTextures": (None, _i, ctypes.POINTER(_u)),
    "glDeleteTextures": (None, _i, ctypes.POINTER(_u)),
    "glBindTexture": (None, _u, _u),
    "glTexParameteri": (None, _u, _u, _i),
    "glCompressedTexImage2D": (None, _u, _i, _u, _i, _i, _i, _i, ctypes.c_void_p),
    "glCompressedTexImage3D": (None, _u, _i, _u, _i, _i, _i, _i, _i, ctypes.c_void_p),
}


class _GL:
    """The raw entry points above, resolved once per context."""

    def __init__(self, ctx):
        loader = getattr(getattr(ctx, "mglo", None), "_context", None)
        if loader is None or not hasattr(loader, "load"):
            raise GPUError("raw GL calls (stencil passes, compressed textures) need the GL "
                           "loader of moderngl's context, which this moderngl build does not "
                           "expose; use the single-pass test and uncompressed textures")
        for name, (restype, *argtypes) in _SIGNATURES.items():
            address = loader.load(name)
            if not address:
                raise GPUError(f"the GL driver has no {name}; raw GL calls are unavailable")
            setattr(self, name[2:], ctypes.CFUNCTYPE(restype, *argtypes)(address))


def raw_gl(ctx) -> _GL:
    """The entry points of ``ctx``, resolved on first use and kept on ``ctx.extra``."""
    extra = ctx.extra if isinstance(ctx.extra, dict) else {}
    if "raw_gl" not in extra:
        extra["raw_gl"] = _GL(ctx)
        ctx.extra = extra
    return extra["raw_gl"]
