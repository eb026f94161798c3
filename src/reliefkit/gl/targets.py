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

Multisampled colour (``msaa`` > 1): the opaque draw runs once more into multisampled colour
and position + coverage renderbuffers with their own multisampled depth, resolved (blitted)
into single-sample textures: straight colour whose alpha is the covered fraction of each
pixel (times the surface's own alpha). The AOVs never come from it (a resolved position or
depth would average two surfaces), and transparent drawables are drawn single-sample only.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..errors import GPUError, UsageError
from .context import bind_home_framebuffer, check_gl_error
from .textures import MAX_TARGET_BYTES, read_depth, read_rgba, render_target

FRAME_ATTACHMENTS = 3  # colour, position + coverage, normal
MSAA_CHOICES = (1, 2, 4, 8)  # samples per pixel of the multisampled colour
FRONT_OPACITY_UNIT = 15  # texture unit of u_front_opacity (drawables use the low units)
MAX_HOST_BYTES = 4 << 30  # refuse renders whose read-back needs more host memory than this
HOST_MEMORY_FRACTION = 0.5  # ... or more than this fraction of the machine's physical memory


def host_limit() -> int:
    """The host-memory cap of one render: `MAX_HOST_BYTES`, or less on a small machine."""
    import os

    try:
        physical = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        return MAX_HOST_BYTES
    return min(MAX_HOST_BYTES, int(HOST_MEMORY_FRACTION * physical)) if physical > 0 else \
        MAX_HOST_BYTES


def host_bytes(width: int, height: int, extra_attachments: int = 0, *, msaa: int = 1,
               transparent: bool = False) -> int:
    """Host memory a render's read-back needs at its peak, estimated before allocating.

    Every RGBA32F attachment is read as bytes and copied into a flipped array (2 x 16 bytes
    per pixel), the depth likewise (2 x 4); the Frame built from them holds colour, position,
    normal, depth, mask and the iteration counters (about 16 + 24 + 12 + 4 + 1 + 8 bytes);
    the transparent pass reads three more attachments plus its zero upload, msaa two more.
    """
    per_pixel = 2 * 16 * (FRAME_ATTACHMENTS + extra_attachments) + 2 * 4 + 65
    if msaa > 1:
        per_pixel += 2 * 16 * 2 + 16
    if transparent:
        per_pixel += 2 * 16 * 3 + 16
    return width * height * per_pixel


def check_host_memory(width: int, height: int, extra_attachments: int = 0, *, msaa: int = 1,
                      transparent: bool = False) -> None:
    """Refuse a render whose read-back would need more host memory than `host_limit()`."""
    needed = host_bytes(width, height, extra_attachments, msaa=msaa, transparent=transparent)
    limit = host_limit()
    if needed > limit:
        raise GPUError(f"a {width}x{height} image with its AOVs needs about "
                       f"{needed / 2**30:.1f} GiB of host memory to read back (limit "
                       f"{limit / 2**30:.1f} GiB); render a smaller size")


@dataclass
class PassImages:
    """Read-back images of both passes, row 0 at the top."""

    color: np.ndarray       # (H, W, 4) straight colour of the opaque pass
    position: np.ndarray    # (H, W, 4) position + coverage
    normal: np.ndarray      # (H, W, 4)
    depth: np.ndarray       # (H, W)
    extra: list             # extra attachments of the opaque pass
    transparent: tuple | None = None  # (premultiplied colour, position + gate, normal + gate)
    msaa_color: np.ndarray | None = None  # (H, W, 4) straight multisampled opaque colour


def draw_passes(ctx, size, opaque: Callable[[], None], transparent: list[Callable[[], None]],
                *, extra_attachments: int = 0, msaa: int = 1) -> PassImages:
    """Clear fresh targets, run the opaque draw, then each transparent draw front to back;
    with ``msaa`` > 1 the opaque draw runs once more, multisampled (`PassImages.msaa_color`).

    While a transparent draw runs, the opacity accumulated in front of it is bound to texture
    unit ``FRONT_OPACITY_UNIT`` (``u_front_opacity`` of shaders/include/transparency.glsl).
    Every GL object made here is released, even when a draw fails.
    """
    import moderngl

    width, height = size
    check_host_memory(width, height, extra_attachments, msaa=msaa,
                      transparent=bool(transparent))
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
        if msaa > 1:
            images.msaa_color = _multisampled_color(ctx, size, opaque, msaa)
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


