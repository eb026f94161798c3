"""Multisampled colour (`render(..., msaa=N)`) on an analytic scene: one large triangle.

The reference is the exact area of each pixel square that the triangle covers (the square
clipped by the triangle's three edges, in window coordinates): with N samples an edge
pixel's alpha approximates it; interior pixels keep the single-sample colour, and every AOV
is the single-sample one.
"""

from __future__ import annotations

import numpy as np
import pytest
from helpers import make_relief

from reliefkit.errors import GPUError, UsageError
from reliefkit.render import render
from reliefkit.scene.camera import Camera
from reliefkit.scene.mesh import RenderMesh

W, H = 64, 48
CAMERA = Camera(eye=(0.0, 0.0, 2.0), target=(0.0, 0.0, 0.0), size=(W, H), ortho_height=1.0)
TRIANGLE = RenderMesh(  # edges at odd slopes, corners inside the image; colours vary
    positions=[[-1.1, -0.83, 0.0], [1.03, -0.41, 0.0], [-0.37, 0.89, 0.0]],
    indices=[[0, 1, 2]], normals=[[0, 0, 1]] * 3,
    colors=[[0.9, 0.2, 0.1, 1], [0.1, 0.8, 0.2, 1], [0.2, 0.3, 0.9, 1]])


def window_triangle() -> np.ndarray:
    """The triangle's corners in window coordinates (x right, y up, pixels)."""
    p = np.c_[TRIANGLE.positions, np.ones(3)] @ (CAMERA.proj @ CAMERA.view).T
    ndc = p[:, :2] / p[:, 3:4]
    return (ndc + 1) / 2 * [W, H]


def clip(polygon: list, a: np.ndarray, b: np.ndarray) -> list:
    """Sutherland-Hodgman: the part of ``polygon`` left of the directed edge a -> b."""
    def side(p):
        return (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])

    out = []
    for k, p in enumerate(polygon):
        q = polygon[(k + 1) % len(polygon)]
        sp, sq = side(p), side(q)
        if sp >= 0:
            out.append(p)
        if sp * sq < 0:
            out.append(p + (q - p) * (sp / (sp - sq)))
    return out


def area(polygon: list) -> float:
    if len(polygon) < 3:
        return 0.0
    x, y = np.array(polygon).T
    return 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))


def covered_fraction() -> np.ndarray:
    """(H, W) exact area of each pixel square inside the triangle; row 0 at the top."""
    tri = window_triangle()
    (ax, ay), (bx, by) = tri[1] - tri[0], tri[2] - tri[0]
    if ax * by - ay * bx < 0:
        tri = tri[::-1]
    out = np.zeros((H, W))
    for r in range(H):
        y = H - 1 - r
        for c in range(W):
            square = [np.array(v, float) for v in ((c, y), (c + 1, y), (c + 1, y + 1),
                                                     (c, y + 1))]
            for k in range(3):
                square = clip(square, tri[k], tri[(k + 1) % 3])
                if not square:
                    break
            out[r, c] = area(square)
    return out


@pytest.fixture(scope="module")
def samples(gl) -> int:
    return min(4, int(gl.info["GL_MAX_SAMPLES"]))


def test_edge_alpha_approximates_the_covered_area(gl, samples):
    exact = covered_fraction()
    plain = render(TRIANGLE, CAMERA)
    frame = render(TRIANGLE, CAMERA, msaa=samples)
    edge = (exact > 0) & (exact < 1)
    error = np.abs(frame.color[..., 3] - exact)
    single = np.abs(plain.color[..., 3] - exact)
    assert edge.sum() > 100
    # N samples resolve coverage in steps of 1 / N; the sample pattern adds a little more
    assert error[edge].mean() < 0.5 / samples + 0.02, error[edge].mean()
    assert error[edge].mean() < 0.5 * single[edge].mean()
    assert error.max() <= 0.75
    assert (frame.color[exact == 0] == 0).all()


def test_interior_colour_and_every_aov_are_the_single_sample_ones(gl, samples):
    exact = covered_fraction()
    plain = render(TRIANGLE, CAMERA)
    frame = render(TRIANGLE, CAMERA, msaa=samples)
    inner = exact == 1
    np.testing.assert_allclose(frame.color[inner], plain.color[inner], atol=1e-6)
    for name in ("mask", "depth", "position", "normal"):
        np.testing.assert_array_equal(getattr(frame, name), getattr(plain, name), err_msg=name)
    # edge pixels keep a straight colour near the surface's, not one darkened by coverage
    edge = (frame.color[..., 3] > 0) & plain.mask & (exact < 1)
    np.testing.assert_allclose(frame.color[edge, :3], plain.color[edge, :3], atol=0.05)


def test_relief_keeps_its_aovs_with_msaa(gl, samples):
    y, x = np.mgrid[0:32, 0:32] / 31.0
    relief = make_relief(0.3 + 0.5 * np.exp(-((x - 0.5) ** 2 + (y - 0.5) ** 2) * 8))
    camera = Camera.orbit((0, 0.4, 0), 30, 35, 3.5, size=(48, 48))
    plain = render(relief, camera, method="exact")
    frame = render(relief, camera, method="exact", msaa=samples)
    for name in ("mask", "depth", "position", "normal"):
        np.testing.assert_array_equal(getattr(frame, name), getattr(plain, name), err_msg=name)
    edge = (frame.color[..., 3] > 0) & (frame.color[..., 3] < 1)
    assert edge.any()
    inner = plain.mask & ~edge
    assert np.abs(frame.color[inner] - plain.color[inner]).max() < 0.05


def test_msaa_is_checked(gl):
    with pytest.raises(UsageError, match="msaa must be one of 1, 2, 4, 8"):
        render(TRIANGLE, CAMERA, msaa=3)
    if int(gl.info["GL_MAX_SAMPLES"]) < 8:
        with pytest.raises(GPUError, match="limit"):
            render(TRIANGLE, CAMERA, msaa=8)


def test_a_multisampled_render_leaves_no_gl_error_behind(gl):
    """The first msaa render of a process released its framebuffers while one was bound;
    moderngl rebound it when the next framebuffer was made, and the pending
    GL_INVALID_OPERATION was blamed on whatever the next command uploaded (--msaa with
    --stats or --turntable failed on every input)."""
    extra = gl.extra if isinstance(gl.extra, dict) else {}
    old_home = extra.pop("home_fbo", None)  # as in a fresh process (kept alive: it is bound)
    render(TRIANGLE, CAMERA, msaa=4)
    assert gl.error == "GL_NO_ERROR"
    assert render(TRIANGLE, CAMERA, msaa=4).mask.any()
    if old_home is not None:
        old_home.release()  # the new home is bound now
