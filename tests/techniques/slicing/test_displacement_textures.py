"""The procedural displacement textures: each texel is its definition (every tuft or bump,
the nearest periodic copy), made a band of rows at a time; oversized ones are refused."""

from __future__ import annotations

import numpy as np
import pytest

from reliefkit.errors import UsageError
from reliefkit.techniques.slicing import displacement_textures as textures


def _every_tuft(res: int, seed: int = 1) -> np.ndarray:
    """Fur's height by its definition: the skin, and the highest of all tufts at each texel."""
    cells = max(2, res // 6)
    cx, cy, rng = textures._jittered(cells, seed)
    tall = 0.55 + 0.45 * rng.random(len(cx))
    s = (np.arange(res) + 0.5) / res
    x, y = np.meshgrid(s, s)
    dx = np.abs(x[..., None] - cx)
    dy = np.abs(y[..., None] - cy)
    d = np.hypot(np.minimum(dx, 1 - dx), np.minimum(dy, 1 - dy))
    return np.maximum(0.12, (tall * np.clip(1 - d / (0.45 / cells), 0, 1)).max(axis=-1))


@pytest.mark.parametrize("res", [12, 50, 96])
def test_fur_is_every_tuft(res, monkeypatch):
    monkeypatch.setattr(textures, "BAND_TEXELS", 7 * res)  # several bands, one ragged
    color, height = textures.make_texture("fur", res)
    np.testing.assert_array_equal(height, _every_tuft(res).astype(np.float32))
    assert color.shape == (res, res, 4) and (color[..., 3] == 1).all()


def test_bands_do_not_change_a_texture(monkeypatch):
    whole = {name: textures.make_texture(name, 40) for name in textures.TEXTURES}
    monkeypatch.setattr(textures, "BAND_TEXELS", 3 * 40)
    for name, (color, height) in whole.items():
        banded = textures.make_texture(name, 40)
        np.testing.assert_array_equal(banded[0], color)
        np.testing.assert_array_equal(banded[1], height)


def test_an_oversized_texture_is_refused_with_its_estimate():
    with pytest.raises(UsageError, match=r"8192x8192 texels would take up to about \d+ "
                                         r"minutes here and 1\.2 GiB"):
        textures.make_texture("fur", 8192)
