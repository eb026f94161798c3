"""The maximum mipmap of a heightfield (Tevs, Ihrke & Seidel 2008) for the `maxmip` method.

Level 0 holds, per texel square [i, i+1] x [j, j+1] (texel coordinates), the largest height
the bilinear surface reaches over it: the surface there is made of the four bilinear cells
that meet at the texel's centre, whose corners are the texel and its eight neighbours
(clamped at the border), so the 3 x 3 maximum bounds it. The field is padded with zeros
(empty) to a power-of-two square; each further level takes the maximum of 2 x 2 nodes, up to
one node over everything. A ray that stays above a node's maximum cannot hit anything under
it, which is what the traversal in shaders/include/intersect.glsl skips.

`max_pyramid` builds it on the CPU; `max_pyramid_texture` builds it on the GPU from the
height texture already there (shaders/maxmip_build.glsl, one compute pass per level), as
Tevs et al. do for dynamic heightfields, and falls back to the CPU below OpenGL 4.3.
"""

from __future__ import annotations

import numpy as np

from ...gl.context import check_gl_error
from ...gl.shaders import program
from ...gl.textures import mip_chain, texture_levels

BUILD_PROGRAM = "relief:maxmip_build.glsl"
GROUP = 8  # the compute pass's work group is GROUP x GROUP nodes


def max_pyramid(height: np.ndarray) -> list[np.ndarray]:
    """[level 0 (P, P), ..., (1, 1)] float32, P the power of two >= the field's sides."""
    from scipy.ndimage import maximum_filter  # scipy: slow to import

    h = np.asarray(height, dtype=np.float32)
    base = maximum_filter(h, size=3, mode="nearest")
    side = pyramid_side(h.shape)
    level = np.zeros((side, side), np.float32)
    level[:h.shape[0], :h.shape[1]] = base
    levels = [level]
    while level.shape[0] > 1:
        n = level.shape[0] // 2
        level = level.reshape(n, 2, n, 2).max(axis=(1, 3))
        levels.append(level)
    return levels


def pyramid_side(shape) -> int:
    """Side of the pyramid's level 0: the power of two >= the field's sides."""
    return 1 << int(np.ceil(np.log2(max(shape))))


def max_pyramid_texture(ctx, height: np.ndarray, height_texture):
    """The max pyramid of ``height`` as one R32F mip-chain texture, built on the GPU from
    ``height_texture`` (its R32F upload) where compute shaders exist (OpenGL >= 4.3), on
    the CPU otherwise. Returns the texture and the index of its 1 x 1 level."""
    hh, ww = np.shape(height)
    side = pyramid_side((hh, ww))
    top = side.bit_length() - 1
    if ctx.version_code < 430:
        return texture_levels(ctx, max_pyramid(height), what="max pyramid"), top
    tex = mip_chain(ctx, side, side, what="max pyramid")
    try:
        base = program(ctx, BUILD_PROGRAM, {"FROM_HEIGHT": True})
        halve = program(ctx, BUILD_PROGRAM)
        height_texture.use(0)
        base["u_height"] = 0
        base["u_hf_size"] = (ww, hh)
        for level in range(top + 1):
            n = side >> level
            prog = base if level == 0 else halve
            prog["u_dst_size"] = (n, n)
            if level > 0:
                tex.bind_to_image(0, read=True, write=False, level=level - 1)
            tex.bind_to_image(1, read=False, write=True, level=level)
            groups = (n + GROUP - 1) // GROUP
            prog.run(groups, groups)
            ctx.memory_barrier()  # the next level (and the draw) reads this one
        check_gl_error(ctx, f"building the max pyramid of a {ww}x{hh} field")
    except BaseException:
        tex.release()
        raise
    return tex, top
