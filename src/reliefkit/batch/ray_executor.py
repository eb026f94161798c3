"""The Ray executor: the very same `task.run_task` as Ray tasks, on a cluster.

With no ``address`` a local Ray cluster is started for the run (``workers`` CPUs) and shut
down after it; ``address`` (``auto``, ``HOST:PORT`` or ``ray://HOST:PORT``) joins an
existing one, and a process already connected to Ray uses its connection. At most
``workers`` tasks are in flight. A task carries its files as bytes and returns the
`Result` (the .rk bytes): nothing needs a shared file system, and the driver writes.

Each Ray worker process is prepared once (`task.prepare_worker`, module-level here: Mesa
and numba threads, then the EGL device, then its kinds) and keeps its GL context for the tasks that
follow. A slot whose worker is new first runs `_prepare` on its own, so an asset's time
and ``timeout`` are its own, as with the local executor. Tasks ask Ray for GPUs only
when the cluster has some (a GPU request on a cluster without one waits forever); the
worker's EGL device is then its first GPU by index (EGL ignores ``CUDA_VISIBLE_DEVICES``).
A task over ``timeout`` is cancelled (its worker killed), a worker that dies fails only
its asset (``max_retries=0``), and on Ctrl-C the run's connection is closed, which ends
its job and the tasks in flight (cancelled one by one where the connection is the
caller's).
"""

from __future__ import annotations

import contextlib
import logging
import math
import os
import re
import socket
import sys
import tempfile
import time
from collections.abc import Callable, Iterable

from ..errors import ReliefkitError, UsageError
from .local import POLL_SECONDS, check_limits, cores
from .task import Result, Task, failed, prepare_worker, run_task

RAY_NEEDED = "--executor ray needs Ray: pip install 'reliefkit[ray]'"
MAX_MEMORY_REFUSED = ("--max-memory is not available with --executor ray: the driver cannot "
                      "watch a Ray worker's memory (Ray's memory monitor stops tasks when a "
                      "node runs short); leave it out or use --executor local")
CONNECT_SECONDS = 10  # to reach an --address before Ray tries (for minutes)
AUTH_REFUSED = ("InvalidAuthToken", "Unauthenticated")  # Ray's core: a token is missing or wrong
AUTH_ADVICE = ("asks for Ray's token authentication and this process has no token it accepts: "
               "run with RAY_AUTH_MODE=token and the cluster's token in ~/.ray/auth_token "
               "(or RAY_AUTH_TOKEN_PATH, or RAY_AUTH_TOKEN)")
RAY_LOGGING = logging.ERROR  # Ray's own log lines stay in its session folder
_prepared = False  # this worker process has been made a baker (`_prepare`)


