"""Textures and render targets, created only after their size is checked against GL limits."""

from __future__ import annotations

import numpy as np

from ..colorspace import srgb_decode
from ..errors import GPUError
from .context import check_framebuffer_size, check_gl_error

GL_SRGB8_ALPHA8 = 0x8C43
MAX_TARGET_BYTES = 2 << 30  # refuse render targets above 2 GiB (RGBA32F attachments + depth)

_DTYPES = {np.dtype(np.uint8): "f1", np.dtype(np.float32): "f4", np.dtype(np.uint16): "u2",
           np.dtype(np.float16): "f2"}


def _check_2d(ctx, width: int, height: int, what: str) -> None:
    limit = int(ctx.info["GL_MAX_TEXTURE_SIZE"])
    if width < 1 or height < 1:
        raise GPUError(f"{what}: texture size must be positive, got {width}x{height}")
    if width > limit or height > limit:
        raise GPUError(
            f"{what}: a {width}x{height} texture exceeds this GPU's limit of {limit}x{limit}; "
            "use a smaller resolution"
        )


def texture2d(ctx, array: np.ndarray, *, what: str = "texture", filter: str = "linear",
              srgb: bool = False, mipmaps: bool = False, repeat: bool = False):
    """Upload an (H, W) or (H, W, C) array as a 2D texture; row 0 of the array is v = 0.

    uint8 arrays become normalised textures (sRGB-decoded when ``srgb``), float32 stay float,
    uint16 become unsigned integer textures (sample them with ``usampler2D``).
    """
    import moderngl

    arr = np.ascontiguousarray(array)
    if arr.ndim == 2:
        arr = arr[:, :, None]
    if arr.ndim != 3 or not 1 <= arr.shape[2] <= 4:
        raise GPUError(f"{what}: expected an (H, W) or (H, W, 1..4) array, got {array.shape}")
    if arr.dtype not in _DTYPES:
        raise GPUError(f"{what}: unsupported texture dtype {arr.dtype}")
    height, width, comps = arr.shape
    _check_2d(ctx, width, height, what)
    kwargs = {}
    if srgb:
        if arr.dtype != np.uint8 or comps != 4:
            raise GPUError(f"{what}: sRGB textures must be (H, W, 4) uint8")
        kwargs["internal_format"] = GL_SRGB8_ALPHA8
    tex = ctx.texture((width, height), comps, arr.tobytes(), dtype=_DTYPES[arr.dtype], **kwargs)
    integer = arr.dtype == np.uint16
    nearest = filter == "nearest" or integer
    tex.filter = (moderngl.NEAREST, moderngl.NEAREST) if nearest else (
        (moderngl.LINEAR_MIPMAP_LINEAR if mipmaps else moderngl.LINEAR), moderngl.LINEAR)
    if mipmaps and not nearest:
        tex.build_mipmaps()
    tex.repeat_x = tex.repeat_y = repeat
    check_gl_error(ctx, f"creating {what} ({width}x{height}x{comps} {arr.dtype})")
    return tex


def mip_chain(ctx, width: int, height: int, *, what: str = "texture"):
    """An R32F texture with its full mip chain allocated (contents undefined), sampled with
    ``texelFetch(tex, p, level)``; the size is checked before anything is allocated."""
    import moderngl

    _check_2d(ctx, width, height, what)
    tex = ctx.texture((width, height), 1, dtype="f4")
    try:
        tex.build_mipmaps()  # allocates the levels
        tex.filter = (moderngl.NEAREST_MIPMAP_NEAREST, moderngl.NEAREST)
        tex.repeat_x = tex.repeat_y = False
        check_gl_error(ctx, f"creating {what} ({width}x{height} with its mip levels)")
    except BaseException:
        tex.release()
        raise
    return tex


