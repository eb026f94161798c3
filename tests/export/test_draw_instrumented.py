"""The iteration-counting plans in an export (`draw.instrumented`, what the viewer's heat map
draws): they read back as the instrumented drawable's plans, only for kinds that count loop
iterations, only when asked, validate against the schema and share the plain plans' arrays."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from helpers import sample
from jsonschema import Draft202012Validator
from referencing import Registry, Resource

from reliefkit.export.draw import read_plans
from reliefkit.export.gltf import export_bytes
from reliefkit.io.gltf.glb import read_glb
from reliefkit.render.plan import to_json
from reliefkit.render.registry import make_drawables

SCHEMAS = Path(__file__).resolve().parents[2] / "docs" / "schema"


def _draw(data: bytes, tmp_path) -> tuple:
    (tmp_path / "x.glb").write_bytes(data)
    glb = read_glb(tmp_path / "x.glb")
    ((extension,),) = [list(n["extensions"].values()) for n in glb.document["nodes"]
                       if "extensions" in n]
    return glb, extension["draw"]


def _resolved(plans) -> list:
    """`to_json`'s document of ``plans`` with each geometry, texture and array in place of
    its key (so the order the records were met in does not matter)."""
    document, arrays = to_json(plans)

    def resolve(value, records=None):
        if isinstance(value, dict):
            if set(value) == {"array"} and isinstance(value["array"], str):
                a = arrays[value["array"]]
                return [a.dtype.str, list(a.shape), a.tobytes().hex()]
            return {k: resolve(v) for k, v in value.items()}
        if isinstance(value, list):
            return [resolve(v) for v in value]
        return value

    out = []
    for plan in document["plans"]:
        plan = dict(plan)
        plan["geometry"] = resolve(document["geometries"][plan["geometry"]])
        plan["textures"] = {n: resolve(document["textures"][k])
                            for n, k in plan["textures"].items()}
        out.append(resolve(plan))
    return out


def _same_plans(got, want) -> None:
    assert _resolved(got) == _resolved(want)


@pytest.mark.parametrize("kind", [("relief", "relief"), ("slicing", "depth-object")],
                         ids=lambda k: k[1])
def test_the_instrumented_plans_read_back(tmp_path, kind):
    rep = sample(*kind)
    glb, draw = _draw(export_bytes(rep, fallback=False, embed_shaders=True,
                                   instrumented=True), tmp_path)
    (counting,) = make_drawables([rep], {}, instrument=True)
    (plain,) = make_drawables([rep], {})
    _same_plans(read_plans(glb, draw["instrumented"], "draw.instrumented"), counting.plans)
    _same_plans(read_plans(glb, draw), plain.plans)  # the plain plans unchanged
    assert all(p["defines"].get("COUNT_ITERATIONS") for p in draw["instrumented"]["programs"])
    schemas = {p.name: json.loads(p.read_text()) for p in SCHEMAS.glob("*.json")}
    registry = Registry().with_resources((n, Resource.from_contents(s))
                                         for n, s in schemas.items())
    validator = Draft202012Validator(schemas["draw.schema.json"], registry=registry)
    assert [e.message for e in validator.iter_errors(draw)] == []
    # arrays equal to the plain plans' are stored once: the same bufferViews
    views = {json.dumps(ref, sort_keys=True) for ref in draw["arrays"].values()}
    assert any(json.dumps(ref, sort_keys=True) in views
               for ref in draw["instrumented"]["arrays"].values())


def test_only_when_asked_and_only_kinds_that_count(tmp_path):
    relief = sample("relief", "relief")
    assert "instrumented" not in _draw(export_bytes(relief, fallback=False), tmp_path)[1]
    from reliefkit.io.inputs import load_input

    for rep in (sample("billboard", "billboard-cloud"), load_input("demo:cup")):  # no loop
        data = export_bytes(rep, fallback=False, instrumented=True)
        assert "instrumented" not in _draw(data, tmp_path)[1]
