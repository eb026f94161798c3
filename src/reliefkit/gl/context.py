"""The one place an OpenGL context is made: headless EGL by default, probed and cached.

``get_context()`` returns the context GL work runs on: a process-wide moderngl context
(GL >= 4.3 core), made on first use, unless a caller's own context is in force in this
thread (`using`). Set ``RELIEFKIT_GL_BACKEND`` to another glcontext backend name (for
example ``x11``) to use a window system instead of EGL.
"""

from __future__ import annotations

import contextlib
import os
import threading

from ..errors import GPUError

REQUIRED_VERSION = 430
_lock = threading.Lock()
_context = None
_local = threading.local()  # .stack: the contexts `using` put in force in this thread

# Debian packages that provide EGL + Mesa's software rasterizer (llvmpipe).
EGL_PACKAGES = "libegl1 libegl-mesa0 libgl1-mesa-dri"


def create_context(backend: str | None = None):
    """Create a new standalone moderngl context, raising GPUError with advice on failure.

    The driver makes a new context current; the context in force (`get_context`), if there
    is one, is made current again, so making a context for later (`using`, ``bake(ctx=)``)
    never moves the process-wide one's GL calls onto it."""
    import moderngl

    backend = backend or os.environ.get("RELIEFKIT_GL_BACKEND", "egl")
    try:
        ctx = moderngl.create_context(standalone=True, backend=backend, require=REQUIRED_VERSION)
    except Exception as exc:  # glcontext raises plain Exceptions with driver text
        detail = " ".join(str(exc).split()) or type(exc).__name__
        raise GPUError(
            f"could not create an OpenGL {REQUIRED_VERSION // 100}.{REQUIRED_VERSION % 100 // 10} "
            f"context through {backend} ({detail}); on Debian install: "
            f"sudo apt-get install -y {EGL_PACKAGES}"
        ) from None
    in_force = _in_force()
    if in_force is not None:
        in_force.__enter__()
    return ctx


def get_context():
    """The context of the innermost `using` in this thread, else the shared process-wide
    one, created on first use."""
    in_force = _in_force()
    if in_force is not None:
        return in_force
    global _context
    with _lock:
        if _context is None:
            _context = create_context()
        return _context


@contextlib.contextmanager
def using(ctx):
    """Run the GL work inside on ``ctx``: `get_context()` returns it in this thread and it
    is made current; on exit (on error too) the context in force before is current again.
    ``ctx=None`` changes nothing (the context in force stays, or is made when first asked).

    Every GL user (bakers, the voxelizer, `Scene`) gets its context from `get_context()`
    unless handed one, so this one override reaches all of them without a parameter
    threaded through each baker; nestable, and thread-local as a current GL context is.
    Nothing caches GL objects outside their context (programs and helpers live in
    ``ctx.extra``), so contexts never share them.
    """
    if ctx is None:
        yield None
        return
    stack = _local.__dict__.setdefault("stack", [])
    stack.append(ctx)
    try:
        ctx.__enter__()  # GL calls go to the current context, whichever object makes them
        yield ctx
    finally:
        stack.pop()
        _make_current_again(ctx)


def _make_current_again(left) -> None:
    """After ``left``'s `using`: the context in force before it is current again; with none
    (no outer `using`, no process-wide context yet) nothing is."""
    outer = _in_force()
    if outer is None:
        left.__exit__(None, None, None)
    else:
        outer.__enter__()


def _in_force():
    """What `get_context` returns in this thread without making anything: the innermost
    `using` context, else the process-wide one, else None."""
    stack = getattr(_local, "stack", None)
    return stack[-1] if stack else _context


def has_context() -> bool:
    """Whether this process has made its shared context (a batch worker sets its EGL device
    and thread count before; work inside `using` never makes it)."""
    return _context is not None


def bind_home_framebuffer(ctx) -> None:
    """Bind a persistent 1x1 framebuffer. Call before releasing a bound framebuffer:
    moderngl rebinds the last used one when it creates the next, and a deleted one is
    GL_INVALID_OPERATION (a headless context has no default framebuffer to fall back to)."""
    extra = ctx.extra if isinstance(ctx.extra, dict) else {}
    if "home_fbo" not in extra:
        extra["home_fbo"] = ctx.simple_framebuffer((1, 1))
        ctx.extra = extra
    extra["home_fbo"].use()


def gl_info(ctx=None) -> dict:
    """Renderer, version and the limits reliefkit checks before allocating."""
    ctx = ctx or get_context()
    info = ctx.info
    keys = {
        "renderer": "GL_RENDERER",
        "vendor": "GL_VENDOR",
        "version": "GL_VERSION",
        "max_texture_size": "GL_MAX_TEXTURE_SIZE",
        "max_3d_texture_size": "GL_MAX_3D_TEXTURE_SIZE",
        "max_renderbuffer_size": "GL_MAX_RENDERBUFFER_SIZE",
        "max_viewport_dims": "GL_MAX_VIEWPORT_DIMS",
        "max_color_attachments": "GL_MAX_COLOR_ATTACHMENTS",
        "max_texture_image_units": "GL_MAX_TEXTURE_IMAGE_UNITS",
    }
    out = {name: info.get(key) for name, key in keys.items()}
    out["version_code"] = ctx.version_code
    return out


def check_gl_error(ctx, what: str) -> None:
    """Raise GPUError if the GL error flag is set (moderngl does not check it for us)."""
    err = ctx.error
    if err != "GL_NO_ERROR":
        raise GPUError(f"OpenGL reported {err} while {what}")


def check_framebuffer_size(ctx, width: int, height: int) -> None:
    """Refuse a render target larger than the renderbuffer and viewport limits."""
    if width < 1 or height < 1:
        raise GPUError(f"framebuffer size must be positive, got {width}x{height}")
    limit = int(ctx.info["GL_MAX_RENDERBUFFER_SIZE"])
    vw, vh = (int(x) for x in ctx.info["GL_MAX_VIEWPORT_DIMS"])
    if width > min(limit, vw) or height > min(limit, vh):
        raise GPUError(
            f"a {width}x{height} image exceeds this GPU's limit of "
            f"{min(limit, vw)}x{min(limit, vh)}; render a smaller size"
        )