def check_msaa(ctx, samples: int) -> None:
    """Refuse a sample count that is no power of two up to 8, or over GL_MAX_SAMPLES."""
    if samples not in MSAA_CHOICES:
        raise UsageError(f"msaa must be one of {', '.join(map(str, MSAA_CHOICES))}, got "
                         f"{samples!r}")
    limit = int(ctx.info["GL_MAX_SAMPLES"])
    if samples > limit:
        raise GPUError(f"msaa {samples} exceeds this GPU's limit of {limit} samples; use "
                       f"--msaa {limit} or less")


def _multisampled_color(ctx, size, opaque: Callable[[], None], samples: int) -> np.ndarray:
    """Run the opaque draw into ``samples``-sample colour, position + coverage and depth;
    resolve; return straight colour whose alpha includes the covered fraction."""
    import moderngl

    width, height = size
    needed = width * height * 36 * samples  # two RGBA32F attachments + depth per sample
    if needed > MAX_TARGET_BYTES:
        raise GPUError(f"a {width}x{height} image with msaa {samples} needs "
                       f"{needed / 2**30:.1f} GiB of multisampled buffers (limit "
                       f"{MAX_TARGET_BYTES / 2**30:.0f} GiB); use fewer samples or a smaller size")
    made = []
    try:
        buffers = [ctx.renderbuffer((width, height), 4, samples=samples, dtype="f4")
                   for _ in range(2)]
        made += buffers
        made.append(ctx.depth_renderbuffer((width, height), samples=samples))
        multisampled = ctx.framebuffer(color_attachments=buffers, depth_attachment=made[-1])
        made.append(multisampled)
        textures = [ctx.texture((width, height), 4, dtype="f4") for _ in range(2)]
        made += textures
        resolved = ctx.framebuffer(color_attachments=textures)
        made.append(resolved)
        multisampled.use()
        multisampled.viewport = (0, 0, width, height)
        multisampled.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        ctx.enable_only(moderngl.DEPTH_TEST)
        opaque()  # outputs past position + coverage (normal, counters) have no buffer: dropped
        check_gl_error(ctx, f"drawing the opaque pass with {samples} samples")
        ctx.copy_framebuffer(resolved, multisampled)  # resolves every attachment (a blit)
        check_gl_error(ctx, "resolving the multisampled colour")
        mean, coverage = read_rgba(resolved, 0), read_rgba(resolved, 1)[..., 3:4]
    finally:
        bind_home_framebuffer(ctx)  # never leave a released framebuffer bound
        for obj in reversed(made):
            obj.release()
    # samples not covered are cleared to 0: the mean colour over the covered ones is mean /
    # coverage, and the mean alpha is already coverage times the surface's own alpha
    with np.errstate(divide="ignore", invalid="ignore"):
        rgb = np.where(coverage > 0, mean[..., :3] / np.where(coverage > 0, coverage, 1.0), 0.0)
    return np.concatenate([rgb, mean[..., 3:4]], axis=-1).astype(np.float32)


def use_transparent_blending(ctx, extra_flags: int = 0) -> None:
    """The transparent pass's state: depth test, and colour composited front to back with
    the *under* operator (premultiplied sources); ``extra_flags`` such as face culling."""
    import moderngl

    ctx.enable_only(moderngl.DEPTH_TEST | moderngl.BLEND | extra_flags)
    ctx.blend_func = moderngl.ONE_MINUS_DST_ALPHA, moderngl.ONE


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
        use_transparent_blending(ctx)
        front.use(FRONT_OPACITY_UNIT)
        draw()
        ctx.disable(moderngl.BLEND)
        ctx.copy_framebuffer(front, fbo)  # attachment 0: the opacity accumulated so far
    check_gl_error(ctx, "drawing the transparent pass")
    return tuple(read_rgba(fbo, i) for i in range(3))
