"""Procedural 3D textures, .npy loading and the §5.2 mip filtering."""

import tracemalloc

import numpy as np
import pytest

from reliefkit.errors import FormatError, UsageError
from reliefkit.techniques.shellvolume.filtering import (
    mip_pyramid,
    naive_pyramid,
    slab_transmittance,
)
from reliefkit.techniques.shellvolume.textures import (
    TEXTURES,
    VolumeTexture,
    load_texture_npy,
)


@pytest.mark.parametrize("name", sorted(TEXTURES))
def test_generator_shapes_ranges_determinism(name):
    a = TEXTURES[name](size=(16, 8, 8), seed=3)
    b = TEXTURES[name](size=(16, 8, 8), seed=3)
    assert isinstance(a, VolumeTexture) and a.name == name
    assert a.rgba.shape == (8, 8, 16, 4) and a.rgba.dtype == np.float32
    assert a.normal.shape == (8, 8, 16, 3) and a.normal.dtype == np.float32
    np.testing.assert_array_equal(a.rgba, b.rgba)
    np.testing.assert_array_equal(a.normal, b.normal)
    assert np.isfinite(a.rgba).all() and a.rgba.min() >= 0 and a.rgba.max() <= 1
    np.testing.assert_allclose(np.linalg.norm(a.normal, axis=-1), 1, atol=1e-5)


def test_seed_changes_random_textures():
    for name in ("fur", "clouds", "ellipsoids", "rocks"):
        assert not np.array_equal(TEXTURES[name](seed=0).rgba, TEXTURES[name](seed=1).rgba)


def test_texture_statistics():
    alpha = {n: m().rgba[..., 3] for n, m in TEXTURES.items()}
    np.testing.assert_array_equal(alpha["absorption"], 0.5)
    fur = (alpha["fur"] > 0).mean(axis=(1, 2))
    assert fur[0] > 0.1 and np.all(np.diff(fur) <= 1e-9) and fur[-1] < fur[0] / 4
    assert np.all(alpha["clouds"][0] == 1)
    assert alpha["clouds"][1:].max() < 1 and alpha["clouds"][1:].max() > 0
    for name in ("chain", "rocks", "ellipsoids"):
        assert (alpha[name] == 1).any() and (alpha[name] < 1).any()
    assert alpha["ellipsoids"].min() == pytest.approx(0.3)


def test_load_npy_round_trip(tmp_path):
    tex = TEXTURES["ellipsoids"](size=(8, 8, 4))
    path = tmp_path / "t.npy"
    np.save(path, tex.rgba)
    loaded = load_texture_npy(path)
    np.testing.assert_array_equal(loaded.rgba, tex.rgba)
    assert loaded.name == "t"


@pytest.mark.parametrize("bad", [np.zeros((4, 4, 4, 3), np.float32),
                                 np.full((2, 2, 2, 4), np.nan, np.float32),
                                 np.full((2, 2, 2, 4), -0.5, np.float32),
                                 np.zeros((2, 2, 2, 4), np.int32)])
def test_load_npy_refuses_bad_arrays(tmp_path, bad):
    path = tmp_path / "bad.npy"
    np.save(path, bad)
    with pytest.raises(FormatError) as info:
        load_texture_npy(path)
    assert "\n" not in str(info.value)


def test_load_npy_refuses_directory_and_forged_header(tmp_path):
    with pytest.raises(FormatError):
        load_texture_npy(tmp_path)
    path = tmp_path / "forged.npy"
    header = {"descr": "<f4", "fortran_order": False, "shape": (10000, 10000, 10000, 4)}
    with open(path, "wb") as f:
        np.lib.format.write_array_header_1_0(f, header)
        f.write(b"\0" * 64)
    tracemalloc.start()
    try:
        with pytest.raises(FormatError, match="voxels"):
            load_texture_npy(path)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < 1 << 20


def _slab_drift(pyramid, thickness):
    t0 = slab_transmittance(pyramid[0], thickness).mean()
    return max(abs(slab_transmittance(lv, thickness).mean() - t0) for lv in pyramid)


def test_uniform_slab_transmittance_and_colour_preserved():
    tex = TEXTURES["absorption"](size=(16, 16, 16))
    pyr = mip_pyramid(tex, 4, thickness=2.0)
    assert [lv.shape for lv in pyr] == [(16, 16, 16, 4), (8, 8, 8, 4), (4, 4, 4, 4), (2, 2, 2, 4)]
    t0 = slab_transmittance(pyr[0], 2.0)
    np.testing.assert_allclose(t0, 0.25, rtol=1e-5)
    for lv in pyr:
        t = slab_transmittance(lv, 2.0)
        assert np.all(np.abs(t - 0.25) <= 0.02 * 0.25)
        want = np.broadcast_to(tex.rgba[0, 0, 0, :3], lv.shape[:3] + (3,))
        np.testing.assert_allclose(lv[..., :3], want, atol=1e-5)


def test_thin_opaque_layer_mip_vs_naive():
    rgba = np.zeros((16, 8, 8, 4), np.float32)
    rgba[5] = (1.0, 0.5, 0.2, 0.99)
    thickness = 16.0
    mip = _slab_drift(mip_pyramid(rgba, 4, thickness), thickness)
    naive = _slab_drift(naive_pyramid(rgba, 4), thickness)
    print(f"slab transmittance drift over 4 levels: mip {mip:.4f}, naive {naive:.4f}")
    assert mip < 0.02
    assert naive > 0.02
    top = mip_pyramid(rgba, 4, thickness)[3]
    np.testing.assert_allclose(top[0, 0, 0, :3], (1, 0.5, 0.2), atol=1e-5)


def test_mip_colour_weights_by_opacity_top_down():
    rgba = np.zeros((2, 2, 2, 4), np.float32)
    rgba[1] = (1, 0, 0, 1)  # top (front) layer opaque red
    rgba[0] = (0, 0, 1, 1)  # back blue hidden behind it
    top = mip_pyramid(rgba, 2)[1]
    np.testing.assert_allclose(top[0, 0, 0], (1, 0, 0, 1), atol=1e-6)


def test_odd_size_refused():
    with pytest.raises(UsageError):
        mip_pyramid(np.zeros((3, 4, 4, 4), np.float32), 2)
