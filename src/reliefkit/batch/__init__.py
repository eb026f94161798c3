"""`reliefkit batch`: bake whole asset libraries, resumable (docs/batch.md).

`batch` expands INPUTs into jobs (`jobs`), skips those whose output already holds their
cache key (`key`), runs the rest as plain-data tasks (`task.run_task`) on an executor
(`local.LocalExecutor`: a process pool that survives its workers) and writes each result
atomically in the driver, recording it in ``OUT/batch.jsonl`` (`report`). Only the CLI and
the composition root import this package.
"""

from __future__ import annotations

from .local import end_if_worker_importing_script
from .report import BatchInterrupted, BatchReport
from .run import executor_for, run_batch

__all__ = ["BatchInterrupted", "BatchReport", "batch"]


def batch(inputs, kind: str, out, executor: str = "local", *, workers: int | None = None,
          force: bool = False, export: str | None = None, timeout: float | None = None,
          max_memory: int | None = None, address: str | None = None, sheet: bool = False,
          progress: bool = True, setup=None, **bake_options) -> BatchReport:
    """Bake every mesh ``inputs`` name as ``kind`` with ``bake_options`` (`reliefkit bake`'s
    options by their Python names: ``depth_res=128``) into the folder ``out``, as
    `reliefkit batch` does (docs/batch.md); call it under ``if __name__ == "__main__":``.

    Parameters
    ----------
    inputs : a path or a list of them: mesh files, folders (searched recursively), glob
        patterns, CSV or JSONL manifests (a kind and options per asset).
    executor : ``"local"`` (a pool of worker processes) or ``"ray"`` (``reliefkit[ray]``).
    workers : processes (local; default the cores) or Ray tasks in flight.
    force : bake again what is up to date (its output holds the same cache key).
    export : ``"glb"``: also the glTF export beside each .rk.
    timeout : seconds an asset may take before its worker is replaced and it fails.
    max_memory : bytes or text (``"4GB"``) a local worker may hold (at least 256 MiB).
    address : a Ray cluster (``"auto"``, ``"HOST:PORT"``, ``"ray://HOST:PORT"``).
    sheet : also ``sheet.png`` and ``index.html``: each output beside its mesh.
    progress : a progress bar on stderr.
    setup : fills the registry, here and once in each worker (``reliefkit.batch`` passes
        the composition root's ``registry``).

    Returns the `BatchReport` (``exit_status`` 1 when any asset failed, its ``summary()``
    lines); Ctrl-C raises `BatchInterrupted` with the report so far.
    """
    end_if_worker_importing_script()  # before anything is read or written
    if isinstance(inputs, str | bytes) or not hasattr(inputs, "__iter__"):
        inputs = [inputs]
    if setup is not None:
        setup()
    runner = executor_for(executor, workers=workers, timeout=timeout, max_memory=max_memory,
                          setup=setup, address=address)
    return run_batch(list(inputs), kind, out, runner, force=force, export=export,
                     sheet=sheet, progress=progress, **bake_options)
