"""The technique registry and typed options: what exists, duplicates refused, options routed."""

from __future__ import annotations

import dataclasses
import subprocess
import sys

import numpy as np
import pytest
from helpers import toy_technique

from reliefkit.bench import suites
from reliefkit.builtins import registry
from reliefkit.core import params
from reliefkit.core.params import param
from reliefkit.core.technique import (
    Baker,
    Technique,
    bakers,
    register,
    technique,
    technique_of,
)
from reliefkit.errors import UsageError
from reliefkit.scene.assets import make_asset

FRESH = ("import sys, reliefkit as rk; from reliefkit.core.technique import REGISTRY; "
         "path = rk.save(sys.argv[1], rk.load_mesh('demo:blob')); "
         "print(type(rk.load(path)).__name__); print(','.join(REGISTRY.codecs().kinds)); "
         "print(','.join(t.name for t in REGISTRY.techniques()))")


def test_the_public_api_registers_the_builtins_in_a_fresh_process(tmp_path):
    out = subprocess.run([sys.executable, "-c", FRESH, str(tmp_path / "m.rk")],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    loaded, kinds, names = out.stdout.split()
    assert loaded == "RenderMesh"
    import reliefkit.techniques as builtin

    expected = {"mesh"} | {k for t in builtin.TECHNIQUES for k in t.kinds}
    assert set(kinds.split(",")) == expected
    assert names.split(",") == [t.name for t in builtin.TECHNIQUES]


def test_the_builtins_are_registered_once():
    first = registry().techniques()
    assert registry().techniques() == first and len({t.name for t in first}) == len(first)


def test_duplicates_are_refused():
    relief = technique("relief")
    with pytest.raises(UsageError, match="already registered"):
        register(relief)
    taken_kind = dataclasses.replace(relief, name="copycat", bakers=(), bench_suites=(),
                                     representations=(), drawables=())
    with pytest.raises(UsageError, match="kind 'relief' is already registered"):
        register(taken_kind)
    taken_baker = dataclasses.replace(relief, name="copycat", codecs=(), bench_suites=(),
                                      representations=(), drawables=())
    with pytest.raises(UsageError, match="baker 'relief' is already registered"):
        register(taken_baker)
    assert "copycat" not in {t.name for t in registry().techniques()}
    assert "copycat" not in registry().codecs().kinds


def test_conflicting_flag_kinds_are_refused():
    @dataclasses.dataclass(frozen=True)
    class Clash:
        depth_res: str = param("high", "a string where relief has an int")

    clash = Technique("clash", "a clash", __name__,
                      bakers=(Baker("clash", "clash", Clash, lambda s, p, g: None),))
    with pytest.raises(UsageError, match="--depth-res is a str .* but a int"):
        register(clash)
    assert "clash" not in bakers()


def test_toy_plugs_in_and_out_without_touching_the_core():
    with toy_technique() as toy:
        assert "toy-quad" in registry().codecs().kinds and "toy-quad" in bakers()
        assert "toy" in suites()
        quad = toy.TECHNIQUE.samples()["toy-quad"]
        assert technique_of(quad).name == "toy"
    assert "toy-quad" not in registry().codecs().kinds and "toy-quad" not in bakers()


def test_bake_validates_its_typed_parameters():
    from reliefkit.bake import bake

    mesh = make_asset("blob")
    with pytest.raises(UsageError, match=r"unknown option\(s\) spread .*it has: depth_res"):
        bake(mesh, "relief", spread=30.0)
    with pytest.raises(UsageError, match="depth-res must be within \\[8, 8192\\]"):
        bake(mesh, "relief", depth_res=4)
    with pytest.raises(UsageError, match="axis must be one of"):
        bake(mesh, "relief", axis="w")
    with pytest.raises(UsageError, match="unknown representation 'voxels'"):
        bake(mesh, "voxels")
    with pytest.raises(UsageError, match="bakes a mesh, not a heightmap"):
        bake(np.zeros((8, 8)), "relief-cube")


def test_params_check_every_kind():
    @dataclasses.dataclass(frozen=True)
    class P:
        n: int = param(3, "n", lo=1, hi=5)
        x: float = param(0.5, "x", lo=0.0)
        flag: bool = param(False, "flag")
        name: str = param("a", "name", choices=("a", "b"))
        size: tuple = param((1.0, 2.0, 3.0), "size", kind="floats", count=3, lo=0.0)
        maybe: int | None = param(None, "maybe", kind="int")

    assert params.make(P, {"n": "4", "x": "2", "size": "1,2,3.5"}, "t") == \
        P(n=4, x=2.0, size=(1.0, 2.0, 3.5))
    assert params.make(P, {"maybe": None}, "t").maybe is None
    for values, message in (({"n": 9}, "within"), ({"n": 2.5}, "must be an integer"),
                            ({"x": "nan"}, "must be a number"), ({"flag": "yes"}, "true or false"),
                            ({"name": "c"}, "one of a, b"), ({"size": "1,2"}, "3 comma"),
                            ({"size": "1,-2,3"}, "within"), ({"q": 1}, "unknown option")):
        with pytest.raises(UsageError, match=message):
            params.make(P, values, "t")
    with pytest.raises(TypeError, match="not declared with param"):
        params.options_of(dataclasses.make_dataclass("Q", [("a", int, 1)]))
