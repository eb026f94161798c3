"""The composition root: the one place that puts the built-ins into the registry.

`registry()` registers the core's ``mesh`` kind and ground-truth drawable and every technique
of ``reliefkit.techniques.TECHNIQUES`` in `reliefkit.core.technique.REGISTRY`, once per
process, and hands the tables derived from it to the layers below: the .rk reader's kinds
(`reliefkit.io.rk.use_codecs`) and the shader loader's namespaces
(`reliefkit.gl.shaders.use_namespaces`). Those layers never reach back up for them. Every
entry point (the public API in ``reliefkit/__init__``, the CLI, compare) calls `registry()`
before it looks anything up; the benches and the demo sheet run from the CLI.

Importing this module is light: it loads none of numba, scipy or trimesh. The techniques
import those where they run them, and their benches, demo tiles and references when those
are called (`tests/test_cli_startup.py`).
"""

from __future__ import annotations

import functools
import os
import threading

from .bake import bake as _bake
from .batch import batch as _batch_of
from .core.technique import REGISTRY, Registry
from .export import export as _export
from .gl import shaders
from .io import rk
from .io.gltf import representation as gltf_representation
from .io.mesh_codec import MESH_CODEC
from .render import render as _render
from .render.mesh import MESH_DRAWABLE
from .techniques import TECHNIQUES

__all__ = ["registry", "bake", "load", "render", "save", "export", "batch"]

_lock = threading.Lock()
_filled = False


def registry() -> Registry:
    """The registry with every built-in in it (registered on the first call)."""
    global _filled
    with _lock:
        if not _filled:
            REGISTRY.add_core(codecs=(MESH_CODEC,), drawables=(MESH_DRAWABLE,))
            for tech in TECHNIQUES:
                REGISTRY.register(tech)
            rk.use_codecs(REGISTRY.codecs)
            shaders.use_namespaces(REGISTRY.shader_namespaces)
            _filled = True
    return REGISTRY


def _with_builtins(function):
    """The public ``reliefkit.NAME`` of a function that looks things up in the registry."""
    @functools.wraps(function)
    def public(*args, **kwargs):
        registry()
        return function(*args, **kwargs)

    return public


def _load(source, **kwargs):
    """An .rk file, or a glTF file reliefkit exported (`io.gltf.representation.load`); bytes
    (or a binary file object) are an .rk's (`io.rk.load`)."""
    if isinstance(source, str | os.PathLike) and gltf_representation.is_gltf(source):
        return gltf_representation.load(source, **kwargs)
    return rk.load(source, **kwargs)


@functools.wraps(_batch_of)  # help(reliefkit.batch) shows its parameters and docstring
def _batch(*args, **options):
    """`reliefkit.batch.batch`, each worker given the built-ins (``setup``)."""
    options.setdefault("setup", registry)
    return _batch_of(*args, **options)


bake = _with_builtins(_bake)
batch = _with_builtins(_batch)
load = _with_builtins(_load)
export = _with_builtins(_export)  # help() on each shows the function's own parameters
render = _with_builtins(_render)
save = _with_builtins(rk.save)
