"""Every registered kind (and the toy technique's) through glTF: export -> load is the same
representation array for array, bit for bit, drawing bit-identical frames; pygltflib (not
the writer's code) finds the arrays and the draw plans' geometry where the extension says;
the draw plans read back draw the frame the representation draws; the Khronos validator
reports no error and no warning. New techniques get these free."""

from __future__ import annotations

import hashlib
import io

import numpy as np
import pygltflib
import pytest
from gltf_validator import problems, validate
from helpers import frame_of_plans, sample, sample_ids, technique_samples
from PIL import Image

import reliefkit as rk
from reliefkit.builtins import registry
from reliefkit.compact.encodings import encoding_of
from reliefkit.export.draw import read_plans
from reliefkit.io.gltf.representation import extension_name, read_document, reliefkit_nodes
from reliefkit.render.registry import make_drawables
from reliefkit.scene.light import DirectionalLight
from reliefkit.scene.views import orbit_bounds

pytestmark = pytest.mark.usefixtures("toy_registered")

SAMPLES = technique_samples()
IDS = sample_ids(SAMPLES)



def stored_arrays(rep) -> dict:
    """What a container stores of each array: the array, or its encoding's blocks."""
    arrays, _ = registry().codecs().for_object(rep).to_arrays(rep)
    out = {}
    for name, value in arrays.items():
        if value is None:
            continue
        encoded = encoding_of(value)
        out[name] = np.asarray(value) if encoded is None else encoded.data
    return out


@pytest.fixture(params=SAMPLES, ids=IDS, scope="module")
def exported(request, tmp_path_factory):
    tech, kind = request.param
    rep = sample(tech, kind)
    path = tmp_path_factory.mktemp(kind) / f"{kind}.glb"
    rk.export(rep, path, embed_shaders=True)
    return kind, rep, path


def test_load_gives_the_same_arrays_bit_for_bit(exported):
    kind, rep, path = exported
    back = rk.load(path)
    assert type(back) is type(rep)
    want, got = stored_arrays(rep), stored_arrays(back)
    assert set(got) == set(want)
    for name, array in want.items():
        assert got[name].dtype == array.dtype and got[name].shape == array.shape, name
        assert got[name].tobytes() == array.tobytes(), name
    _, params = registry().codecs().for_object(rep).to_arrays(rep)
    assert registry().codecs().for_object(back).to_arrays(back)[1] == params


def test_loaded_representation_draws_bit_identical_frames(gl, exported):
    kind, rep, path = exported
    back = rk.load(path)
    camera = orbit_bounds(rep.bounds, 30.0, 35.0, 2.4, size=(48, 40))
    want, got = rk.render(rep, camera), rk.render(back, camera)
    np.testing.assert_array_equal(got.color, want.color)
    np.testing.assert_array_equal(got.depth, want.depth)


def test_the_draw_plans_read_back_draw_the_same_frame(gl, exported):
    kind, rep, path = exported
    glb = read_document(path)
    ((node, name, extension),) = reliefkit_nodes(glb.document)
    assert name == extension_name(kind)
    plans = read_plans(glb, extension["draw"])
    camera = orbit_bounds(rep.bounds, 30.0, 35.0, 2.4, size=(48, 40))
    light = DirectionalLight()
    (drawable,) = make_drawables([rep], {})
    expected = rk.render(rep, camera, light=light)
    frame = frame_of_plans(gl, rep, drawable, plans, camera, light)
    np.testing.assert_array_equal(frame.color, expected.color)


def _view_bytes(gltf: pygltflib.GLTF2, blob: bytes, index: int) -> bytes:
    view = gltf.bufferViews[index]
    return blob[view.byteOffset or 0:(view.byteOffset or 0) + view.byteLength]


def test_pygltflib_finds_every_array_where_the_extension_says(exported):
    kind, rep, path = exported
    gltf = pygltflib.GLTF2().load(str(path))
    blob = gltf.binary_blob()
    assert gltf.asset.generator.startswith("reliefkit ")
    name = extension_name(kind)
    assert name in gltf.extensionsUsed and name not in (gltf.extensionsRequired or [])
    (node,) = [n for n in gltf.nodes if n.extensions and name in n.extensions]
    extension = node.extensions[name]
    assert node.extras["reliefkit"]["kind"] == kind
    for array_name, array in stored_arrays(rep).items():
        ref = extension["arrays"][array_name]
        assert ref["shape"] == list(array.shape) and ref["dtype"] == array.dtype.name
        if "image" in ref:
            data = _view_bytes(gltf, blob, gltf.images[ref["image"]].bufferView)
            pixels = np.asarray(Image.open(io.BytesIO(data)))
            assert pixels.tobytes() == array.tobytes(), array_name
        elif array.size:
            assert _view_bytes(gltf, blob, ref["bufferView"]) == array.tobytes(), array_name
        assert ref["sha256"] == hashlib.sha256(array.tobytes()).hexdigest()
    (drawable,) = make_drawables([rep], {})
    draw = extension["draw"]
    for geometry in draw["geometries"].values():
        for attribute in geometry["attributes"].values():
            ref = draw["arrays"][attribute["tuple"][0]["array"]]
            if ref["dtype"] not in ("float32", "uint8", "uint16", "uint32", "int8", "int16"):
                assert "accessor" not in ref  # int32: no glTF component type
                continue
            accessor = gltf.accessors[ref["accessor"]]
            values = np.frombuffer(_view_bytes(gltf, blob, accessor.bufferView), ref["dtype"])
            assert accessor.count == ref["shape"][0]
            assert values.tobytes() == _view_bytes(gltf, blob, ref["bufferView"])
    programs = {p["program"] for p in draw["programs"]}
    assert programs >= {p.program.name for p in drawable.plans}
    assert all(p["fragment"].startswith("#version 300 es") for p in draw["programs"])


def test_the_khronos_validator_reports_no_error_and_no_warning(exported):
    kind, rep, path = exported
    report = validate(path)
    assert problems(report) == [], problems(report)
