"""The core's `mesh` kind: every material kept bit for bit, version 1 files still read, and
forged material data refused with one FormatError line."""

from __future__ import annotations

import hashlib
import io
import json
import zipfile

import numpy as np
import pytest
from helpers import assert_same_mesh
from numpy.lib import format as npy

from reliefkit.builtins import registry
from reliefkit.errors import FormatError
from reliefkit.io import rk
from reliefkit.io.mesh_codec import MAX_TEXTURED
from reliefkit.scene.mesh import Material, RenderMesh


def quads(count: int) -> dict:
    """`count` unit quads side by side: the arrays of a RenderMesh, without materials."""
    rng = np.random.default_rng(count)
    corners = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], np.float32)
    positions = np.concatenate([corners + [2.0 * k, 0, 0] for k in range(count)])
    indices = np.concatenate([np.array([[0, 1, 2], [0, 2, 3]]) + 4 * k for k in range(count)])
    return {"positions": positions, "indices": indices,
            "normals": np.tile(np.float32([0, 0, 1]), (len(positions), 1)),
            "colors": rng.random((len(positions), 4), dtype=np.float32),
            "uvs": rng.random((len(positions), 2), dtype=np.float32)}


def three_materials() -> RenderMesh:
    rng = np.random.default_rng(3)
    materials = [
        Material("bricks", (1.0, 0.5, 0.25, 1.0), rng.integers(0, 256, (8, 16, 4), np.uint8)),
        Material("paint", (0.2, 0.4, 0.6, 0.5)),
        Material("", (1.0, 1.0, 1.0, 1.0), rng.integers(0, 256, (4, 4, 4), np.uint8),
                 uv_transform=[[2.0, 0, 0.5], [0, 2.0, 0.25], [0, 0, 1]]),
    ]
    return RenderMesh(**quads(3), name="three", materials=materials, material=[0, 0, 1, 1, 2, 0])


def test_several_materials_round_trip_bit_exact(tmp_path):
    mesh = three_materials()
    back = rk.load(rk.save(tmp_path / "m.rk", mesh))
    assert_same_mesh(mesh, back)
    assert back.materials[2].uv_transform is not None and back.materials[1].texture is None


def test_arrays_and_params_of_a_multi_material_file(tmp_path):
    manifest = rk.read_manifest(rk.save(tmp_path / "m.rk", three_materials()))
    assert manifest["kind_version"] == 3
    assert manifest["params"] == {"name": "three", "materials": ["bricks", "paint", ""]}
    arrays = manifest["arrays"]
    assert {"material", "material_colors", "uv_transforms", "texture", "texture_2"} <= set(arrays)
    assert "texture_1" not in arrays
    assert (arrays["material"]["dtype"], arrays["material"]["shape"]) == ("<u2", [6])


def test_a_one_material_mesh_keeps_the_arrays_of_version_1(tmp_path):
    texture = np.random.default_rng(0).integers(0, 256, (8, 8, 4), np.uint8)
    mesh = RenderMesh(**quads(1), texture=texture, name="one")
    path = rk.save(tmp_path / "one.rk", mesh)
    assert set(rk.read_manifest(path)["arrays"]) == {"positions", "indices", "normals",
                                                      "colors", "uvs", "texture"}
    assert_same_mesh(mesh, rk.load(path))


def version_1_file(path, arrays: dict, params: dict) -> None:
    """A mesh .rk as version 1 of the kind wrote it: stored .npy members and a manifest."""
    members, entries = {}, {}
    for name, arr in arrays.items():
        bio = io.BytesIO()
        npy.write_array(bio, arr, allow_pickle=False)
        members[f"{name}.npy"] = bio.getvalue()
        entries[name] = {"dtype": arr.dtype.str, "shape": list(arr.shape),
                         "sha256": hashlib.sha256(bio.getvalue()).hexdigest()}
    manifest = {"format": "reliefkit", "format_version": 1, "kind": "mesh", "kind_version": 1,
                "params": params, "source_hash": None, "created_by": "reliefkit 0.1.0",
                "arrays": entries}
    with zipfile.ZipFile(path, "w", zipfile.ZIP_STORED) as zf:
        for name, data in members.items():
            zf.writestr(name, data)
        zf.writestr("manifest.json", json.dumps(manifest))


def test_a_version_1_file_loads_as_one_material(tmp_path):
    arrays = {k: np.asarray(v, np.uint32 if k == "indices" else np.float32)
              for k, v in quads(2).items()}
    arrays["texture"] = np.random.default_rng(1).integers(0, 256, (4, 8, 4), np.uint8)
    path = tmp_path / "old.rk"
    version_1_file(path, arrays, {"name": "old"})
    mesh = rk.load(path)
    assert mesh.name == "old" and len(mesh.materials) == 1
    np.testing.assert_array_equal(mesh.texture, arrays["texture"])
    np.testing.assert_array_equal(mesh.materials[0].color, 1.0)
    np.testing.assert_array_equal(mesh.material, 0)
    np.testing.assert_array_equal(mesh.colors, arrays["colors"])


def test_too_many_textured_materials_cannot_be_saved(tmp_path):
    count = MAX_TEXTURED + 1
    texture = np.zeros((1, 1, 4), np.uint8)
    mesh = RenderMesh(**quads(count), materials=[Material(texture=texture)] * count,
                      material=np.repeat(np.arange(count), 2))
    with pytest.raises(FormatError, match=f"first {MAX_TEXTURED} materials"):
        rk.save(tmp_path / "many.rk", mesh)


def forged(tmp_path, **changes):
    """A multi-material file whose arrays or params are changed after a valid write."""
    mesh = three_materials()
    codec = registry().codecs().for_object(mesh)  # forging needs the codec's arrays
    arrays, params = codec.to_arrays(mesh)
    arrays = {k: v for k, v in arrays.items() if v is not None}
    for name, value in changes.items():
        if name == "params":
            params = {**params, **value}
        elif value is None:
            del arrays[name]
        else:
            arrays[name] = value
    return rk.write_rk(tmp_path / "forged.rk", "mesh", arrays, params)


FORGERIES = {
    "index_out_of_range": ({"material": np.array([0, 0, 1, 1, 3, 0], np.uint16)},
                           "material index 3 out of range for 3 materials"),
    "too_few_indices": ({"material": np.zeros(5, np.uint16)}, "one per triangle"),
    "indices_missing": ({"material": None}, "need per-triangle material indices"),
    "texture_of_no_material": ({"texture_7": np.zeros((1, 1, 4), np.uint8)},
                               "texture_7' belongs to material 7"),
    "names_mismatch": ({"params": {"materials": ["a"]}}, "3 material colours but 1 names"),
    "names_not_strings": ({"params": {"materials": [1, 2, 3]}}, "list of material names"),
    "transforms_mismatch": ({"uv_transforms": np.tile(np.eye(3, dtype=np.float32), (2, 1, 1))},
                            "but 2 uv_transforms"),
    "transform_not_affine": ({"uv_transforms": np.ones((3, 3, 3), np.float32)}, "affine"),
    "colour_out_of_range": ({"material_colors": np.full((3, 4), 2.0, np.float32)},
                            r"\[0, 1\]"),
}


@pytest.mark.parametrize("case", FORGERIES)
def test_forged_material_data_is_refused(tmp_path, case):
    changes, pattern = FORGERIES[case]
    path = forged(tmp_path, **changes)
    with pytest.raises(FormatError, match=pattern) as info:
        rk.load(path)
    assert "\n" not in str(info.value) and str(path) in str(info.value)
