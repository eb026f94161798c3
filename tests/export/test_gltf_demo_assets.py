"""Every kind baked from a demo asset (small resolutions) and exported with its fallback:
the Khronos validator reports no error and no warning, `load` gives the representation
back bit for bit, and reliefkit's own mesh loader (trimesh underneath, an independent
reader) finds the fallback a viewer shows, with as many triangles as `fallback_mesh` has."""

from __future__ import annotations

import numpy as np
import pytest
from gltf_validator import problems, validate

import reliefkit as rk
from reliefkit.builtins import registry
from reliefkit.core.technique import bakers
from reliefkit.io.meshes import load_mesh as load_mesh_file

BAKES = {  # kind -> (asset, small bake parameters)
    "relief": ("vehicle", {"depth_res": 32, "color_res": 32}),
    "relief-frustum": ("vehicle", {"depth_res": 32, "color_res": 32}),
    "relief-cube": ("blob", {"depth_res": 32, "color_res": 32}),
    "billboard-cloud": ("tree", {}),
    "dmbbc": ("vehicle", {}),
    "shell-volume": ("torus", {"texture_size": (16, 16, 8)}),
    "depth-object": ("vehicle", {"res": 32}),
    "visual-hull": ("blob", {"res": 32}),
    "displacement": ("torus", {}),
    "octahedral-impostor": ("vehicle", {"grid": 6, "atlas_res": 192}),
}


def test_every_baker_is_covered():
    assert set(BAKES) == {name for name, (_, b) in bakers().items() if "mesh" in b.sources}


@pytest.mark.parametrize("kind", BAKES)
def test_a_demo_bake_exports_valid_gltf_that_reads_back(gl, tmp_path, kind):
    asset, params = BAKES[kind]
    rep = rk.bake(rk.load_mesh(f"demo:{asset}"), kind, **params)
    path = rk.export(rep, tmp_path / f"{kind}.glb", fallback_triangles=5000)
    assert problems(validate(path)) == []
    codec = registry().codecs().for_object(rep)
    (want, params_in), (got, params_out) = codec.to_arrays(rep), codec.to_arrays(rk.load(path))
    assert params_out == params_in
    assert all(np.asarray(got[k]).tobytes() == np.asarray(want[k]).tobytes()
               for k in want if want[k] is not None)
    shown = load_mesh_file(path)
    assert shown.triangle_count == rep.fallback_mesh(5000).triangle_count
