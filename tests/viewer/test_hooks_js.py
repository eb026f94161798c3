"""The JavaScript view hooks (web/src/hooks/) against the Python ones they port: every
kind's sample, its drawable's plans (default options and the options that change the hook's
work), several cameras (perspective and orthographic, outside and inside the object,
grazing a face), each plan's Python hook and its JavaScript port run through
tools/viewer/run_hook.mjs (one node process for the module). Integer arrays and orders are
equal exactly, strings and counts too; floats within 1e-5 of the array's largest magnitude
(the ports compute in float64 as the Python does; the matrix inverses differ in rounding).
The SXMPVO port's order satisfies every pixel ray of a torus shell at 12 views, by the
checker the Python sort is tested with (`order_check.ordering_violations`)."""

from __future__ import annotations

import json
import re
from dataclasses import fields

import numpy as np
import pytest
from helpers import sample, sample_ids, technique_samples
from node_tools import ROOT, NodeScript, unwire, wire
from shell_scenes import torus_mesh

from reliefkit.render.instancing import instanced, placements
from reliefkit.render.plan import Attribute, DrawPlan, Geometry, Program, ViewHook, to_json
from reliefkit.render.registry import make_drawables
from reliefkit.scene.camera import Camera
from reliefkit.scene.light import DirectionalLight
from reliefkit.techniques.shellvolume.order import order_cells
from reliefkit.techniques.shellvolume.order_check import ordering_violations
from reliefkit.techniques.shellvolume.shell import build_shell

pytestmark = pytest.mark.usefixtures("toy_registered")

SCRIPT = ROOT / "tools" / "viewer" / "run_hook.mjs"
RTOL = 1e-5
#: Statistics that are measured, not computed (the sort's wall time).
MEASURED = {"sort_seconds"}
#: Per kind, the render options besides the defaults whose hooks compute other things.
OPTIONS = {
    "dmbbc": [{"lod": "auto"}, {"flatten": 0.4}],
    "shell-volume": [{"sort": "centroid"}],
    "depth-object": [{"slicing": "orthogonal"}, {"slicing": "screen"},
                     {"slicing": "screen", "passes": "stencil"},
                     {"slicing": "orthogonal", "slices": 7}],
    "visual-hull": [{"slicing": "screen", "alpha_test": "point"}],
    "displacement": [{"slicing": "surface"}, {"slicing": "screen"},
                     {"slicing": "orthogonal", "slices": 5}],
}
#: The largest difference seen per hook (printed with -s: the report's figures).
LARGEST: dict[str, float] = {}


class NodeHooks(NodeScript):
    """tools/viewer/run_hook.mjs in one node process: `load` plans, `call` a plan's hook."""

    def __init__(self):
        super().__init__("the JavaScript view hooks", SCRIPT)

    def load(self, plans) -> None:
        doc, arrays = to_json(plans)
        self.ask({"load": {"doc": doc, "arrays": {k: wire(a) for k, a in arrays.items()}}})

    def names(self) -> list[str]:
        return self.ask({"names": True})["names"]

    def call(self, index: int, camera, light) -> dict:
        return unwire(self.ask({"call": {"plan": index, "camera": camera_json(camera),
                                         "light": light_json(light)}})["update"])


@pytest.fixture(scope="module")
def node_hooks():
    hooks = NodeHooks()
    yield hooks
    hooks.close()
    print("\nlargest difference per hook:", json.dumps(LARGEST, indent=1))


def camera_json(camera: Camera) -> dict:
    """The JS camera (web/src/hooks/README.md): matrices as 16 row-major numbers."""
    return {"eye": list(camera.eye), "target": list(camera.target), "up": list(camera.up),
            "fov_deg": camera.fov_deg, "size": list(camera.size), "near": camera.near,
            "far": camera.far, "ortho_height": camera.ortho_height,
            "origin": [float(x) for x in camera.origin],
            "view": [float(x) for x in np.asarray(camera.view).ravel()],
            "proj": [float(x) for x in np.asarray(camera.proj).ravel()]}


def light_json(light: DirectionalLight) -> dict:
    return {"direction": list(light.direction), "color": list(light.color),
            "intensity": light.intensity, "ambient": light.ambient}


