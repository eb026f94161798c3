"""The billboard kinds in .rk files: a bake is the same file every time, and what a file
derives from its maps (the distance textures) or types loosely (the thickness) is checked on
reading, not trusted."""

from __future__ import annotations

import numpy as np
import pytest
from billboard_scenes import flat, quads, stacked

from reliefkit.builtins import registry
from reliefkit.errors import FormatError, UsageError
from reliefkit.io.rk import load, save, write_rk
from reliefkit.techniques.billboard.bake import bake_billboard_cloud
from reliefkit.techniques.billboard.box_bake import bake_boxes
from reliefkit.techniques.billboard.boxes import BillboardBoxes


def test_the_same_bake_writes_the_same_bytes(gl, tmp_path):
    """The plane search's time goes to the bake's report only, not into the file."""
    mesh = stacked()
    for name, bake in (("bbc", lambda: bake_billboard_cloud(mesh, texel_size=0.05)),
                       ("dmbbc", lambda: bake_boxes(mesh, "shell", texel_size=0.05))):
        first, second = bake(), bake()
        assert "planes found in" in first.bake_report()[0 if name == "bbc" else 1]
        a, b = save(tmp_path / f"{name}-a.rk", first), save(tmp_path / f"{name}-b.rk", second)
        assert a.read_bytes() == b.read_bytes(), name
        assert load(a).bake_report()  # a loaded file reports without the time it lacks


def rewritten(tmp_path, rep, change) -> object:
    """``rep`` written with ``change(arrays, params)`` applied, as a forger would."""
    codec = registry().codecs().for_object(rep)
    arrays, params = codec.to_arrays(rep)
    arrays = {k: np.array(v) for k, v in arrays.items() if v is not None}
    change(arrays, params)
    path = tmp_path / "forged.rk"
    write_rk(path, codec.kind, arrays, params)
    return path


@pytest.mark.parametrize("variant", ["volumetric", "shell", "thick-shell"])
def test_a_distance_texture_longer_than_the_maps_allow_is_refused(gl, tmp_path, variant):
    """A safe step one voxel longer than the truth next to a surface lets the sphere march
    jump over it; shorter steps only cost time and load."""
    rep = bake_boxes(quads(flat(0.0)), variant, texel_size=0.05)
    assert load(save(tmp_path / "honest.rk", rep)).boxes[0].distance.tolist() \
        == rep.boxes[0].distance.tolist()

    def longer(arrays, _):
        distance = arrays["b0_distance"]
        d, h, w = np.unravel_index(np.argmax(distance == 1), distance.shape)
        assert distance[d, h, w] == 1  # a voxel next to the surface
        distance[d, h, w] = 3

    with pytest.raises(FormatError, match="distance texture exceeds") as error:
        load(rewritten(tmp_path, rep, longer))
    assert "\n" not in str(error.value)

    def shorter(arrays, _):
        arrays["b0_distance"][:] = 0

    assert load(rewritten(tmp_path, rep, shorter)).boxes[0].distance.max() == 0


@pytest.mark.parametrize("thickness", ["0.5", True, float("nan"), [0.5]])
def test_a_shell_thickness_must_be_a_number(gl, tmp_path, thickness):
    rep = bake_boxes(quads(flat(0.0)), "shell", texel_size=0.05, thickness=0.5)
    with pytest.raises(UsageError, match="thickness must be a number"):
        BillboardBoxes("shell", rep.boxes, rep.cloud, thickness=thickness)
    if isinstance(thickness, float):
        return  # NaN is not JSON: no file can hold it

    def typed(_, params):
        params["thickness"] = thickness

    with pytest.raises(FormatError, match="thickness must be a number"):
        load(rewritten(tmp_path, rep, typed))
