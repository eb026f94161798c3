"""Tests of reliefkit.metrics against independent computations on tiny synthetic frames."""

from __future__ import annotations

import json
import math
import warnings
from dataclasses import dataclass

import numpy as np
import pytest

from reliefkit import metrics
from reliefkit.errors import UsageError


@pytest.fixture(autouse=True)
def _strict_float():
    """Floating-point errors raise and RuntimeWarnings (e.g. mean of empty) fail the test."""
    old = np.seterr(all="raise")
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        yield
    np.seterr(**old)


@dataclass
class F:
    """The smallest frame-like object the metrics accept."""

    color: np.ndarray
    mask: np.ndarray
    depth: np.ndarray
    position: np.ndarray


def srgb_ref(x: float) -> float:
    """The IEC 61966-2-1 encoding, written out independently of the module."""
    return 12.92 * x if x <= 0.0031308 else 1.055 * x ** (1 / 2.4) - 0.055


def srgb_inv(s: float) -> float:
    return s / 12.92 if s <= 0.04045 else ((s + 0.055) / 1.055) ** 2.4


def srgb_ref_array(x: np.ndarray) -> np.ndarray:
    x = np.nan_to_num(np.asarray(x, np.float64))
    return np.vectorize(srgb_ref)(x)


def frame(mask, srgb=0.5, alpha=1.0, depth=0.5, position=None) -> F:
    """Frame whose covered pixels display ``srgb`` (scalar or (H,W)) at full alpha.

    Uncovered pixels hold garbage colour/depth and NaN positions, as renderers may.
    """
    mask = np.asarray(mask, dtype=bool)
    h, w = mask.shape
    lin = np.vectorize(srgb_inv)(np.broadcast_to(np.asarray(srgb, float), (h, w)))
    color = np.empty((h, w, 4), np.float32)
    color[..., :3] = lin[..., None]
    color[..., 3] = alpha
    color[~mask] = np.nan
    dep = np.broadcast_to(np.asarray(depth, np.float32), (h, w)).copy()
    dep[~mask] = np.nan
    pos = np.zeros((h, w, 3), np.float32) if position is None else np.array(position, np.float32)
    pos[~mask] = np.nan
    return F(color, mask, dep, pos)


def full(h=8, w=8):
    return np.ones((h, w), bool)


# ----------------------------------------------------------------------------- sRGB


def test_srgb_known_points():
    assert metrics.srgb_encode(0.5) == pytest.approx(0.7353569830524495, abs=1e-6)
    assert metrics.srgb_decode(0.7353569830524495) == pytest.approx(0.5, abs=1e-6)
    # The branch point: both pieces meet at linear 0.0031308 / sRGB 0.04045 (to ~1e-8).
    assert metrics.srgb_encode(0.0031308) == pytest.approx(12.92 * 0.0031308, abs=1e-7)
    high_piece = 1.055 * 0.0031308 ** (1 / 2.4) - 0.055
    assert high_piece == pytest.approx(12.92 * 0.0031308, abs=1e-7)
    assert metrics.srgb_decode(0.04045) == pytest.approx(0.04045 / 12.92, abs=1e-8)
    assert metrics.srgb_encode(0.001) == pytest.approx(0.01292, abs=1e-8)
    assert metrics.srgb_encode(0.0) == 0.0 and metrics.srgb_encode(1.0) == 1.0
    assert metrics.srgb_decode(0.0) == 0.0 and metrics.srgb_decode(1.0) == 1.0


def test_srgb_matches_reference_formula_and_round_trips():
    x = np.linspace(0.0, 1.0, 10000, dtype=np.float32).reshape(100, 100, 1)
    enc = metrics.srgb_encode(x)
    assert enc.dtype == np.float32 and enc.shape == x.shape
    expected = np.vectorize(srgb_ref)(x.astype(np.float64))
    np.testing.assert_allclose(enc, expected, atol=1e-6)
    np.testing.assert_allclose(metrics.srgb_decode(enc), x, atol=1e-6)
    np.testing.assert_allclose(metrics.srgb_encode(metrics.srgb_decode(x)), x, atol=1e-6)
    assert np.all(np.diff(enc.ravel()) >= 0)


def test_srgb_clips_out_of_range():
    np.testing.assert_array_equal(metrics.srgb_encode([-0.5, 2.0]), [0.0, 1.0])
    np.testing.assert_array_equal(metrics.srgb_decode([-0.5, 2.0]), [0.0, 1.0])


# ----------------------------------------------------------------------------- PSNR / SSIM


@pytest.mark.parametrize("d", [0.1, 0.02, 0.25])
def test_psnr_constant_offset(d):
    test, ref = frame(full(), srgb=0.5 + d), frame(full(), srgb=0.5)
    assert metrics.psnr(test, ref) == pytest.approx(10 * math.log10(1 / d**2), abs=1e-3)