def cameras(bounds) -> list[tuple[str, Camera]]:
    """Named views of the object in ``bounds``: perspective and orthographic from outside,
    both from inside, grazing its top face, from far away."""
    lo, hi = np.asarray(bounds, np.float64)
    centre, radius = 0.5 * (lo + hi), 0.5 * float(np.linalg.norm(hi - lo)) or 1.0
    size = (96, 64)
    inside_eye = centre + radius * np.array([0.11, 0.07, -0.05])
    graze = np.array([centre[0], hi[1], centre[2]])
    out = [
        ("perspective", Camera.orbit(centre, 30, 20, 3 * radius, size=size)),
        ("perspective-low", Camera.orbit(centre, 200, -35, 2.5 * radius, 55, size=size)),
        ("orthographic", Camera.orbit(centre, 75, 40, 3 * radius, size=size,
                                      ortho_height=1.2 * radius)),
        ("inside", Camera(tuple(inside_eye), tuple(centre + [radius, 0.2 * radius, 0.0]),
                          fov_deg=70, size=size, near=0.01 * radius, far=10 * radius)),
        ("inside-ortho", Camera(tuple(inside_eye), tuple(centre + [0.0, 0.0, radius]),
                                size=size, near=0.01 * radius, far=10 * radius,
                                ortho_height=radius)),
        ("grazing", Camera(tuple(graze + [3 * radius, 0.0, 1e-3 * radius]), tuple(graze),
                           size=size, near=0.01 * radius, far=10 * radius)),
        ("far", Camera.orbit(centre, 310, 10, 400 * radius, 2, size=size)),
    ]
    return out


def python_update(plan, camera, light) -> dict:
    """The Python hook's `ViewUpdate` as the JS form: empty and None fields left out."""
    update = plan.per_view(plan, camera, light)
    out = {}
    for f in fields(update):
        value = getattr(update, f.name)
        if value is None or (isinstance(value, dict) and not value):
            continue
        out[f.name] = value
    return out


def compare(python, js, where: str, hook: str) -> None:
    """Assert ``js`` equals ``python`` (module docstring), noting the largest float
    difference under ``hook``."""
    if isinstance(python, dict):
        python = {k: v for k, v in python.items() if k not in MEASURED}
        js = {k: v for k, v in js.items() if k not in MEASURED}
        assert sorted(python) == sorted(js), f"{where}: keys {sorted(python)} != {sorted(js)}"
        for k in python:
            compare(python[k], js[k], f"{where}.{k}", hook)
        return
    if isinstance(python, str | bool) or python is None:
        assert python == js, f"{where}: {python!r} != {js!r}"
        return
    a = np.asarray(python)
    b = np.asarray(js)
    assert a.shape == b.shape, f"{where}: shape {a.shape} != {b.shape}"
    if a.dtype.kind in "iub" and (b.dtype.kind in "iub" or not b.size):
        assert np.array_equal(a, b), f"{where}: integers differ at {np.argwhere(a != b)[:5]}"
        return
    a, b = a.astype(np.float64), b.astype(np.float64)
    if not a.size:
        return
    assert np.isfinite(a).all() == np.isfinite(b).all(), f"{where}: non-finite values"
    scale = float(np.abs(a).max()) or 1.0
    diff = float(np.abs(a - b).max()) / scale
    LARGEST[hook] = max(LARGEST.get(hook, 0.0), diff)
    assert diff <= RTOL, f"{where}: largest difference {diff:.3g} of {scale:.3g}"


def flattening_cameras(plans, bounds) -> list[tuple[str, Camera]]:
    """With lod auto, views from within the DMBBC's flattening range (§3.4.2): between
    ``transition`` times the distance where epsilon is one pixel and that distance."""
    lods = [p.per_view.data["lod"] for p in plans
            if p.per_view is not None and p.per_view.data.get("lod")]
    if not lods:
        return []
    lod, fov, size = lods[0], 40.0, (96, 64)
    switch = lod["epsilon"] * size[1] / (2.0 * np.tan(np.radians(fov) / 2))
    return [(f"flattening {f:.2f}", Camera.orbit(lod["center"], 40 * k, 15, f * switch, fov,
                                                 size=size))
            for k, f in enumerate(np.linspace(lod["transition"], 1.0, 5)[1:-1])]


