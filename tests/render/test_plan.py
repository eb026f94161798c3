"""Draw plans are plain data: every sample of every technique (and the mesh) describes its
draws as plans that serialize to JSON plus named arrays and back without loss, and the
plans read back draw the same Frame."""

from __future__ import annotations

import json

import numpy as np
import pytest
from helpers import frame_of_plans, sample, sample_ids, technique_samples

from reliefkit.render import render
from reliefkit.render.executor import Executor
from reliefkit.render.plan import DrawPlan, ViewHook, from_json, to_json
from reliefkit.render.registry import make_drawables
from reliefkit.scene.assets import make_asset
from reliefkit.scene.light import DirectionalLight
from reliefkit.scene.views import orbit_bounds

pytestmark = pytest.mark.usefixtures("toy_registered")

SAMPLES = technique_samples()
IDS = sample_ids(SAMPLES)



def _objects():
    return [*(sample(*tk) for tk in SAMPLES), make_asset("tree")]


def _same(a, b, where: str) -> None:
    """Equal values of the same types, arrays bit-identical with the same dtype."""
    assert type(a) is type(b), f"{where}: {type(a).__name__} != {type(b).__name__}"
    if isinstance(a, np.ndarray):
        assert a.dtype == b.dtype and a.shape == b.shape, where
        np.testing.assert_array_equal(a, b, err_msg=where)
    elif isinstance(a, dict):
        assert a.keys() == b.keys(), where
        for key in a:
            _same(a[key], b[key], f"{where}.{key}")
    elif isinstance(a, list | tuple):
        assert len(a) == len(b), where
        for k, (x, y) in enumerate(zip(a, b, strict=True)):
            _same(x, y, f"{where}[{k}]")
    elif hasattr(a, "__dataclass_fields__"):
        for name in a.__dataclass_fields__:
            _same(getattr(a, name), getattr(b, name), f"{where}.{name}")
    else:
        assert a == b, f"{where}: {a!r} != {b!r}"


def _round_trip(plans):
    doc, arrays = to_json(plans)
    text = json.dumps(doc)  # strict JSON: no arrays or objects left in the document
    return from_json(json.loads(text), {k: v.copy() for k, v in arrays.items()})


@pytest.mark.parametrize("obj", _objects(), ids=[*IDS, "mesh:tree"])
def test_every_drawable_describes_its_draws_as_plans_that_round_trip(gl, obj):
    (drawable,) = make_drawables([obj], {})
    assert drawable.plans and all(isinstance(p, DrawPlan) for p in drawable.plans)
    back = _round_trip(drawable.plans)
    for k, (plan, read) in enumerate(zip(drawable.plans, back, strict=True)):
        _same(plan, read, f"plan {k}")


def test_shared_arrays_and_textures_stay_shared(gl):
    mesh = make_asset("vehicle")
    (drawable,) = make_drawables([mesh], {})
    back = _round_trip(drawable.plans)
    assert len({id(p.geometry) for p in back}) == len({id(p.geometry) for p in drawable.plans})
    doc, arrays = to_json(drawable.plans)
    positions = drawable.plans[0].geometry.attributes["in_position"].array
    assert sum(a is positions for a in arrays.values()) == 1


@pytest.mark.parametrize("tech_kind", SAMPLES, ids=IDS)
def test_plans_read_back_draw_the_same_frame(gl, tech_kind):
    rep = sample(*tech_kind)
    camera = orbit_bounds(rep.bounds, 30.0, 35.0, 2.4, size=(48, 40))
    light = DirectionalLight()
    (drawable,) = make_drawables([rep], {})
    expected = render(rep, camera, light=light)
    frame = frame_of_plans(gl, rep, drawable, _round_trip(drawable.plans), camera, light)
    np.testing.assert_array_equal(frame.color, expected.color)
    np.testing.assert_array_equal(frame.depth, expected.depth)


def test_a_view_hook_names_only_reliefkit_functions():
    hook = ViewHook("os:system", {"command": "true"})
    with pytest.raises(ValueError, match="not a reliefkit function"):
        hook(None, None, None)


def test_executor_uploads_shared_textures_once(gl):
    mesh = make_asset("vehicle")
    (drawable,) = make_drawables([mesh], {})
    executor = Executor(gl)
    try:
        executor.upload(drawable.plans)
        textures = {id(t) for p in drawable.plans for t in p.textures.values()}
        geometries = {id(p.geometry) for p in drawable.plans}
        assert len(executor._textures) == len(textures)
        assert len(executor._geometry) == len(geometries)
    finally:
        executor.release()