def test_psnr_union_counts_pixels_covered_only_by_one_frame():
    ref_mask = np.zeros((4, 5), bool)
    ref_mask[1, 1:5] = True  # four pixels
    test_mask = ref_mask.copy()
    test_mask[1, 4] = False  # the test misses one of them...
    test_mask[3, 0] = True  # ...and covers one the reference does not
    v, u = 0.6, 0.3
    test, ref = frame(test_mask, srgb=u), frame(ref_mask, srgb=u)
    ref.color[1, 4, :3] = srgb_inv(v)
    # Union: 5 pixels x 3 channels; errors v (ref only, vs black) and u (test only).
    expected_mse = 3 * (v**2 + u**2) / (5 * 3)
    assert metrics.psnr(test, ref) == pytest.approx(10 * math.log10(1 / expected_mse), abs=1e-4)


def test_psnr_premultiplies_alpha_in_linear_space():
    test, ref = frame(full(2, 2), srgb=0.8, alpha=0.25), frame(full(2, 2), srgb=0.8)
    shown = srgb_ref(srgb_inv(0.8) * 0.25)  # displayed over black
    expected = 10 * math.log10(1 / (0.8 - shown) ** 2)
    assert metrics.psnr(test, ref) == pytest.approx(expected, abs=1e-4)


def test_psnr_explicit_mask_restricts_region():
    test, ref = frame(full(4, 4), srgb=0.5), frame(full(4, 4), srgb=0.5)
    test.color[0, 0, :3] = srgb_inv(0.9)
    region = np.zeros((4, 4), bool)
    region[2:, 2:] = True
    assert metrics.psnr(test, ref, mask=region) == math.inf
    region[0, 0] = True  # 5 pixels, one off by 0.4
    expected = 10 * math.log10(1 / (0.4**2 / 5))
    assert metrics.psnr(test, ref, mask=region) == pytest.approx(expected, abs=1e-4)
    with pytest.raises(UsageError):
        metrics.psnr(test, ref, mask=np.ones((3, 3), bool))


def test_identical_frames():
    rng = np.random.default_rng(0)
    mask = rng.random((16, 12)) < 0.7
    pos = rng.normal(size=(16, 12, 3))
    a = frame(mask, srgb=rng.random((16, 12)), depth=rng.random((16, 12)), position=pos)
    b = frame(mask, srgb=rng.random((16, 12)), depth=0.0, position=pos)
    b.color, b.depth = a.color.copy(), a.depth.copy()
    assert metrics.psnr(a, b) == math.inf
    assert metrics.ssim(a, b) == pytest.approx(1.0, abs=1e-12)
    assert metrics.mask_iou(a, b) == 1.0
    assert metrics.mask_xor(a, b) == 0
    assert metrics.position_error(a, b)["max"] == 0.0
    assert metrics.depth_error(a, b)["max"] == 0.0


def test_ssim_decreases_with_noise():
    rng = np.random.default_rng(0)
    yy, xx = np.mgrid[0:32, 0:32] / 31.0
    base = 0.2 + 0.6 * xx * yy
    ref = frame(full(32, 32), srgb=base)
    scores = []
    for sigma in (0.0, 0.02, 0.1, 0.3):
        noisy = np.clip(base + rng.normal(0.0, sigma, base.shape), 0.0, 1.0)
        scores.append(metrics.ssim(frame(full(32, 32), srgb=noisy), ref))
    assert scores[0] == pytest.approx(1.0, abs=1e-12)
    assert scores[0] > scores[1] > scores[2] > scores[3]


def test_ssim_is_averaged_over_union_only():
    from skimage.metrics import structural_similarity

    mask = np.zeros((20, 20), bool)
    mask[5:12, 5:12] = True
    rng = np.random.default_rng(0)
    test = frame(mask, srgb=rng.random((20, 20)))
    ref = frame(mask, srgb=0.5)
    img = [np.where(f.mask[..., None], srgb_ref_array(f.color[..., :3]), 0.0) for f in (test, ref)]
    _, smap = structural_similarity(*img, win_size=7, channel_axis=-1, data_range=1.0, full=True)
    expected = smap.mean(axis=-1)[mask].mean()
    assert metrics.ssim(test, ref) == pytest.approx(expected, abs=1e-5)
    # Identical black background outside the union would pull a whole-image mean up.
    assert metrics.ssim(test, ref) < smap.mean()


def test_ssim_small_frames():
    test, ref = frame(full(4, 5), srgb=0.3), frame(full(4, 5), srgb=0.5)
    assert metrics.ssim(test, ref) < 1.0  # window shrinks to 3
    assert metrics.ssim(ref, ref) == pytest.approx(1.0, abs=1e-12)
    with pytest.raises(UsageError, match="3x3"):
        metrics.ssim(frame(full(2, 8)), frame(full(2, 8)))