def texture_levels(ctx, levels: list, *, what: str = "texture"):
    """Upload a full mip chain of float32 (H, W) arrays, each half the size of the one
    before down to 1 x 1 (a max pyramid, say), into one R32F texture (`mip_chain`)."""
    arrays = [np.ascontiguousarray(a, dtype=np.float32) for a in levels]
    if not arrays or any(a.ndim != 2 for a in arrays):
        raise GPUError(f"{what}: expected a list of (H, W) levels")
    height, width = arrays[0].shape
    for k, a in enumerate(arrays):
        expected = (max(height >> k, 1), max(width >> k, 1))
        if a.shape != expected:
            raise GPUError(f"{what}: level {k} must be {expected}, got {a.shape}")
    if arrays[-1].shape != (1, 1):
        raise GPUError(f"{what}: the chain must end at 1 x 1, got {arrays[-1].shape}")
    tex = mip_chain(ctx, width, height, what=what)
    try:
        for k, a in enumerate(arrays):
            tex.write(a.tobytes(), level=k)
        check_gl_error(ctx, f"uploading {what} ({width}x{height}, {len(arrays)} levels)")
    except BaseException:
        tex.release()
        raise
    return tex


def render_target(ctx, width: int, height: int, color_attachments: int):
    """A framebuffer of ``color_attachments`` RGBA32F textures plus a float depth texture."""
    check_framebuffer_size(ctx, width, height)
    limit = int(ctx.info["GL_MAX_COLOR_ATTACHMENTS"])
    needed = width * height * (16 * color_attachments + 4)
    if needed > MAX_TARGET_BYTES:
        raise GPUError(f"a {width}x{height} image with its AOVs needs {needed / 2**30:.1f} GiB "
                       f"of render targets (limit {MAX_TARGET_BYTES / 2**30:.0f} GiB); "
                       "render a smaller size")
    if color_attachments > limit:
        raise GPUError(f"{color_attachments} colour attachments exceed this GPU's limit of {limit}")
    colors = [ctx.texture((width, height), 4, dtype="f4") for _ in range(color_attachments)]
    depth = ctx.depth_texture((width, height))
    fbo = ctx.framebuffer(color_attachments=colors, depth_attachment=depth)
    check_gl_error(ctx, f"creating a {width}x{height} render target")
    return fbo


def read_rgba(fbo, attachment: int, *, top_row_first: bool = True) -> np.ndarray:
    """Read one RGBA32F attachment as an (H, W, 4) array with row 0 at the top (a picture),
    or with ``top_row_first=False`` row 0 at GL's y = 0 (a bake's texture rows)."""
    width, height = fbo.size
    data = fbo.read(attachment=attachment, components=4, dtype="f4")
    image = np.frombuffer(data, np.float32).reshape(height, width, 4)
    return image[::-1].copy() if top_row_first else image.copy()


def read_depth(fbo, *, top_row_first: bool = True) -> np.ndarray:
    """Read the depth attachment as an (H, W) float32 array with row 0 at the top, or with
    ``top_row_first=False`` at GL's y = 0. (From the texture itself: reading it through the
    framebuffer leaves GL's read buffer at none, and Mesa crashes on a later blit.)"""
    width, height = fbo.size
    data = fbo.depth_attachment.read()
    image = np.frombuffer(data, np.float32).reshape(height, width)
    return image[::-1].copy() if top_row_first else image.copy()


MAX_TEXTURE3D_BYTES = 2 << 30  # refuse 3D textures above 2 GiB (checked before allocating)
_DTYPES_3D = {np.dtype(np.uint8): "f1", np.dtype(np.float32): "f4", np.dtype(np.float16): "f2"}


def check_3d_size(ctx, width: int, height: int, depth: int, what: str,
                  nbytes: int | None = None) -> None:
    """Refuse a 3D texture over GL_MAX_3D_TEXTURE_SIZE or the byte cap, before allocating."""
    if min(width, height, depth) < 1:
        raise GPUError(f"{what}: 3D texture size must be positive, got {width}x{height}x{depth}")
    limit = int(ctx.info["GL_MAX_3D_TEXTURE_SIZE"])
    if max(width, height, depth) > limit:
        raise GPUError(f"{what}: a {width}x{height}x{depth} 3D texture exceeds this GPU's limit "
                       f"of {limit} per side; use a smaller resolution")
    if nbytes is not None and nbytes > MAX_TEXTURE3D_BYTES:
        raise GPUError(f"{what}: a {width}x{height}x{depth} 3D texture needs "
                       f"{nbytes / 2**30:.1f} GiB (limit {MAX_TEXTURE3D_BYTES / 2**30:.0f} GiB); "
                       "use a smaller resolution or fewer channels")


