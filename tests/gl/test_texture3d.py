"""3D textures: bit-exact upload, [w, v, u] orientation as GL samples it, limits checked first."""

from __future__ import annotations

import numpy as np
import pytest

from reliefkit.errors import GPUError
from reliefkit.gl import textures
from reliefkit.gl.textures import texture3d


class FakeContext:
    """Just enough of a moderngl context for the checks; allocating fails the test."""

    def __init__(self, max_3d: int):
        self.info = {"GL_MAX_3D_TEXTURE_SIZE": max_3d}

    def texture3d(self, *args, **kwargs):
        raise AssertionError("texture3d allocated although the request should be refused")


@pytest.mark.parametrize(("dtype", "comps"), [(np.uint8, 1), (np.uint8, 3), (np.uint8, 4),
                                              (np.float32, 1), (np.float32, 2),
                                              (np.float32, 4), (np.float16, 4)])
def test_upload_reads_back_bit_exact(gl, rng, dtype, comps):
    shape = (3, 5, 7, comps)  # odd widths: rows are not 4-byte aligned
    if dtype == np.uint8:
        arr = rng.integers(0, 256, shape, dtype=np.uint8)
    else:
        arr = rng.standard_normal(shape).astype(dtype)
    tex = texture3d(gl, arr if comps > 1 else arr[..., 0], what="test volume")
    try:
        assert tex.size == (7, 5, 3)
        assert tex.components == comps
        assert tex.read() == arr.tobytes()  # GL layout is numpy C order of [w, v, u]
    finally:
        tex.release()


SAMPLE_SRC = {
    "vertex_shader": """#version 330 core
in vec2 in_pos;
void main() { gl_Position = vec4(in_pos, 0.0, 1.0); }
""",
    "fragment_shader": """#version 330 core
uniform sampler3D u_volume;
uniform vec3 u_size;  // (W, H, D)
uniform float u_layer;
out vec4 f_color;
void main() {
    vec3 p = vec3(gl_FragCoord.xy, u_layer + 0.5) / u_size;  // texel centres
    f_color = texture(u_volume, p);
}
""",
}


def _sample_layers(gl, tex, size):
    """Sample ``tex`` on a (W, H, D) grid of cell centres over [0, 1]^3: (D, H, W, 4)."""
    width, height, depth = size
    prog = gl.program(**SAMPLE_SRC)
    vbo = gl.buffer(np.array([-1, -1, 3, -1, -1, 3], np.float32).tobytes())
    vao = gl.vertex_array(prog, [(vbo, "2f", "in_pos")])
    target = gl.texture((width, height), 4, dtype="f4")
    fbo = gl.framebuffer(color_attachments=[target])
    layers = []
    try:
        fbo.use()
        tex.use(0)
        prog["u_volume"].value = 0
        prog["u_size"].value = (float(width), float(height), float(depth))
        for k in range(depth):
            fbo.clear(0.0, 0.0, 0.0, 0.0)
            prog["u_layer"].value = float(k)
            vao.render()
            data = np.frombuffer(fbo.read(components=4, dtype="f4"), np.float32)
            layers.append(data.reshape(height, width, 4))  # row 0 = gl_FragCoord.y 0.5 = v
        return np.stack(layers)
    finally:
        from reliefkit.gl.context import bind_home_framebuffer

        bind_home_framebuffer(gl)
        for obj in (fbo, target, vao, vbo, prog):
            obj.release()


def test_sampling_follows_w_v_u_indexing(gl):
    depth, height, width = 3, 4, 5
    k, j, i = np.meshgrid(np.arange(depth), np.arange(height), np.arange(width), indexing="ij")
    code = (100 * k + 10 * j + i).astype(np.float32)  # a texel knows its own index
    tex = texture3d(gl, code, what="index volume", filter="nearest")
    try:
        seen = _sample_layers(gl, tex, (width, height, depth))
    finally:
        tex.release()
    np.testing.assert_array_equal(seen[..., 0], code)