# ----------------------------------------------------------------------------- masks


def test_mask_iou_and_xor_hand_made():
    a = np.zeros((3, 4), bool)
    b = np.zeros((3, 4), bool)
    a[0, 0:3] = True  # (0,0) (0,1) (0,2)
    b[0, 1:3] = True  # (0,1) (0,2)
    b[2, 2:4] = True  # (2,2) (2,3)
    # intersection 2, union 5, exactly-one 3
    assert metrics.mask_iou(frame(a), frame(b)) == pytest.approx(2 / 5)
    assert metrics.mask_xor(frame(a), frame(b)) == 3
    assert metrics.mask_iou(frame(a), frame(np.zeros((3, 4), bool))) == 0.0
    assert isinstance(metrics.mask_xor(frame(a), frame(b)), int)


# ----------------------------------------------------------------------------- geometry


def _geometry_pair():
    """3x3 frames sharing three pixels whose positions differ by 1, 2 and 5."""
    mt = np.zeros((3, 3), bool)
    mr = np.zeros((3, 3), bool)
    mt[0, :] = True
    mr[0, :] = True
    mt[2, 0] = True  # only the test: huge error, must be ignored
    mr[2, 2] = True  # only the reference
    pt = np.zeros((3, 3, 3))
    pr = np.zeros((3, 3, 3))
    pr[0, 0] = (1, 0, 0)
    pr[0, 1] = (0, -2, 0)
    pt[0, 2], pr[0, 2] = (10, 10, 10), (13, 14, 10)
    pt[2, 0] = (1e6, 0, 0)
    dt = np.full((3, 3), 0.5)
    dr = np.full((3, 3), 0.5)
    dr[0] = (0.5, 0.6, 0.2)
    dt[2, 0] = 1.0
    return frame(mt, position=pt, depth=dt), frame(mr, position=pr, depth=dr)


def test_position_error_hand_made():
    test, ref = _geometry_pair()
    assert np.isnan(test.position[1, 1]).all()  # NaN outside masks reaches the metric
    err = metrics.position_error(test, ref)
    d = np.array([1.0, 2.0, 5.0])
    assert err["count"] == 3
    assert err["mean"] == pytest.approx(8 / 3)
    assert err["rms"] == pytest.approx(math.sqrt(30 / 3))
    assert err["max"] == pytest.approx(5.0)
    assert err["median"] == pytest.approx(2.0)
    assert err["p95"] == pytest.approx(2.0 + 0.9 * 3.0)  # linear interpolation at rank 1.9
    assert err["p95"] == pytest.approx(np.percentile(d, 95))


def test_depth_error_hand_made():
    test, ref = _geometry_pair()
    err = metrics.depth_error(test, ref)
    assert err["count"] == 3
    assert err["max"] == pytest.approx(0.3, abs=1e-6)
    assert err["mean"] == pytest.approx((0.0 + 0.1 + 0.3) / 3, abs=1e-6)
    assert err["median"] == pytest.approx(0.1, abs=1e-6)


def test_empty_common_mask_gives_nan_and_zero_count():
    a = np.zeros((4, 4), bool)
    b = np.zeros((4, 4), bool)
    a[0, 0] = True
    b[3, 3] = True
    for fn in (metrics.position_error, metrics.depth_error):
        err = fn(frame(a), frame(b))
        assert err["count"] == 0
        assert set(err) == {"mean", "rms", "max", "p95", "median", "count"}
        assert all(math.isnan(err[k]) for k in ("mean", "rms", "max", "p95", "median"))


# ----------------------------------------------------------------------------- errors


ALL_PAIRWISE = [
    metrics.psnr,
    metrics.ssim,
    metrics.mask_iou,
    metrics.mask_xor,
    metrics.position_error,
    metrics.depth_error,
    metrics.compare,
    metrics.error_image,
]


@pytest.mark.parametrize("fn", ALL_PAIRWISE, ids=lambda f: f.__name__)
def test_shape_mismatch_raises(fn):
    with pytest.raises(UsageError, match="frames differ in size: 64x48 vs 64x64"):
        fn(frame(full(48, 64)), frame(full(64, 64)))


@pytest.mark.parametrize(
    "fn", [metrics.psnr, metrics.ssim, metrics.mask_iou, metrics.compare], ids=lambda f: f.__name__
)
def test_empty_frames_raise(fn):
    empty = np.zeros((8, 8), bool)
    with pytest.raises(UsageError, match="both frames are empty"):
        fn(frame(empty), frame(empty))


