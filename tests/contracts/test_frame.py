"""Every registered drawable (and the toy technique's) renders a Frame that meets the Frame
contract of docs/architecture.md, and its instrumented pass draws exactly the pixels of the
plain one."""

from __future__ import annotations

import numpy as np
import pytest
from helpers import sample, sample_ids, technique_samples

from reliefkit.render import render
from reliefkit.render.frame import window_depth
from reliefkit.scene.views import orbit_bounds

pytestmark = pytest.mark.usefixtures("toy_registered")

SAMPLES = technique_samples()
IDS = sample_ids(SAMPLES)
VIEWS = [(30.0, 35.0, 2.4), (200.0, 10.0, 2.0)]



def check_frame(frame, camera) -> None:
    """The Frame contract: shapes, dtypes, row order, mask vs AOVs, depth vs position."""
    w, h = camera.size
    assert frame.color.shape == (h, w, 4) and frame.color.dtype == np.float32
    assert frame.mask.shape == (h, w) and frame.mask.dtype == bool
    assert frame.depth.shape == (h, w) and frame.depth.dtype == np.float32
    assert frame.position.shape == (h, w, 3) and frame.normal.shape == (h, w, 3)
    np.testing.assert_array_equal(frame.view, camera.view)
    np.testing.assert_array_equal(frame.proj, camera.proj)
    assert tuple(frame.viewport) == (0, 0, w, h)
    assert np.isfinite(frame.color).all()
    assert (frame.color >= 0).all() and (frame.color[..., 3] <= 1 + 1e-6).all()
    alpha = frame.color[..., 3]
    assert (alpha[~frame.mask] == 0).all(), "colour outside the mask"
    assert (alpha[frame.mask] > 0).all(), "a covered pixel with zero alpha"
    has_point = np.isfinite(frame.position).all(axis=-1)
    assert not has_point[~frame.mask].any(), "a position where nothing was drawn"
    assert (frame.depth >= 0).all() and (frame.depth <= 1).all()
    assert (frame.depth[~frame.mask] == 1).all()
    # in float64: a float32 component near 1e-23 underflows when squared
    lengths = np.linalg.norm(frame.normal[has_point].astype(np.float64), axis=-1)
    np.testing.assert_allclose(lengths, 1.0, atol=1e-3)
    expected = window_depth(frame.position, frame.view, frame.proj, frame.depth)
    np.testing.assert_allclose(frame.depth[has_point], expected[has_point], atol=2e-4)
    assert frame.stats["covered"] == int(frame.mask.sum())


@pytest.mark.parametrize("view", VIEWS, ids=["above", "grazing"])
@pytest.mark.parametrize("tech_kind", SAMPLES, ids=IDS)
def test_render_meets_the_frame_contract(gl, tech_kind, view):
    rep = sample(*tech_kind)
    camera = orbit_bounds(rep.bounds, *view, size=(64, 48))
    frame = render(rep, camera)
    assert frame.mask.sum() > 50, "the sample should be visible from this view"
    check_frame(frame, camera)


@pytest.mark.parametrize("view", VIEWS, ids=["above", "grazing"])
@pytest.mark.parametrize("tech_kind", SAMPLES, ids=IDS)
def test_instrumented_pass_draws_the_plain_pixels(gl, tech_kind, view):
    """Counting iterations must not change the picture (misses must not hide hits)."""
    rep = sample(*tech_kind)
    camera = orbit_bounds(rep.bounds, *view, size=(64, 48))
    plain = render(rep, camera)
    counted = render(rep, camera, count_iterations=True)
    np.testing.assert_array_equal(counted.mask, plain.mask)
    np.testing.assert_array_equal(counted.color, plain.color)
    np.testing.assert_array_equal(counted.depth, plain.depth)
    check_frame(counted, camera)
    if "fragments" in counted.stats:
        assert counted.stats["fragments"] >= int(plain.mask.sum()) > 0
        its = counted.extra["iterations"]
        assert np.isfinite(its[plain.mask]).all()
        assert counted.stats["iterations_max"] >= counted.stats["iterations_mean"] >= 0


@pytest.mark.parametrize("tech_kind", SAMPLES, ids=IDS)
def test_a_list_of_cameras_gives_the_frames_of_single_renders(gl, tech_kind):
    """`render(obj, [a, b])` uploads once and draws per camera: bit-identical to two calls."""
    rep = sample(*tech_kind)
    cameras = [orbit_bounds(rep.bounds, *view, size=(64, 48)) for view in VIEWS]
    together = render(rep, cameras)
    assert isinstance(together, list) and len(together) == len(cameras)
    for camera, frame in zip(cameras, together, strict=True):
        alone = render(rep, camera)
        for name in ("color", "mask", "depth", "position", "normal"):
            np.testing.assert_array_equal(getattr(frame, name), getattr(alone, name),
                                          err_msg=name)
        assert frame.warnings == alone.warnings
