"""GL platform: capability probe, limit checks before allocation, error checks, timers,
baking and drawing on a given context."""

import subprocess
import sys

import numpy as np
import pytest

from reliefkit.errors import GPUError
from reliefkit.gl.context import check_framebuffer_size, check_gl_error, gl_info
from reliefkit.gl.textures import texture2d
from reliefkit.gl.timing import gpu_times_ms


def test_gl_info_reports_renderer_and_limits(gl):
    info = gl_info(gl)
    assert info["renderer"] and info["version_code"] >= 430
    assert info["max_texture_size"] >= 2048 and info["max_3d_texture_size"] >= 256


def test_texture_over_limit_is_refused_before_upload(gl):
    limit = int(gl.info["GL_MAX_TEXTURE_SIZE"])
    with pytest.raises(GPUError, match=f"exceeds this GPU's limit of {limit}x{limit}"):
        texture2d(gl, np.zeros((1, limit + 1), np.uint8), what="height")
    check_gl_error(gl, "after a refused texture")  # nothing reached the driver


def test_texture_round_trip_rows_are_v(gl):
    data = np.arange(12, dtype=np.float32).reshape(3, 4)
    tex = texture2d(gl, data, filter="nearest")
    back = np.frombuffer(tex.read(), np.float32).reshape(3, 4)
    np.testing.assert_array_equal(back, data)  # row 0 of the array is row 0 of GL (v = 0)
    tex.release()


def test_framebuffer_size_checks(gl):
    limit = int(gl.info["GL_MAX_RENDERBUFFER_SIZE"])
    with pytest.raises(GPUError, match="exceeds"):
        check_framebuffer_size(gl, limit + 1, 8)
    with pytest.raises(GPUError, match="positive"):
        check_framebuffer_size(gl, 0, 8)


def test_gl_errors_are_raised_and_home_framebuffer_avoids_them(gl):
    from reliefkit.gl.context import bind_home_framebuffer

    first = gl.simple_framebuffer((4, 4))
    first.use()
    first.release()  # moderngl rebinds this deleted framebuffer when it makes the next one
    gl.simple_framebuffer((4, 4)).release()
    with pytest.raises(GPUError, match="GL_INVALID_OPERATION while testing"):
        check_gl_error(gl, "testing")
    bind_home_framebuffer(gl)  # recover: bind a live framebuffer again
    gl.error  # noqa: B018 - reading the flag clears it
    second = gl.simple_framebuffer((4, 4))
    second.use()
    bind_home_framebuffer(gl)
    second.release()
    gl.simple_framebuffer((4, 4)).release()
    check_gl_error(gl, "with the home framebuffer bound")


def test_timer_reports_positive_times(gl):
    fbo = gl.simple_framebuffer((8, 8))
    fbo.use()
    (timing,) = gpu_times_ms(gl, [lambda: fbo.clear(1.0, 0.0, 0.0, 1.0)], repeats=3)
    assert timing["repeats"] == 3 and timing["wall_ms"] > 0 and timing["gpu_ms"] >= 0


def test_oversized_render_target_is_refused_before_allocation(gl):
    from reliefkit.gl.textures import render_target

    with pytest.raises(GPUError, match="GiB of render targets"):
        render_target(gl, 16000, 16000, 3)


OWN_CONTEXT = """
import sys
import numpy as np
from reliefkit.builtins import bake, render
from reliefkit.gl.context import create_context, has_context
from reliefkit.io.meshes import load_mesh
from reliefkit.io.rk import rk_bytes
from reliefkit.scene.camera import Camera

KINDS = {"relief": {"depth_res": 16}, "octahedral-impostor": {"grid": 4, "atlas_res": 64},
         "depth-object": {"res": 16}, "dmbbc": {"texel_size": 0.1}}  # Scene, voxelize too
mesh = load_mesh(sys.argv[1])
camera = Camera.orbit(mesh.center, 30.0, 20.0, 3.0, size=(48, 48))
own = create_context()
baked = {kind: bake(mesh, kind, ctx=own, **p) for kind, p in KINDS.items()}
drawn = [render(rep, camera, ctx=own).color for rep in (mesh, baked["relief"])]
assert not has_context(), "bake(ctx=) or render(ctx=) made the process-wide context"
for kind, p in KINDS.items():  # on the process-wide context now: bit for bit the same
    assert rk_bytes(bake(mesh, kind, **p)) == rk_bytes(baked[kind]), kind
assert has_context()
for rep, color in zip((mesh, baked["relief"]), drawn):
    assert np.array_equal(render(rep, camera).color, color)
later = create_context()  # made while the process-wide one is in force: that one stays current
assert rk_bytes(bake(mesh, "relief", **KINDS["relief"])) == rk_bytes(baked["relief"])
assert rk_bytes(bake(mesh, "relief", ctx=later, **KINDS["relief"])) == rk_bytes(baked["relief"])
print("ok")
"""


def test_a_bake_and_a_render_run_on_the_context_they_are_given(gl, tmp_path):
    """``bake(ctx=)`` and ``render(ctx=)`` never make the process-wide context and give what
    it gives, bit for bit (the same llvmpipe); a fresh interpreter: none exists there yet."""
    from helpers import write_tetrahedron

    mesh = write_tetrahedron(tmp_path / "t.obj")
    out = subprocess.run([sys.executable, "-c", OWN_CONTEXT, str(mesh)], capture_output=True,
                         text=True, timeout=300)
    assert out.returncode == 0 and out.stdout.strip() == "ok", out.stderr[-2000:]


def test_using_is_nestable_and_restored_on_error(gl):
    """Inside `using(ctx)` get_context() is ctx and it is current (a texture made through
    get_context() belongs to it); on exit, on error too, the context before is in force."""
    from reliefkit.gl.context import create_context, get_context, using

    first, second = create_context(), create_context()
    assert get_context() is gl
    with using(first):
        assert get_context() is first
        with pytest.raises(RuntimeError), using(second):
            assert get_context() is second
            raise RuntimeError
        assert get_context() is first
        check_gl_error(first, "after the inner context")
    assert get_context() is gl
    texture2d(get_context(), np.zeros((2, 2), np.uint8), what="t").release()
    check_gl_error(gl, "back on the process-wide context")
    for ctx in (first, second):
        ctx.release()