def _stacked(array, filter: str, what: str, noun: str, shape: str, dtypes) -> np.ndarray:
    """A stack of 2D images as (N, H, W, C), checked: filter name, shape, dtype."""
    if filter not in ("linear", "nearest"):
        raise GPUError(f"{what}: filter must be 'linear' or 'nearest', got {filter!r}")
    arr = np.asarray(array)
    if arr.ndim == 3:
        arr = arr[..., None]
    if arr.ndim != 4 or not 1 <= arr.shape[3] <= 4:
        raise GPUError(f"{what}: {noun} needs an array of shape {shape} or {shape[:-1]}, "
                       f"1..4), got {np.shape(array)}")
    if arr.dtype not in dtypes:
        raise GPUError(f"{what}: unsupported {noun.split(' ', 1)[1]} dtype {arr.dtype} "
                       "(use uint8, float16 or float32)")
    return arr


def texture3d(ctx, array: np.ndarray, *, what: str = "texture", filter: str = "linear",
              repeat: bool = False):
    """Upload a (D, H, W) or (D, H, W, C<=4) array indexed [w, v, u] as a 3D texture.

    numpy C order matches GL's layout: the last axis is the texture's width (u), then its
    height (v), then its depth (w), so ``array[k, j, i]`` is the texel sampled at
    ``((i + 0.5) / W, (j + 0.5) / H, (k + 0.5) / D)``. uint8 arrays become normalised
    textures, float32 and float16 stay float. Sizes are checked before anything is allocated.
    """
    import moderngl

    arr = _stacked(array, filter, what, "a 3D texture", "(D, H, W)", _DTYPES_3D)
    depth, height, width, comps = (int(s) for s in arr.shape)
    check_3d_size(ctx, width, height, depth, what, nbytes=arr.size * arr.dtype.itemsize)
    data = np.ascontiguousarray(arr).tobytes()
    tex = ctx.texture3d((width, height, depth), comps, data, dtype=_DTYPES_3D[arr.dtype])
    try:
        mode = moderngl.NEAREST if filter == "nearest" else moderngl.LINEAR
        tex.filter = (mode, mode)
        tex.repeat_x = tex.repeat_y = tex.repeat_z = repeat
        check_gl_error(ctx, f"creating {what} ({width}x{height}x{depth}x{comps} {arr.dtype})")
    except BaseException:
        tex.release()
        raise
    return tex


MAX_TEXTURE_ARRAY_BYTES = 2 << 30  # refuse texture arrays above 2 GiB (checked before allocating)
_DTYPES_ARRAY = {np.dtype(np.uint8): "f1", np.dtype(np.float32): "f4",
                 np.dtype(np.float16): "f2"}


def check_array_size(ctx, width: int, height: int, layers: int, what: str,
                     nbytes: int | None = None) -> None:
    """Refuse a texture array over GL_MAX_TEXTURE_SIZE, GL_MAX_ARRAY_TEXTURE_LAYERS or the
    byte cap, before anything is allocated."""
    if min(width, height, layers) < 1:
        raise GPUError(f"{what}: texture array size must be positive, got "
                       f"{layers} x {width}x{height}")
    _check_2d(ctx, width, height, what)
    limit = int(ctx.info["GL_MAX_ARRAY_TEXTURE_LAYERS"])
    if layers > limit:
        raise GPUError(f"{what}: {layers} texture array layers exceed this GPU's limit of "
                       f"{limit}; use fewer atlas pages (a larger page or texel size)")
    if nbytes is not None and nbytes > MAX_TEXTURE_ARRAY_BYTES:
        raise GPUError(f"{what}: a {layers} x {width}x{height} texture array needs "
                       f"{nbytes / 2**30:.1f} GiB (limit {MAX_TEXTURE_ARRAY_BYTES / 2**30:.0f} "
                       "GiB); use a smaller resolution")


