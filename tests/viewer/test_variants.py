"""The render options the page's controls are built from (inputs.json: every kind's own
declarations, nothing listed by hand), and the server's GLBs made with other options:
`input-K.glb?FLAG=VALUE` is the export with those options, and a value the CLI refuses is a
400 whose body is the CLI's one-line message."""

from __future__ import annotations

import json
import urllib.error
import urllib.request

import pytest
from browser import served
from helpers import run_cli, sample

from reliefkit import save
from reliefkit.core.technique import techniques
from reliefkit.export.gltf import export_bytes
from reliefkit.io.inputs import load_input
from reliefkit.render import render_options
from reliefkit.viewer.site import load_inputs, make_input, manifest
from reliefkit.viewer.variants import KEEP, Variants


def test_the_manifest_carries_each_kinds_render_options():
    objects = {"mesh": load_input("demo:cup")}
    objects.update({f"{tech.name}:{kind}": made for tech in techniques()
                    for kind, made in tech.samples().items()})
    for what, obj in objects.items():
        declared = render_options(obj)
        (entry,) = json.loads(json.dumps(manifest([make_input(what, obj)])))["inputs"]
        assert [o["flag"] for o in entry["options"]] == [o.flag for o in declared], what
        for got, opt in zip(entry["options"], declared, strict=True):
            choices = list(opt.choices) if opt.choices else None
            default = list(opt.default) if isinstance(opt.default, tuple) else opt.default
            assert (got["kind"], got["choices"], got["lo"], got["hi"], got["default"],
                    got["help"], got["value"]) == \
                (opt.kind, choices, opt.lo, opt.hi, default, opt.help, default), (what, opt)


def test_the_manifest_carries_the_values_the_glb_was_made_with():
    made = make_input("imp", sample("impostor", "octahedral-impostor"), {"parallax_steps": 3})
    options = {o["flag"]: o["value"] for o in manifest([made])["inputs"][0]["options"]}
    assert options["parallax-steps"] == 3 and options["shadows"] is False
    assert manifest([made], live=True)["live"] and not manifest([made])["live"]


def _get(url: str) -> tuple[int, bytes]:
    try:
        with urllib.request.urlopen(url) as response:
            return response.status, response.read()
    except urllib.error.HTTPError as error:
        return error.code, error.read()


@pytest.fixture(scope="module")
def relief_spec(tmp_path_factory):
    spec = tmp_path_factory.mktemp("inputs") / "relief.rk"
    save(spec, sample("relief", "relief"))
    return str(spec)


def test_a_glb_with_options_is_the_export_with_them(gl, relief_spec):
    inputs = load_inputs([relief_spec])
    obj = inputs[0].obj
    with served({"input-0.glb": inputs[0].glb}, Variants(inputs)) as (base, _):
        status, body = _get(f"{base}input-0.glb?method=binary&linear-steps=2&binary-steps=1")
        assert status == 200
        assert body == export_bytes(obj, fallback=False, embed_shaders=True, instrumented=True,
                                    options={"method": "binary", "linear_steps": 2,
                                             "binary_steps": 1})
        assert body != inputs[0].glb
        assert _get(f"{base}input-0.glb")[1] == inputs[0].glb  # no query: the file itself
        assert _get(f"{base}input-1.glb?method=exact")[0] == 404


@pytest.mark.parametrize("query, flags", [
    ("method=nope", ["--method", "nope"]),
    ("binary-steps=abc", ["--binary-steps", "abc"]),
    ("max-iterations=-1", ["--max-iterations", "-1"]),
    ("parallax-steps=2", ["--parallax-steps", "2"])])
def test_a_bad_value_is_a_400_with_the_clis_message(gl, relief_spec, query, flags):
    inputs = load_inputs([relief_spec])
    with served({}, Variants(inputs)) as (base, _):
        status, body = _get(f"{base}input-0.glb?{query}")
    # the CLI's refusal of the same value (view routes it to every input that declares it)
    cli = run_cli("view", relief_spec, "--no-browser", *flags)
    if flags[0] == "--parallax-steps":  # no input declares it: the CLI says so up front
        assert "applies to none of the inputs" in cli.stderr
        assert body.decode().startswith("error: --parallax-steps does not apply to")
    else:
        assert cli.returncode != 0
        assert body.decode() == cli.stderr.strip()
    assert status == 400


def test_the_exports_kept_are_bounded(gl, relief_spec):
    inputs = load_inputs([relief_spec])
    variants = Variants(inputs)
    made = [variants.answer("input-0.glb", f"binary-steps={n}&method=binary")
            for n in range(1, KEEP + 3)]
    assert len({*made}) == KEEP + 2
    assert variants.answer("input-0.glb", "binary-steps=1&method=binary") == made[0]
    assert variants.kept(0) == KEEP

