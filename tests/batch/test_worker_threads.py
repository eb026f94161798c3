"""A local batch worker's numba threads: cores / workers, like its Mesa threads, so two
workers' parallel loops do not fight over the cores (`task.prepare_worker`)."""

from __future__ import annotations

import pytest
import worker_kinds
from helpers import write_tetrahedron

from reliefkit.batch import batch
from reliefkit.batch.local import cores
from reliefkit.io import rk


@pytest.fixture(autouse=True)
def _kinds_unregistered_after():
    """The driver (this process) registers the test kinds through ``setup``: not for long."""
    yield
    worker_kinds.teardown()


@pytest.mark.parametrize("workers", [1, 2])
def test_numba_and_mesa_threads_are_the_cores_over_the_workers(tmp_path, workers):
    for k in range(2):
        write_tetrahedron(tmp_path / "lib" / f"t{k}.obj", scale=1.0 + k)
    report = batch([tmp_path / "lib"], "worker", tmp_path / "out", workers=workers,
                   setup=worker_kinds.setup, progress=False)
    assert len(report.ok) == 2
    share = max(1, cores() // workers)
    for record in report.ok:
        params = rk.read_manifest(tmp_path / "out" / record.output)["params"]
        assert params["ray_gpu_ids"] is None and params["GLCONTEXT_DEVICE_INDEX"] is None
        assert (params["LP_NUM_THREADS"], params["numba_threads"]) == (str(share), share)