def texture_array(ctx, array: np.ndarray, *, what: str = "texture", srgb: bool = False,
                  mipmaps: bool = False, filter: str = "linear"):
    """Upload an (L, H, W) or (L, H, W, C<=4) array as a 2D texture array (``sampler2DArray``).

    ``array[k, j, i]`` is the texel of layer k sampled at ``((i + 0.5) / W, (j + 0.5) / H)``:
    row 0 of a layer is v = 0, as in `texture2d`. uint8 arrays become normalised textures,
    float32 and float16 stay float. Sizes are checked before anything is allocated.

    ``srgb`` takes (L, H, W, 4) uint8 sRGB colour with linear alpha and samples linear colour,
    like `texture2d`'s GL_SRGB8_ALPHA8. moderngl cannot give a texture array an internal
    format, so the texels are decoded on the CPU (a 256-entry table: exact) into float16;
    filtering and mipmaps then average linear values as an sRGB texture would, at twice
    the memory.
    """
    import moderngl

    arr = _stacked(array, filter, what, "a texture array", "(L, H, W)", _DTYPES_ARRAY)
    if srgb and (arr.dtype != np.uint8 or arr.shape[3] != 4):
        raise GPUError(f"{what}: sRGB texture arrays must be (L, H, W, 4) uint8")
    layers, height, width, comps = (int(s) for s in arr.shape)
    itemsize = 2 if srgb else arr.dtype.itemsize
    check_array_size(ctx, width, height, layers, what, nbytes=arr.size * itemsize)
    if srgb:
        arr = _srgb_to_linear_half(arr)
    # the array itself (buffer protocol): a bytes copy would double the host peak
    tex = ctx.texture_array((width, height, layers), comps, np.ascontiguousarray(arr),
                            dtype=_DTYPES_ARRAY[arr.dtype])
    try:
        if filter == "nearest":
            tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
        else:
            tex.filter = (moderngl.LINEAR_MIPMAP_LINEAR if mipmaps else moderngl.LINEAR,
                          moderngl.LINEAR)
            if mipmaps:
                tex.build_mipmaps()
        tex.repeat_x = tex.repeat_y = False
        check_gl_error(ctx, f"creating {what} ({layers} x {width}x{height}x{comps} "
                            f"{np.asarray(array).dtype})")
    except BaseException:
        tex.release()
        raise
    return tex


def _srgb_to_linear_half(rgba8: np.ndarray) -> np.ndarray:
    """(..., 4) uint8 sRGB colour + linear alpha -> float16 linear colour + alpha."""
    levels = np.arange(256) / 255.0
    colour_table = srgb_decode(levels).astype(np.float16)
    out = np.empty(rgba8.shape, np.float16)
    out[..., :3] = colour_table[rgba8[..., :3]]
    out[..., 3] = levels.astype(np.float16)[rgba8[..., 3]]
    return out


# -- encoded textures (reliefkit.compact) ---------------------------------------------------

GL_TEXTURE_2D, GL_TEXTURE_3D, GL_TEXTURE_2D_ARRAY = 0x0DE1, 0x806F, 0x8C1A
GL_TEXTURE_BASE_LEVEL, GL_TEXTURE_MAX_LEVEL = 0x813C, 0x813D
_GL_TARGETS = {"2d": GL_TEXTURE_2D, "3d": GL_TEXTURE_3D, "2d_array": GL_TEXTURE_2D_ARRAY}
#: Block format -> (GL internal format, its sRGB variant or None, the extension naming it,
#: the targets GL allows it on: S3TC and RGTC are 2D-only, BPTC also takes 3D textures).
BLOCK_FORMATS = {
    "bc1": (0x83F1, 0x8C4D, "GL_EXT_texture_compression_s3tc", ("2d", "2d_array")),
    "bc4": (0x8DBB, None, "GL_ARB_texture_compression_rgtc", ("2d", "2d_array")),
    "bc5": (0x8DBD, None, "GL_ARB_texture_compression_rgtc", ("2d", "2d_array")),
    "bc7": (0x8E8C, 0x8E8D, "GL_ARB_texture_compression_bptc", ("2d", "2d_array", "3d")),
}
_QUANTIZED_DTYPES = {"u8": "nu1", "u16": "nu2"}