def check_plans(node_hooks, plans, bounds, where: str) -> int:
    """Compare every hooked plan of ``plans`` from every camera; how many calls."""
    node_hooks.load(plans)
    light = DirectionalLight()
    calls = 0
    for name, camera in cameras(bounds) + flattening_cameras(plans, bounds):
        for index, plan in enumerate(plans):
            if plan.per_view is None:
                continue
            hook = plan.per_view.function
            if hook.endswith(":instanced_view"):
                hook = f"instanced({plan.per_view.data['hook']})"
            compare(python_update(plan, camera, light), node_hooks.call(index, camera, light),
                    f"{where} {plan.name} from {name}", hook)
            calls += 1
    return calls


SAMPLES = technique_samples()


@pytest.mark.parametrize(("technique", "kind"), SAMPLES, ids=sample_ids(SAMPLES))
def test_js_hooks_match_python(node_hooks, technique, kind):
    rep = sample(technique, kind)
    for options in [{}, *OPTIONS.get(kind, [])]:
        (drawable,) = make_drawables([rep], options)
        check_plans(node_hooks, drawable.plans, rep.bounds, f"{kind} {options}")


@pytest.mark.parametrize("kind", ["relief", "relief-object", "depth-object"])
def test_js_instanced_hooks_match_python(node_hooks, kind):
    technique = dict((k, t) for t, k in SAMPLES)[kind]
    rep = sample(technique, kind)
    (drawable,) = make_drawables([rep], {})
    placed = instanced(drawable.plans, placements([[0.0, 0.0, 0.0], [2.0, 0.5, -1.0]],
                                                  [1.0, 0.5], [0.0, 1.2]))
    assert check_plans(node_hooks, placed, rep.bounds, f"instanced {kind}") > 0


def torus_sort_plan(shell, method: str) -> DrawPlan:
    """A plan with only what the visibility hook reads: the torus shell's order cells."""
    cells = order_cells(shell)
    count = len(shell.tets)
    return DrawPlan(
        "torus shell", Program("shellvolume:shell.glsl"),
        Geometry({"in_tet": Attribute(np.arange(count, dtype=np.int32), per_instance=True)},
                 vertices=12, instances=count),
        per_view=ViewHook("reliefkit.techniques.shellvolume.render:visibility_hook", {
            "cells": {f.name: getattr(cells, f.name) for f in fields(cells)},
            "method": method}))


def test_js_sxmpvo_orders_a_torus_shell_without_violations(node_hooks):
    """12 views around and through the hole: the JS order breaks no pixel ray's order of
    crossings (the checker of the Python sort's tests) and equals the Python order."""
    shell = build_shell(torus_mesh(), 0.08)
    plan = torus_sort_plan(shell, "sxmpvo")
    node_hooks.load([plan])
    light = DirectionalLight()
    for k in range(12):
        camera = Camera.orbit((0, 0, 0), 30 * k + 7, (-60, -25, 0, 25, 50, 80)[k % 6], 4.0,
                              size=(64, 48), ortho_height=1.6 if k % 4 == 3 else None)
        js = node_hooks.call(0, camera, light)
        order = js["attributes"]["in_tet"]
        check = ordering_violations(shell, camera, order)
        assert check.pairs > 0 and check.violations == 0, (camera.eye, check)
        compare(python_update(plan, camera, light), js, f"torus from {camera.eye}",
                "visibility_hook (torus)")


def python_hooks() -> set[str]:
    """Every view hook a plan in src/ names: ``ViewHook(f"{__name__}:function", ...)``."""
    src = ROOT / "src"
    found = set()
    for path in src.rglob("*.py"):
        module = ".".join(path.relative_to(src).with_suffix("").parts)
        for name in re.findall(r'ViewHook\(\s*f"\{__name__\}:(\w+)"', path.read_text()):
            found.add(f"{module}:{name}")
    return found


def test_every_python_view_hook_has_a_js_port(node_hooks):
    hooks = python_hooks()
    assert len(hooks) >= 8  # the scan finds the hooks it is meant to
    assert hooks <= set(node_hooks.names()), hooks - set(node_hooks.names())