def test_empty_frames_counts_are_still_defined():
    empty = np.zeros((8, 8), bool)
    assert metrics.mask_xor(frame(empty), frame(empty)) == 0
    assert metrics.position_error(frame(empty), frame(empty))["count"] == 0


def test_inconsistent_frame_arrays_raise():
    bad = frame(full(4, 4))
    bad.color = bad.color[..., :3]
    with pytest.raises(UsageError, match="color"):
        metrics.psnr(bad, frame(full(4, 4)))


# ----------------------------------------------------------------------------- compare


def test_compare_flat_json_dict():
    test, ref = _geometry_pair()
    out = metrics.compare(test, ref, scene_size=2.0)
    expected_keys = {
        "psnr", "ssim", "iou", "xor", "xor_fraction", "common_pixels",
        "position_mean", "position_rms", "position_max", "position_p95",
        "depth_mean", "depth_max",
        "position_mean_rel", "position_rms_rel", "position_max_rel", "position_p95_rel",
    }  # fmt: skip
    assert set(out) == expected_keys
    assert all(type(v) in (float, int) for v in out.values())
    assert out["xor"] == 2 and out["xor_fraction"] == pytest.approx(2 / 5)
    assert out["iou"] == pytest.approx(3 / 5)
    assert out["position_max"] == pytest.approx(5.0)
    assert out["position_max_rel"] == pytest.approx(2.5)
    assert out["depth_max"] == pytest.approx(0.3, abs=1e-6)
    assert json.loads(json.dumps(out)) == pytest.approx(out)

    plain = metrics.compare(test, ref)
    assert not any(k.endswith("_rel") for k in plain)
    for bad in (0.0, -1.0, math.inf, math.nan):
        with pytest.raises(UsageError, match="scene_size"):
            metrics.compare(test, ref, scene_size=bad)


# ----------------------------------------------------------------------------- pictures


def test_heat_ramp_endpoints_and_rising_luminance():
    t = np.linspace(0.0, 1.0, 101)
    ramp = metrics.heat_ramp(t)
    assert ramp.shape == (101, 3) and ramp.dtype == np.float32
    np.testing.assert_allclose(metrics.heat_ramp(-1.0), ramp[0])
    np.testing.assert_allclose(metrics.heat_ramp(2.0), ramp[-1])
    lum = ramp @ np.array([0.2126, 0.7152, 0.0722], np.float32)
    assert np.all(np.diff(lum) > 0)


def test_error_image_mask_colours():
    a = np.array([[1, 1], [0, 0]], bool)
    b = np.array([[1, 0], [1, 0]], bool)
    img = metrics.error_image(frame(a), frame(b), "mask")
    assert img.shape == (2, 2, 3) and img.dtype == np.float32
    np.testing.assert_array_equal(img[0, 0], [0, 1, 0])  # both
    np.testing.assert_array_equal(img[0, 1], [1, 0, 0])  # only test
    np.testing.assert_array_equal(img[1, 0], [0, 0, 1])  # only ref
    np.testing.assert_array_equal(img[1, 1], [0, 0, 0])  # neither


def test_error_image_color():
    mask = np.zeros((3, 3), bool)
    mask[:2] = True
    test, ref = frame(mask, srgb=0.5), frame(mask, srgb=0.5)
    test.color[0, 0, :3] = srgb_inv(0.75)  # difference 0.25 -> half-way with scale 0.5
    img = metrics.error_image(test, ref, "color", scale=0.5)
    assert img.shape == (3, 3, 3) and img.dtype == np.float32
    assert img.min() >= 0.0 and img.max() <= 1.0
    np.testing.assert_allclose(img[0, 0], metrics.heat_ramp(0.5), atol=1e-5)
    np.testing.assert_allclose(img[1, 1], metrics.heat_ramp(0.0), atol=1e-6)
    np.testing.assert_array_equal(img[2], 0.0)  # outside the union


def test_error_image_position():
    test, ref = _geometry_pair()
    auto = metrics.error_image(test, ref, "position")
    np.testing.assert_allclose(auto[0, 2], metrics.heat_ramp(1.0))  # largest error on top
    np.testing.assert_allclose(auto[0, 0], metrics.heat_ramp(0.2), atol=1e-6)
    np.testing.assert_array_equal(auto[2], 0.0)  # not common: black
    scaled = metrics.error_image(test, ref, "position", scale=10.0)
    np.testing.assert_allclose(scaled[0, 2], metrics.heat_ramp(0.5), atol=1e-6)
    assert np.isfinite(auto).all() and np.isfinite(scaled).all()


def test_error_image_bad_arguments():
    f = frame(full(3, 3))
    with pytest.raises(UsageError, match="kind"):
        metrics.error_image(f, f, "normal")
    with pytest.raises(UsageError, match="scale"):
        metrics.error_image(f, f, "color", scale=0.0)