class RayExecutor:
    """Runs tasks as Ray tasks, ``workers`` in flight (default: the local cluster's CPUs,
    those of the cluster at ``address``); ``setup`` and ``timeout`` as in
    `local.LocalExecutor`."""

    def __init__(self, workers: int | None = None, *, timeout: float | None = None,
                 max_memory: int | None = None, setup: Callable | None = None,
                 address: str | None = None) -> None:
        try:
            import ray  # noqa: F401 - here, so a missing Ray is one line before any work
        except ImportError:
            raise UsageError(RAY_NEEDED) from None
        if max_memory is not None:
            raise UsageError(MAX_MEMORY_REFUSED)
        check_limits(workers, timeout)
        if address not in (None, "auto"):
            _check_reachable(address)
        self.workers, self.timeout, self.setup, self.address = workers, timeout, setup, address

    def run(self, tasks: Iterable[Task], count: int,
            on_result: Callable[[Task, Result], None]) -> None:
        """Run every task of ``tasks`` (``count`` of them) on Ray, calling ``on_result`` in
        this process as each finishes; on any exit (Ctrl-C too) nothing of this batch runs
        on: the connection made here is closed (and a cluster started here shut down),
        which ends the job and its tasks; on a caller's connection they are cancelled."""
        if count == 0:
            return
        import ray

        owned = self._connect(ray)
        try:
            slots = _Slots(ray, min(count, self._in_flight(ray)), self.setup, self.timeout)
            try:
                slots.run(tasks, on_result)
            except BaseException:  # Ctrl-C too
                if not owned:  # the caller's connection stays open: stop this batch's tasks
                    slots.cancel()
                raise
        finally:
            if owned:  # ends this job: Ray stops its tasks, and a cluster started here
                ray.shutdown()

    def _connect(self, ray) -> bool:
        """Connected to Ray; whether the connection is this run's (to close after it: a
        process already connected keeps its own)."""
        if ray.is_initialized():
            return False
        quiet = {"logging_level": RAY_LOGGING, "log_to_driver": False}
        if self.address is None:
            try:
                ray.init(num_cpus=self.workers or cores(), include_dashboard=False, **quiet)
            except (ConnectionError, RuntimeError, ValueError) as exc:
                raise ReliefkitError(f"--executor ray: could not start a local Ray cluster "
                                     f"({_one_line(exc)})") from None
            return True
        with tempfile.TemporaryFile("w+b") as core_log:
            try:
                with _native_stderr_to(core_log):
                    ray.init(address=self.address, **quiet)
            except (ConnectionError, RuntimeError, ValueError, ray.exceptions.RayError) as exc:
                core_log.seek(0)
                said = core_log.read().decode("utf-8", "replace") + str(exc)
                where = _cluster_named(self.address, str(exc))
                if any(word in said for word in AUTH_REFUSED):
                    raise ReliefkitError(f"--executor ray: {where} {AUTH_ADVICE}") from None
                raise ReliefkitError(f"--executor ray: could not reach {where} "
                                     f"({_one_line(exc)})") from None
        return True

    def _in_flight(self, ray) -> int:
        return self.workers or max(1, int(ray.cluster_resources().get("CPU", 1)))


class _Slots:
    """The ``count`` tasks in flight: each slot holds a bake (or a new worker's `_prepare`),
    its object reference and when it was handed to Ray."""

    def __init__(self, ray, count: int, setup, timeout: float | None) -> None:
        self.ray, self.setup, self.timeout = ray, setup, timeout
        gpus = ray.cluster_resources().get("GPU", 0)
        options = {"num_cpus": 1, "max_retries": 0}
        if gpus:  # fractional: several bakers share a GPU when there are more than GPUs
            options["num_gpus"] = min(1.0, math.floor(gpus / count * 1e4) / 1e4)  # Ray's 4 places
        self.prepare = ray.remote(_prepare).options(**options)
        self.bake = ray.remote(_bake).options(**options)
        self.slots: list[dict | None] = [None] * count  # None: no worker ready for it

    def run(self, tasks: Iterable[Task], on_result) -> None:
        pending = iter(tasks)
        waiting: Task | None = None
        while True:
            for k, slot in enumerate(self.slots):
                if slot is not None and slot["ref"] is not None:
                    continue
                waiting = waiting or next(pending, None)
                if waiting is None:
                    break
                if slot is None:  # a worker for it first (start-up outside the limit)
                    self.slots[k] = {"ref": self.prepare.remote(self.setup), "task": None}
                else:
                    self.slots[k] = {"ref": self.bake.remote(self.setup, waiting),
                                     "task": waiting, "since": time.monotonic()}
                    waiting = None
            busy = [s["ref"] for s in self.slots if s is not None and s["ref"] is not None]
            if not busy:
                return
            self.ray.wait(busy, num_returns=1, timeout=POLL_SECONDS)
            for k, slot in enumerate(self.slots):
                if slot is not None and slot["ref"] is not None:
                    self._poll(k, slot, on_result)

    def cancel(self) -> None:
        """Cancel the tasks in flight (their workers killed)."""
        for slot in self.slots:
            if slot is not None and slot["ref"] is not None:
                self.ray.cancel(slot["ref"], force=True)

    def _poll(self, k: int, slot: dict, on_result) -> None:
        """The slot's bake or preparation, once done (or over the time limit)."""
        ray, task = self.ray, slot["task"]
        ready, _ = ray.wait([slot["ref"]], timeout=0)
        if not ready:
            if task is not None and self.timeout is not None and \
                    time.monotonic() - slot["since"] > self.timeout:
                ray.cancel(slot["ref"], force=True)
                self.slots[k] = None
                on_result(task, failed(task, f"took longer than --timeout {self.timeout:g} s; "
                                             "its Ray task was cancelled", self.timeout))
            return
        try:
            result = ray.get(slot["ref"])
        except ray.exceptions.WorkerCrashedError:
            self.slots[k] = None
            if task is not None:
                on_result(task, failed(task, "the Ray worker baking it died; Ray replaced it",
                                       time.monotonic() - slot["since"]))
            return
        except ray.exceptions.RayError as exc:  # no worker for it: the batch cannot go on
            raise ReliefkitError(f"--executor ray: {_first_line(exc)}") from None
        slot["ref"] = None
        if task is not None:
            on_result(task, result)


