"""The relief kinds' own validation: what the generic contract tests cannot know."""

from __future__ import annotations

import json
import zipfile

import numpy as np
import pytest

from reliefkit.errors import FormatError
from reliefkit.io import rk
from reliefkit.techniques.relief import TECHNIQUE


def _edit_params(path, edit):
    with zipfile.ZipFile(path) as zf:
        content = {info.filename: zf.read(info) for info in zf.infolist()}
    manifest = json.loads(content["manifest.json"])
    edit(manifest["params"])
    content["manifest.json"] = json.dumps(manifest).encode()
    with zipfile.ZipFile(path, "w") as zf:
        for name, data in content.items():
            zf.writestr(name, data)


@pytest.fixture
def samples():
    return TECHNIQUE.samples()


@pytest.mark.parametrize("part_params", [[{}], "x", [{}, 3], None])
def test_object_part_params_must_match_the_parts(tmp_path, samples, part_params):
    path = tmp_path / "o.rk"
    rk.save(path, samples["relief-object"])
    _edit_params(path, lambda p: p.update(part_params=part_params))
    with pytest.raises(FormatError, match="part_params must be a list of 2"):
        rk.load(path)


@pytest.mark.parametrize("value, words", [
    ([[5, 5, 5], [6, 6, 6]], "do not overlap"),
    ("everything", "clip_bounds must be"),
    ([[0, 0], [1, 1]], "clip_bounds must be"),
    ([[1, 0, 0], [0, 1, 1]], "min <= max"),
])
def test_old_style_clip_bounds_are_validated(tmp_path, samples, value, words):
    path = tmp_path / "r.rk"
    rk.save(path, samples["relief"])
    _edit_params(path, lambda p: p.update(clip_bounds=value))
    with pytest.raises(FormatError, match=words):
        rk.load(path)


def test_old_style_clip_bounds_still_clip(tmp_path, samples):
    path = tmp_path / "r.rk"
    rk.save(path, samples["relief"])
    _edit_params(path, lambda p: p.update(clip_bounds=[[-0.5, 0, -0.5], [0.5, 1, 0.5]]))
    np.testing.assert_array_equal(rk.load(path).clip_bounds, [[-0.5, 0, -0.5], [0.5, 1, 0.5]])
