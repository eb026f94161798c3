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


@pytest.mark.parametrize("change, words", [
    ("zero heights", "nothing visible"),
    ("tiny box", "cannot be drawn"),
    ("far box", "cannot be drawn"),
    ("singular", "singular or badly conditioned"),
    ("beyond infinity", "plane at infinity"),
    ("huge radii", "at most 255 make sense"),
])
def test_representations_that_cannot_be_drawn_are_refused(tmp_path, samples, change, words):
    """Each is refused when it is made and, forged into a file, when the file is loaded."""
    from reliefkit.errors import UsageError
    from reliefkit.techniques.relief.representation import ReliefTexture

    relief = samples["relief"]
    box = relief.box_to_world
    projective = box.copy()
    projective[3] = [0.0, 0.0, -4.0, 1.0]  # w = 1 - 4h: negative in the upper part of the box
    fields = {
        "zero heights": {"height": np.zeros_like(relief.height)},
        "tiny box": {"box_to_world": np.diag([1e-97, 1e-97, 1e-97, 1.0])},
        "far box": {"box_to_world": box + np.array([[0, 0, 0, 1e30]] * 3 + [[0, 0, 0, 0]])},
        "singular": {"box_to_world": np.diag([1.0, 1.0, 1e-14, 1.0])},
        "beyond infinity": {"box_to_world": projective},
        "huge radii": {"safety": np.full(relief.height.shape, 65535, np.uint16)},
    }[change]
    kwargs = {name: getattr(relief, name) for name in
              ("height", "color", "normal", "box_to_world", "safety")} | fields
    with pytest.raises(UsageError, match=words):
        ReliefTexture(**kwargs)
    # the same forged into a file
    good = tmp_path / "good.rk"
    rk.save(good, relief)
    forged = tmp_path / "forged.rk"
    arrays, params = rk.read_rk(good).arrays, rk.read_manifest(good)["params"]
    arrays = dict(arrays) | {k: v for k, v in fields.items()}
    rk.write_rk(forged, "relief", arrays, params)
    with pytest.raises(FormatError, match=words):
        rk.load(forged)
