"""The maximum mipmap: every node bounds the bilinear surface over the texels it covers."""

import numpy as np
import pytest

from reliefkit.gl.textures import texture_levels
from reliefkit.reference.heightfield import surface_height
from reliefkit.techniques.relief.maxmip import max_pyramid


def test_nodes_bound_the_bilinear_surface():
    rng = np.random.default_rng(3)
    h = rng.random((13, 20)).astype(np.float32)  # not a power of two: padded
    levels = max_pyramid(h)
    assert levels[0].shape == (32, 32) and levels[-1].shape == (1, 1)
    assert [lv.shape[0] for lv in levels] == [32, 16, 8, 4, 2, 1]
    # dense samples of the exact surface inside each texel square stay under level 0
    xs = rng.uniform(0, 20, 4000)
    ys = rng.uniform(0, 13, 4000)
    s = surface_height(h, xs, ys)
    node0 = levels[0][ys.astype(int), xs.astype(int)]
    assert (s <= node0 + 1e-6).all()
    for k, lv in enumerate(levels):
        size = 1 << k
        assert (s <= lv[(ys // size).astype(int), (xs // size).astype(int)] + 1e-6).all()
    # and tightly: the 3x3 maximum is reached by the surface at the texel centre or a
    # neighbour's, so a node is never above every height around it
    assert levels[0][:13, :20].max() == h.max() and levels[-1][0, 0] == h.max()
    assert (levels[0][13:, :] == 0).all() and (levels[0][:, 20:] == 0).all()


def test_levels_upload_as_one_mipmapped_texture(gl):
    levels = max_pyramid(np.random.default_rng(0).random((8, 8)).astype(np.float32))
    tex = texture_levels(gl, levels, what="test pyramid")
    try:
        for k, lv in enumerate(levels):
            got = np.frombuffer(tex.read(level=k), np.float32).reshape(lv.shape)
            assert np.array_equal(got, lv)
    finally:
        tex.release()
    from reliefkit.errors import GPUError

    with pytest.raises(GPUError, match="level 1"):
        texture_levels(gl, [levels[0], levels[0]], what="bad")

