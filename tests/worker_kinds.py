"""The batch tests' kinds (`batch_kinds`) and one more: ``worker`` bakes the toy quad and
reports, in its params, how its worker was prepared: the GPU ids Ray gave the task (on a
Ray worker), the EGL device and Mesa threads its GL context was made with, numba's
threads."""

from __future__ import annotations

import os
import sys

import batch_kinds
import toy_technique

from reliefkit.core.technique import Baker, Technique, register, techniques, unregister


def _worker(mesh, params, progress=None):
    import numba

    from reliefkit.gl.context import get_context

    ray = sys.modules.get("ray")  # imported in a Ray worker, never in a local one
    renderer = get_context().info["GL_RENDERER"]
    quad = toy_technique.bake_quad(mesh, toy_technique.ToyBakeParams())
    quad.params = {"ray_gpu_ids": [int(i) for i in ray.get_gpu_ids()] if ray else None,
                   "GLCONTEXT_DEVICE_INDEX": os.environ.get("GLCONTEXT_DEVICE_INDEX"),
                   "LP_NUM_THREADS": os.environ.get("LP_NUM_THREADS"),
                   "numba_threads": numba.get_num_threads(), "renderer": renderer}
    return quad


WORKER = Technique(
    name="worker", summary="reports how a batch worker was prepared (batch tests)",
    package=__name__,
    bakers=(Baker("worker", "reports its GPU, EGL device and threads", batch_kinds.NoParams,
                  _worker),))


def setup() -> None:
    batch_kinds.setup()
    if WORKER.name not in {tech.name for tech in techniques()}:
        register(WORKER)


def teardown() -> None:
    if WORKER.name in {tech.name for tech in techniques()}:
        unregister(WORKER.name)
    batch_kinds.teardown()
