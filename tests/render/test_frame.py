"""`Frame.save_aovs` without a GPU: a compressed .npz that plain numpy reads bit for bit."""

from __future__ import annotations

import os
import zipfile

import numpy as np
import pytest

from reliefkit.errors import UsageError
from reliefkit.render.frame import AOV_NAMES, Frame


def make_frame(width: int = 96, height: int = 64) -> Frame:
    rng = np.random.default_rng(0)
    mask = np.zeros((height, width), bool)
    mask[10:50, 20:70] = True
    color = np.where(mask[..., None], rng.random((height, width, 4), np.float32), 0)
    position = np.where(mask[..., None], rng.random((height, width, 3), np.float32), np.nan)
    normal = np.where(mask[..., None], np.float32([0, 0, 1]), 0)
    depth = np.where(mask, rng.random((height, width), np.float32), 1)
    return Frame(color=color.astype(np.float32), mask=mask, depth=depth.astype(np.float32),
                 position=position.astype(np.float32), normal=normal.astype(np.float32),
                 view=np.eye(4), proj=np.diag([1.0, 1.0, -1.0, 1.0]),
                 viewport=np.array([0, 0, width, height], np.int32))


def test_save_aovs_writes_a_compressed_npz_read_back_bit_for_bit(tmp_path):
    frame = make_frame()
    path = tmp_path / "f.npz"
    frame.save_aovs(path)
    with zipfile.ZipFile(path) as zf:
        infos = zf.infolist()
        assert {info.compress_type for info in infos} == {zipfile.ZIP_DEFLATED}
        assert sum(i.compress_size for i in infos) < sum(i.file_size for i in infos) / 2
    with np.load(path, allow_pickle=False) as data:
        assert set(data.files) == set(AOV_NAMES)
        for name in AOV_NAMES:
            want = np.asarray(getattr(frame, name))
            assert data[name].dtype == want.dtype and data[name].shape == want.shape, name
            assert data[name].tobytes() == want.tobytes(), name  # NaN where nothing was hit
    assert os.listdir(tmp_path) == ["f.npz"]  # written through a temp file, nothing left


def test_save_aovs_replaces_atomically_and_checks_the_suffix(tmp_path, monkeypatch):
    path = tmp_path / "f.npz"
    make_frame().save_aovs(path)
    before = path.read_bytes()

    def broken(*args, **kwargs):
        raise RuntimeError("disk on fire")

    monkeypatch.setattr(np, "savez_compressed", broken)
    with pytest.raises(RuntimeError, match="disk on fire"):
        make_frame(32, 32).save_aovs(path)
    assert path.read_bytes() == before and os.listdir(tmp_path) == ["f.npz"]
    with pytest.raises(UsageError, match=r"must end in \.npz"):
        make_frame().save_aovs(tmp_path / "f.npy")