@contextlib.contextmanager
def _native_stderr_to(sink):
    """The process's stderr (file descriptor 2) into ``sink`` while Ray's C++ core connects:
    it logs each retry there, a line a second for about 20 s (a cluster that refuses the
    token: 21 lines before Ray's own error, which does not say why); read afterwards."""
    sys.stderr.flush()
    saved = os.dup(2)
    try:
        os.dup2(sink.fileno(), 2)
        yield
    finally:
        os.dup2(saved, 2)
        os.close(saved)


def _cluster_named(address: str, said: str) -> str:
    """The cluster an error is about: ``auto`` with the address Ray found for it (RAY_ADDRESS
    or the last ``ray start`` here; its error names it: ``... Ray cluster at HOST:PORT``),
    another address as given."""
    found = re.search(r"Ray cluster at (\S+?)\.?$", said.strip())
    if address == "auto" and found:
        return f"the Ray cluster --address auto found at {found.group(1)}"
    return f"the Ray cluster at {address}"


def _one_line(exc: Exception) -> str:
    return " ".join(str(exc).split())[:300]


def _check_reachable(address: str) -> None:
    """Refuse an address nothing answers at, in seconds: Ray itself retries for minutes,
    printing its own lines."""
    host, _, port = address.removeprefix("ray://").rpartition(":")
    if not host or not port.isdigit():
        raise UsageError(f"--address takes auto, HOST:PORT or ray://HOST:PORT, got {address!r}")
    try:
        socket.create_connection((host, int(port)), timeout=CONNECT_SECONDS).close()
    except OSError as exc:
        raise ReliefkitError(f"--executor ray: nothing answers at {address} "
                             f"({exc.strerror or exc}); is the Ray cluster running?") from None


def _prepare(setup) -> None:
    """Make this Ray worker process a baker, once: its Mesa threads (its node's cores over
    the node's CPU slots), its EGL device (its first GPU by index, when Ray gave it one),
    its kinds (``setup``)."""
    global _prepared
    if _prepared:
        return
    import ray

    gpu_ids = ray.get_gpu_ids()
    prepare_worker(setup, threads=max(1, cores() // _node_cpus(ray)),
                   device_index=int(gpu_ids[0]) if gpu_ids else None)
    _prepared = True


def _bake(setup, task: Task) -> Result:
    """`run_task` in this prepared worker."""
    _prepare(setup)
    return run_task(task)


def _node_cpus(ray) -> int:
    """The CPU slots Ray runs tasks in on this worker's node."""
    node = ray.get_runtime_context().get_node_id()
    for info in ray.nodes():
        if info.get("NodeID") == node:
            return max(1, int(info.get("Resources", {}).get("CPU", 1)))
    return 1


def _first_line(exc: Exception) -> str:
    lines = [line.strip() for line in str(exc).splitlines() if line.strip()]
    return lines[0][:300] if lines else type(exc).__name__
