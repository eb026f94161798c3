"""The batch tests' kinds (`batch_kinds`) and one more for the Ray executor's workers: ``gpu``
bakes the toy quad and reports, in its params, the GPU ids Ray gave the task and the EGL
device and Mesa threads its worker's GL context was made with."""

from __future__ import annotations

import os

import batch_kinds
import toy_technique

from reliefkit.core.technique import Baker, Technique, register, techniques, unregister


def _gpu(mesh, params, progress=None):
    import ray

    from reliefkit.gl.context import get_context

    renderer = get_context().info["GL_RENDERER"]
    quad = toy_technique.bake_quad(mesh, toy_technique.ToyBakeParams())
    quad.params = {"ray_gpu_ids": [int(i) for i in ray.get_gpu_ids()],
                   "GLCONTEXT_DEVICE_INDEX": os.environ.get("GLCONTEXT_DEVICE_INDEX"),
                   "LP_NUM_THREADS": os.environ.get("LP_NUM_THREADS"), "renderer": renderer}
    return quad


RAY_WORKER = Technique(
    name="ray-worker", summary="reports a Ray worker's GPU and GL context (batch tests)",
    package=__name__,
    bakers=(Baker("gpu", "reports its Ray GPU and EGL device", batch_kinds.NoParams, _gpu),))


def setup() -> None:
    batch_kinds.setup()
    if RAY_WORKER.name not in {tech.name for tech in techniques()}:
        register(RAY_WORKER)


def teardown() -> None:
    if RAY_WORKER.name in {tech.name for tech in techniques()}:
        unregister(RAY_WORKER.name)
    batch_kinds.teardown()