def test_linear_filter_interpolates_along_u_and_clamps(gl):
    arr = np.zeros((1, 1, 2), np.float32)
    arr[0, 0, 1] = 1.0
    tex = texture3d(gl, arr, what="ramp")
    try:
        # 4 samples across 2 texels: u = 1/8 .. 7/8, a quarter texel off the texel centres
        seen = _sample_layers(gl, tex, (4, 1, 1))[0, 0, :, 0]
    finally:
        tex.release()
    np.testing.assert_allclose(seen, [0.0, 0.25, 0.75, 1.0], atol=1 / 256)


def test_repeat_and_nearest_settings(gl):
    import moderngl

    tex = texture3d(gl, np.zeros((2, 2, 2), np.uint8), filter="nearest", repeat=True)
    try:
        assert tex.filter == (moderngl.NEAREST, moderngl.NEAREST)
        assert tex.repeat_x and tex.repeat_y and tex.repeat_z
    finally:
        tex.release()


def test_side_over_gl_limit_is_refused_before_allocating():
    ctx = FakeContext(max_3d=8)
    for shape in [(9, 4, 4), (4, 9, 4), (4, 4, 9)]:
        with pytest.raises(GPUError, match=r"limit of 8 per side; use a smaller"):
            texture3d(ctx, np.zeros(shape, np.uint8))


class _Texture:
    filter = repeat_x = repeat_y = repeat_z = None


def test_size_at_the_limit_is_passed_to_gl_as_width_height_depth():
    calls = []
    ctx = FakeContext(max_3d=8)
    ctx.error = "GL_NO_ERROR"
    ctx.texture3d = lambda *args, **kwargs: calls.append((args, kwargs)) or _Texture()
    texture3d(ctx, np.zeros((2, 4, 8, 3), np.float16))
    (size, comps, data), kwargs = calls[0]
    assert size == (8, 4, 2) and comps == 3 and len(data) == 2 * 4 * 8 * 3 * 2
    assert kwargs["dtype"] == "f2"


def test_byte_cap_is_checked_before_copying_or_allocating():
    ctx = FakeContext(max_3d=2048)
    # 16 GiB described by a broadcast view of 16 bytes: a copy would exhaust memory
    huge = np.broadcast_to(np.zeros((1, 1, 1, 4), np.float32), (1024, 1024, 1024, 4))
    with pytest.raises(GPUError, match=r"16\.0 GiB.*smaller resolution"):
        texture3d(ctx, huge)


def test_byte_cap_constant_is_used(monkeypatch):
    monkeypatch.setattr(textures, "MAX_TEXTURE3D_BYTES", 1000)
    with pytest.raises(GPUError, match="GiB"):
        texture3d(FakeContext(max_3d=64), np.zeros((8, 8, 8), np.float32))  # 2048 bytes


@pytest.mark.parametrize("array", [
    np.zeros((4, 4), np.float32),            # 2D
    np.zeros((2, 2, 2, 5), np.float32),      # too many channels
    np.zeros((2, 2, 2, 0), np.float32),      # no channels
    np.zeros((1, 2, 2, 2, 1), np.float32),   # 5D
    np.zeros((0, 4, 4), np.float32),         # empty side
])
def test_bad_shapes_are_refused(array):
    with pytest.raises(GPUError, match="3D"):
        texture3d(FakeContext(max_3d=64), array)


@pytest.mark.parametrize("dtype", [np.float64, np.int32, np.uint16, np.bool_, np.int8])
def test_bad_dtypes_are_refused(dtype):
    with pytest.raises(GPUError, match="dtype"):
        texture3d(FakeContext(max_3d=64), np.zeros((2, 2, 2), dtype))


def test_bad_filter_is_refused():
    with pytest.raises(GPUError, match="filter"):
        texture3d(FakeContext(max_3d=64), np.zeros((2, 2, 2), np.uint8), filter="cubic")
