"""Kinds that misbehave on purpose, for the batch tests: each worker registers them (and
the toy technique) through `setup`, which the tests hand to `reliefkit.batch`."""

from __future__ import annotations

import os
import time
from dataclasses import dataclass

import numpy as np
import toy_technique

from reliefkit.builtins import registry
from reliefkit.core.technique import Baker, Technique, register, techniques

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


MISBEHAVING = Technique(
    name="misbehaving", summary="kinds that crash, hang or hog memory (batch tests)",
    package=__name__,
    bakers=tuple(Baker(name, f"a baker that {what}", NoParams, bake) for name, what, bake in (
        ("crash", "exits its process", _crash), ("hang", "never returns", _hang),
        ("hog", "takes memory without end", _hog))))


def setup() -> None:
    """The built-ins, the toy technique and the misbehaving kinds, in this process."""
    registry()
    known = {tech.name for tech in techniques()}
    for tech in (toy_technique.TECHNIQUE, MISBEHAVING):
        if tech.name not in known:
            register(tech)
