"""Kinds that misbehave (or report on their worker) on purpose, for the batch tests: each
worker registers them (and the toy technique) through `setup`, which the tests hand to
`reliefkit.batch`."""

from __future__ import annotations

import os
import time
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import toy_technique

from reliefkit.builtins import registry
from reliefkit.core.technique import Baker, Technique, register, techniques, unregister

HOG_STEP = 32 << 20  # bytes the hog kind touches at a time


@dataclass(frozen=True)
class NoParams:
    pass


def _crash(mesh, params, progress=None):
    os._exit(7)  # as a segfault would: no exception, no result


def _hang(mesh, params, progress=None):
    time.sleep(600)


def _hog(mesh, params, progress=None):
    """Touches more and more memory until the driver stops the worker."""
    held = []
    while True:
        held.append(np.ones(HOG_STEP // 8))
        time.sleep(0.02)


def _threads(mesh, params, progress=None):
    """A toy quad whose params say how many llvmpipe threads this worker's GL context
    started and what ``LP_NUM_THREADS`` was."""
    from reliefkit.gl.context import get_context

    get_context()
    names = [(Path("/proc/self/task") / t / "comm").read_text().strip()
             for t in os.listdir("/proc/self/task")]
    quad = toy_technique.bake_quad(mesh, toy_technique.ToyBakeParams())
    quad.params = {"LP_NUM_THREADS": os.environ.get("LP_NUM_THREADS"),
                   "llvmpipe_threads": sum(n.startswith("llvmpipe-") for n in names)}
    return quad


def _warns(mesh, params, progress=None):
    """A toy quad, after a Python warning (which the worker must not print)."""
    warnings.warn("the toy quad is flat", UserWarning, stacklevel=1)
    return toy_technique.bake_quad(mesh, toy_technique.ToyBakeParams())


MISBEHAVING = Technique(
    name="misbehaving", summary="kinds that crash, hang or hog memory (batch tests)",
    package=__name__,
    bakers=tuple(Baker(name, f"a baker that {what}", NoParams, bake) for name, what, bake in (
        ("crash", "exits its process", _crash), ("hang", "never returns", _hang),
        ("hog", "takes memory without end", _hog),
        ("threads", "reports its worker's Mesa threads", _threads),
        ("warns", "warns, then bakes a toy quad", _warns))))


def setup() -> None:
    """The built-ins, the toy technique and the misbehaving kinds, in this process."""
    registry()
    known = {tech.name for tech in techniques()}
    for tech in (toy_technique.TECHNIQUE, MISBEHAVING):
        if tech.name not in known:
            register(tech)


def teardown() -> None:
    """This process's registry without them again (the driver's, after a test)."""
    known = {tech.name for tech in techniques()}
    for tech in (MISBEHAVING, toy_technique.TECHNIQUE):
        if tech.name in known:
            unregister(tech.name)