def encoded_supported(ctx, encoded, target: str, srgb: bool = False) -> bool:
    """Whether this GL samples ``encoded`` on ``target`` as it is (else: upload the decoded
    array). Quantized images are plain normalized textures, 2D or 2D arrays."""
    if encoded.format in _QUANTIZED_DTYPES:
        return target in ("2d", "2d_array") and not srgb
    linear, srgb_format, extension, targets = BLOCK_FORMATS[encoded.format]
    return (target in targets and extension in ctx.extensions
            and (srgb_format is not None or not srgb))


def check_encoded_size(ctx, encoded, target: str, what: str) -> None:
    """Refuse an encoded texture over the GL limits (its bytes as uploaded), before any
    allocation."""
    height, width = encoded.size
    if target == "2d":
        _check_2d(ctx, width, height, what)
    elif target == "3d":
        check_3d_size(ctx, width, height, encoded.layers, what, nbytes=encoded.nbytes)
    else:
        check_array_size(ctx, width, height, encoded.layers, what, nbytes=encoded.nbytes)


def encoded_texture(ctx, encoded, *, target: str = "2d", what: str = "texture",
                    filter: str = "linear", srgb: bool = False, mipmaps: bool = False,
                    repeat: bool = False):
    """Upload a `reliefkit.compact.encodings.EncodedImage` as it is: block formats through
    glCompressedTexImage (moderngl has no compressed upload: it makes the texture object,
    whose levels are then redefined compressed), one call per mip level; ``u8``/``u16`` as
    normalized textures (level 0 only). ``mipmaps``: every level of a block encoding (they
    are encoded per level: the GL cannot build them). Sizes are checked before anything is
    allocated."""
    import moderngl

    if not encoded_supported(ctx, encoded, target, srgb):
        raise GPUError(f"{what}: this GL cannot sample {encoded.format} on a {target} texture")
    check_encoded_size(ctx, encoded, target, what)
    height, width = encoded.size
    layers, comps = encoded.layers, encoded.channels
    size = (width, height) if target == "2d" else (width, height, layers)
    make = {"2d": ctx.texture, "3d": ctx.texture3d, "2d_array": ctx.texture_array}[target]
    quantized = _QUANTIZED_DTYPES.get(encoded.format)
    levels = encoded.levels if mipmaps and not quantized else encoded.levels[:1]
    if quantized:
        tex = make(size, comps, np.ascontiguousarray(levels[0]), dtype=quantized)
    else:
        tex = make(size, 4 if comps == 3 else comps, None, dtype="f1")
    try:
        if not quantized:
            _compressed_levels(ctx, tex.glo, encoded, target, srgb, levels)
        nearest = filter == "nearest"
        minify = moderngl.NEAREST if nearest else (
            moderngl.LINEAR_MIPMAP_LINEAR if len(levels) > 1 else moderngl.LINEAR)
        tex.filter = (minify, moderngl.NEAREST if nearest else moderngl.LINEAR)
        tex.repeat_x = tex.repeat_y = repeat
        check_gl_error(ctx, f"creating {what} ({layers} x {width}x{height}, "
                            f"{encoded.format}, {len(levels)} levels)")
    except BaseException:
        tex.release()
        raise
    return tex


def _compressed_levels(ctx, glo: int, encoded, target: str, srgb: bool, levels) -> None:
    """Redefine texture ``glo``'s levels as ``levels`` (compressed bytes, level 0 first)."""
    from .raw import raw_gl

    gl = raw_gl(ctx)
    linear, srgb_format, _, _ = BLOCK_FORMATS[encoded.format]
    internal = srgb_format if srgb else linear
    gl_target = _GL_TARGETS[target]
    height, width = encoded.size
    gl.BindTexture(gl_target, glo)
    try:
        for k, data in enumerate(levels):
            h, w = max(height >> k, 1), max(width >> k, 1)
            buffer = np.ascontiguousarray(data).ctypes.data
            if target == "2d":
                gl.CompressedTexImage2D(gl_target, k, internal, w, h, 0, data.size, buffer)
            else:
                gl.CompressedTexImage3D(gl_target, k, internal, w, h, encoded.layers, 0,
                                        data.size, buffer)
        gl.TexParameteri(gl_target, GL_TEXTURE_BASE_LEVEL, 0)
        gl.TexParameteri(gl_target, GL_TEXTURE_MAX_LEVEL, len(levels) - 1)
    finally:
        gl.BindTexture(gl_target, 0)
