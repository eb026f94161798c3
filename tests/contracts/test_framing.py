"""Every registered baker keeps its source mesh's framing: one ``--view`` gives one camera
for a mesh and every kind baked from it (`scene.views.framing_bounds`), also after a
round trip through a .rk file, so pictures and AOVs of the two line up pixel for pixel."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from reliefkit.bake import bake
from reliefkit.core.technique import bakers
from reliefkit.io import rk
from reliefkit.scene.assets import make_asset
from reliefkit.scene.views import framing_bounds, orbit_bounds

#: Small values for the parameters that set a bake's cost, wherever a baker declares them.
SMALL = {"depth_res": 16, "res": 16, "safety": False, "texture_size": (8, 8, 4)}
MESH_BAKERS = sorted(name for name, (_, b) in bakers().items() if "mesh" in b.sources)
VIEWS = [(30.0, 25.0, None), (200.0, -10.0, 2.0)]


def _small_params(baker) -> dict:
    names = {f.name for f in dataclasses.fields(baker.params)}
    return {name: value for name, value in SMALL.items() if name in names}


@pytest.mark.parametrize("kind", MESH_BAKERS)
def test_a_bake_is_framed_as_its_mesh(gl, tmp_path, kind):
    mesh = make_asset("teapot")  # uvs, and a box whose sides all differ
    _, baker = bakers()[kind]
    path = tmp_path / "baked.rk"
    rk.save(path, bake(mesh, kind, **_small_params(baker)))
    for rep in (bake(mesh, kind, **_small_params(baker)), rk.load(path)):
        for view in VIEWS:
            expected = orbit_bounds(mesh.bounds, *view, size=(64, 48))
            camera = orbit_bounds(framing_bounds(rep), *view, size=(64, 48))
            np.testing.assert_array_equal(camera.view, expected.view, err_msg=kind)
            np.testing.assert_array_equal(camera.proj, expected.proj, err_msg=kind)
