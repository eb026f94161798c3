"""docs/gltf.md is the specification a third party writes a loader from: every kind's
export validates against its JSON schemas (docs/schema/, checked by jsonschema, not by
reliefkit's reader), the schemas reject what the reader rejects, and the page names every
kind's extension and fallback."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from helpers import sample, technique_samples
from jsonschema import Draft202012Validator
from referencing import Registry, Resource

import reliefkit as rk
from reliefkit.builtins import registry
from reliefkit.io.gltf.representation import extension_name, read_document, reliefkit_nodes

pytestmark = pytest.mark.usefixtures("toy_registered")

DOCS = Path(__file__).resolve().parents[2] / "docs"
SCHEMAS = {p.name: json.loads(p.read_text()) for p in (DOCS / "schema").glob("*.json")}
REGISTRY = Registry().with_resources(
    (name, Resource.from_contents(schema)) for name, schema in SCHEMAS.items())
SAMPLES = technique_samples()


def validator(name: str) -> Draft202012Validator:
    return Draft202012Validator(SCHEMAS[name], registry=REGISTRY)



def test_the_schemas_are_valid_json_schemas():
    assert set(SCHEMAS) == {"RELIEFKIT_kind.schema.json", "typedArray.schema.json",
                            "encoding.schema.json", "draw.schema.json",
                            "extras.reliefkit.schema.json"}
    for schema in SCHEMAS.values():
        Draft202012Validator.check_schema(schema)


@pytest.mark.parametrize("tech_kind", SAMPLES, ids=[f"{t}:{k}" for t, k in SAMPLES])
def test_every_kinds_export_validates_against_the_schemas(tmp_path, tech_kind):
    path = rk.export(sample(*tech_kind), tmp_path / "x.glb", embed_shaders=True,
                     fallback=False, cache_key="5" * 64)
    document = read_document(path).document
    ((index, name, extension),) = reliefkit_nodes(document)
    errors = [e.message for e in validator("RELIEFKIT_kind.schema.json").iter_errors(extension)]
    assert errors == []
    extras = document["nodes"][index]["extras"]["reliefkit"]
    assert [e.message for e in validator("extras.reliefkit.schema.json").iter_errors(extras)] \
        == []


def test_the_schemas_reject_what_the_reader_rejects():
    typed = validator("typedArray.schema.json")
    good = {"dtype": "float32", "shape": [2, 3], "sha256": "0" * 64, "bufferView": 1}
    assert typed.is_valid(good)
    for bad in ({**good, "image": 0}, {**good, "dtype": "object"}, {**good, "shape": [-1]},
                {**good, "sha256": "xyz"}, {**good, "extra": 1},
                {k: v for k, v in good.items() if k != "shape"}):
        assert not typed.is_valid(bad), bad
    extension = validator("RELIEFKIT_kind.schema.json")
    assert not extension.is_valid({"kind": "relief", "kindVersion": 0, "params": {},
                                   "arrays": {}})
    assert not extension.is_valid({"kind": "relief", "kindVersion": 1, "params": {},
                                   "arrays": {"bad name": good}})


def test_the_page_names_every_kinds_extension_and_fallback():
    import toy_technique

    text = (DOCS / "gltf.md").read_text()
    fallbacks = text[text.index("## What a viewer shows"):text.index("## Document structure")]
    for kind in set(registry().codecs().kinds) - set(toy_technique.TECHNIQUE.kinds):
        assert f"`{kind}`" in fallbacks, kind
    for name in ("RELIEFKIT_relief_object", "RELIEFKIT_billboard_cloud",
                 "RELIEFKIT_octahedral_impostor"):
        assert name in text
        assert extension_name(name[len("RELIEFKIT_"):].replace("_", "-")) == name
