"""Block formats: what the CPU decoder (texture2ddecoder) reads from etcpak's blocks is what
the GL samples (two independent readers, level 0 and a mip level), and each format's error
on a smooth and a noisy image stays within its known bounds."""

from __future__ import annotations

import ctypes

import numpy as np
import pytest

from reliefkit.compact import blocks
from reliefkit.compact.encodings import encode
from reliefkit.gl.textures import encoded_supported, encoded_texture

CHANNELS = {"bc1": 3, "bc4": 1, "bc5": 2, "bc7": 4}
#: How far the GL's decode may be from texture2ddecoder's, in 8-bit steps: BC7 is specified
#: bit-exactly; BC1 interpolates thirds and BC4/BC5 sevenths (or fifths), which decoders
#: round differently (llvmpipe decodes RGTC at more than 8 bits, then rounds).
GL_AGREEMENT = {"bc1": 1, "bc4": 2, "bc5": 2, "bc7": 0}


def smooth(height, width, channels):
    """A gentle gradient per channel (at most 3 steps of 255 between neighbours)."""
    v, u = np.mgrid[:height, :width] / np.array([[[height]], [[width]]])
    planes = [u, v, 1 - u, 0.5 + 0.5 * u * v][:channels]
    return np.round(np.stack(planes, axis=-1) * 255).astype(np.uint8)


def noisy(rng, height, width, channels):
    return rng.integers(0, 256, (height, width, channels), dtype=np.uint8)


def read_level(ctx, tex, level: int, height: int, width: int) -> np.ndarray:
    """Level ``level`` of a 2D texture as the GL decodes it (glGetTexImage, RGBA8): moderngl
    reads only the levels it built itself."""
    address = ctx.mglo._context.load("glGetTexImage")
    get = ctypes.CFUNCTYPE(None, ctypes.c_uint, ctypes.c_int, ctypes.c_uint, ctypes.c_uint,
                           ctypes.c_void_p)(address)
    out = np.zeros((height, width, 4), np.uint8)
    tex.use(0)
    get(0x0DE1, level, 0x1908, 0x1401, out.ctypes.data)  # GL_TEXTURE_2D, GL_RGBA, UNSIGNED_BYTE
    return out


@pytest.mark.parametrize("fmt", list(CHANNELS))
def test_the_gl_samples_what_the_cpu_decoder_reads(gl, rng, fmt):
    image = noisy(rng, 22, 30, CHANNELS[fmt])  # not multiples of 4: padded blocks
    encoded = encode(image, fmt, mipmaps=True)
    assert encoded_supported(gl, encoded, "2d")
    tex = encoded_texture(gl, encoded, mipmaps=True, what=fmt)
    try:
        for level in (0, 1):
            cpu = encoded.decode(level)
            read = read_level(gl, tex, level, *cpu.shape[:2])[..., :CHANNELS[fmt]]
            diff = np.abs(read.astype(int) - cpu.astype(int)).max()
            assert diff <= GL_AGREEMENT[fmt], (fmt, level, diff)
    finally:
        tex.release()


#: The largest error per texel, in 8-bit steps, each format keeps on a smooth image (a
#: gradient whose channels vary independently: BC1 fits one colour line per block, so two
#: independent gradients cost it most) and the mean error on noise (the worst case: 16
#: unrelated values in a block).
FLAT_MAX = {"bc1": 4, "bc4": 0, "bc5": 0, "bc7": 1}  # BC1's 5:6:5 endpoints: 255 / 31 / 2
SMOOTH_MAX = {"bc1": 16, "bc4": 2, "bc5": 2, "bc7": 8}
NOISE_MEAN = {"bc1": 56, "bc4": 12, "bc5": 12, "bc7": 40}


@pytest.mark.parametrize("fmt", list(CHANNELS))
def test_each_format_keeps_its_known_error(rng, fmt):
    channels = CHANNELS[fmt]
    image = smooth(64, 64, channels)
    decoded = blocks.decode(fmt, blocks.encode(fmt, image), 64, 64)
    assert np.abs(decoded.astype(int) - image).max() <= SMOOTH_MAX[fmt]
    flat = np.full((64, 64, channels), 93, np.uint8)  # one colour: only endpoint precision
    flat_decoded = blocks.decode(fmt, blocks.encode(fmt, flat), 64, 64)
    assert np.abs(flat_decoded.astype(int) - 93).max() <= FLAT_MAX[fmt]
    noise = noisy(rng, 64, 64, channels)
    noise_decoded = blocks.decode(fmt, blocks.encode(fmt, noise), 64, 64)
    assert np.abs(noise_decoded.astype(int) - noise).mean() <= NOISE_MEAN[fmt]
    assert len(blocks.encode(fmt, image)) == 64 * 64 * blocks.FORMATS[fmt].bits_per_texel // 8


class LimitedContext:
    """A context with every format and a 64 x 64 texture limit; allocating fails the test."""

    info = {"GL_MAX_TEXTURE_SIZE": 64, "GL_MAX_ARRAY_TEXTURE_LAYERS": 2048,
            "GL_MAX_3D_TEXTURE_SIZE": 64}
    extensions = {"GL_ARB_texture_compression_bptc", "GL_EXT_texture_compression_s3tc",
                  "GL_ARB_texture_compression_rgtc"}

    def texture(self, *args, **kwargs):
        raise AssertionError("allocated a texture that should have been refused")

    texture_array = texture3d = texture


def test_an_encoded_texture_over_the_limits_is_refused_before_allocating():
    from reliefkit.errors import GPUError

    encoded = encode(np.zeros((8, 128, 4), np.uint8), "bc7")
    with pytest.raises(GPUError, match="a 128x8 texture exceeds this GPU's limit of 64x64"):
        encoded_texture(LimitedContext(), encoded, what="atlas")
