"""`texture_array`: sizes checked against the GPU's limits before allocating, sRGB decoded."""

from __future__ import annotations

import numpy as np
import pytest

from reliefkit.colorspace import srgb_decode
from reliefkit.errors import GPUError
from reliefkit.gl import textures
from reliefkit.gl.textures import texture_array


class LimitedContext:
    """A context reporting ``limits``; allocating anything is a test failure."""

    def __init__(self, **limits):
        self.info = {"GL_MAX_TEXTURE_SIZE": 16384, "GL_MAX_ARRAY_TEXTURE_LAYERS": 2048} | limits

    def texture_array(self, *args, **kwargs):
        raise AssertionError("allocated a texture array that should have been refused")


@pytest.mark.parametrize("shape, limits, match", [
    ((5, 8, 8, 4), {"GL_MAX_ARRAY_TEXTURE_LAYERS": 4},
     r"5 texture array layers exceed this GPU's limit of 4"),
    ((1, 8, 32, 4), {"GL_MAX_TEXTURE_SIZE": 16}, r"a 32x8 texture exceeds .* limit of 16x16"),
    ((1, 32, 8, 4), {"GL_MAX_TEXTURE_SIZE": 16}, r"a 8x32 texture exceeds .* limit of 16x16"),
])
def test_sizes_beyond_the_limits_are_refused_before_allocating(shape, limits, match):
    with pytest.raises(GPUError, match=match):
        texture_array(LimitedContext(**limits), np.zeros(shape, np.uint8), what="atlas")


def test_the_byte_cap_counts_what_is_uploaded(monkeypatch):
    """sRGB arrays are uploaded as float16: twice their uint8 bytes."""
    rgba = np.zeros((2, 16, 16, 4), np.uint8)
    monkeypatch.setattr(textures, "MAX_TEXTURE_ARRAY_BYTES", rgba.nbytes)
    with pytest.raises(GPUError, match=r"atlas: a 2 x 16x16 texture array needs .* GiB"):
        texture_array(LimitedContext(), rgba, what="atlas", srgb=True)


@pytest.mark.parametrize("array, match", [
    (np.zeros((4, 4, 4, 5), np.uint8), "needs an array of shape \\(L, H, W\\)"),
    (np.zeros((4, 4), np.uint8), "needs an array of shape \\(L, H, W\\)"),
    (np.zeros((1, 4, 4, 4), np.int64), "unsupported texture array dtype"),
    (np.zeros((1, 4, 4, 3), np.uint8), "sRGB texture arrays must be"),
    (np.zeros((0, 4, 4, 4), np.uint8), "size must be positive"),
])
def test_bad_arrays_are_refused(array, match):
    with pytest.raises(GPUError, match=match):
        texture_array(LimitedContext(), array, srgb=array.ndim == 4 and array.shape[3] == 3)


def test_srgb_layers_read_back_linear_in_layer_row_order(gl):
    rng = np.random.default_rng(1)
    rgba = rng.integers(0, 256, (3, 4, 8, 4), dtype=np.uint8)
    tex = texture_array(gl, rgba, what="atlas", srgb=True, mipmaps=True)
    try:
        back = np.frombuffer(tex.read(), np.float16).reshape(3, 4, 8, 4).astype(np.float64)
    finally:
        tex.release()
    assert np.abs(back[..., :3] - srgb_decode(rgba[..., :3] / 255.0)).max() < 1e-3
    assert np.abs(back[..., 3] - rgba[..., 3] / 255.0).max() < 1e-3
