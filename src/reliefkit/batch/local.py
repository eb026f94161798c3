"""The local executor: a small pool of worker processes that survives its workers.

Each worker is a spawned process with a pipe: the driver sends it one `Task` at a time and
receives its `Result`. A worker that dies (a segfault, ``os._exit``), runs past
``timeout`` seconds on one asset or holds more than ``max_memory`` bytes (its resident
set, checked every `POLL_SECONDS`) is killed and replaced, and its asset is failed with
that reason; the other workers' work goes on (a ProcessPoolExecutor would break the whole
pool). Workers ignore SIGINT: the driver stops them. Workers x Mesa threads stay within
the cores (`task.prepare_worker`).
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import signal
import time
from collections.abc import Callable, Iterable
from multiprocessing.connection import wait

from ..errors import UsageError
from ..units import parse_bytes
from .task import Result, Task, failed, prepare_worker, run_task

POLL_SECONDS = 0.2
MIN_MAX_MEMORY = 256 * 2**20  # a worker holds 114-121 MiB before its first bake (measured)
UNGUARDED_EXIT = 87  # a worker that found its parent's script calling batch as it started
UNGUARDED_SCRIPT = ("batch ran again in each worker process as it started: a worker imports the "
                    "script that calls it, so call batch under `if __name__ == \"__main__\":` "
                    "(Python's rule for scripts that start processes)")


def cores() -> int:
    """The CPU cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


def end_if_worker_importing_script() -> None:
    """End this process at once (`UNGUARDED_EXIT`) when it is a worker still importing its
    parent's script: a spawned process re-runs the script's top level, so a script without
    the ``__main__`` guard calls batch again there. Before, every worker died of Python's
    own error in ~450 lines and each asset was failed as "worker died"; now the driver sees
    the exit status and says what to fix (`UNGUARDED_SCRIPT`)."""
    if getattr(multiprocessing.current_process(), "_inheriting", False):  # spawn's own test
        os._exit(UNGUARDED_EXIT)


def check_limits(workers: int | None, timeout: float | None) -> None:
    """Refuse a worker count or time limit no executor can honour."""
    if workers is not None and workers < 1:
        raise UsageError(f"--workers must be at least 1, got {workers}")
    if timeout is not None and not timeout > 0:
        raise UsageError(f"--timeout must be a positive number of seconds, got {timeout}")


def memory_limit(value) -> int | None:
    """``--max-memory`` in bytes: an int, or text such as ``2GB`` or ``512MB``
    (`units.parse_bytes`); a limit a worker passes before baking anything (below
    `MIN_MAX_MEMORY`) would fail assets by the clock, so it is refused up front."""
    if value is None:
        return None
    limit = value if isinstance(value, int) and not isinstance(value, bool) else \
        parse_bytes(value) if isinstance(value, str) else None
    if limit is None or limit <= 0:
        raise UsageError(f"--max-memory takes a byte count such as 2GB or 512MB, got {value!r}")
    if limit < MIN_MAX_MEMORY:
        raise UsageError(f"--max-memory {value} is below {MIN_MAX_MEMORY // 2**20} MiB: a worker "
                         "holds about 120 MiB before it bakes anything; give at least that")
    return limit


class LocalExecutor:
    """Runs tasks in ``workers`` processes (default: the cores) on this machine.

    ``setup`` is called once in each worker before its first task (the composition root's
    ``registry``); ``timeout`` (seconds) and ``max_memory`` (bytes, or text such as
    ``"4GB"``: `memory_limit`) limit each asset."""

    def __init__(self, workers: int | None = None, *, timeout: float | None = None,
                 max_memory: int | None = None, setup: Callable | None = None) -> None:
        check_limits(workers, timeout)
        self.workers = workers or cores()
        self.timeout, self.max_memory, self.setup = timeout, memory_limit(max_memory), setup

    def run(self, tasks: Iterable[Task], count: int,
            on_result: Callable[[Task, Result], None]) -> None:
        """Run every task of ``tasks`` (``count`` of them), calling ``on_result`` in this
        process as each finishes; on any exit (Ctrl-C too) every worker is stopped. A lost
        worker's slot gets a new one when there is a task for it."""
        threads = max(1, cores() // self.workers)
        slots: list[_Worker | None] = [_Worker(self.setup, threads)
                                       for _ in range(min(self.workers, count))]
        pending = iter(tasks)
        try:
            while True:
                for k, worker in enumerate(slots):
                    if worker is None or worker.task is None:
                        task = next(pending, None)
                        if task is None:
                            break
                        slots[k] = worker = worker or _Worker(self.setup, threads)
                        worker.start(task)
                busy = [w for w in slots if w is not None and w.task is not None]
                if not busy:
                    return
                wait([w.conn for w in busy] + [w.process.sentinel for w in busy],
                     timeout=POLL_SECONDS)
                for k, worker in enumerate(slots):
                    if worker is None or worker.task is None:
                        continue
                    task, result = worker.task, worker.poll(self.timeout, self.max_memory)
                    if result is None:
                        continue
                    if worker.broken:
                        slots[k] = None
                    on_result(task, result)
        finally:
            for worker in slots:
                if worker is not None:
                    worker.stop()


class _Worker:
    """One worker process, its pipe and the task it runs (with when it started)."""

    def __init__(self, setup, threads: int) -> None:
        context = multiprocessing.get_context("spawn")  # no inherited GL or thread state
        self.conn, child = context.Pipe()
        self.process = context.Process(target=_serve, args=(child, setup, threads),
                                       name="reliefkit-batch-worker", daemon=True)
        self.process.start()
        child.close()
        self.task: Task | None = None
        self.started: float | None = None  # when the worker took its task
        self.broken = False

    def start(self, task: Task) -> None:
        self.task, self.started = task, None
        with contextlib.suppress(OSError):  # it died before the task reached it: see `poll`
            self.conn.send(task)

    def poll(self, timeout: float | None, max_memory: int | None) -> Result | None:
        """The task's result once there is one: the worker's, or a failure saying why the
        worker was lost (then ``broken``). The time limit counts from the worker taking
        the task (after its start-up)."""
        while self.conn.poll():
            try:
                message = self.conn.recv()
            except (EOFError, OSError):
                break
            if isinstance(message, Result):
                self.task = None
                return message
            self.started = time.monotonic()  # the worker took the task
        if not self.process.is_alive():
            if self.process.exitcode == UNGUARDED_EXIT:
                raise UsageError(UNGUARDED_SCRIPT)
            return self._lost(f"the worker baking it died ({_exit_reason(self.process)}); "
                              "it was replaced")
        if timeout is not None and self.started is not None and \
                time.monotonic() - self.started > timeout:
            return self._lost(f"took longer than --timeout {timeout:g} s; its worker was "
                              "stopped and replaced")
        used = _resident_bytes(self.process.pid)
        if max_memory is not None and used is not None and used > max_memory:
            return self._lost(f"its worker used {used / 2**20:.0f} MiB, over --max-memory "
                              f"{max_memory / 2**20:.0f} MiB; it was stopped and replaced")
        return None

    def _lost(self, why: str) -> Result:
        task, self.task, self.broken = self.task, None, True
        self.stop()
        seconds = 0.0 if self.started is None else time.monotonic() - self.started
        return failed(task, why, seconds)  # (now - now read in that order was -0.0 s)

    def stop(self) -> None:
        if self.process.is_alive():
            self.process.kill()
        self.process.join()
        self.conn.close()


def _serve(conn, setup, threads: int) -> None:
    """A worker's life: prepared once, then one task after another until the pipe closes."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the driver's to handle
    prepare_worker(setup, threads=threads)
    while True:
        try:
            task = conn.recv()
        except (EOFError, OSError):
            return
        conn.send("started")
        conn.send(run_task(task))


def _exit_reason(process) -> str:
    code = process.exitcode
    if code is not None and code < 0:
        try:
            return f"signal {signal.Signals(-code).name}"
        except ValueError:
            return f"signal {-code}"
    return f"exit status {code}"


def _resident_bytes(pid: int) -> int | None:
    """A process's resident set in bytes (Linux's /proc), None where unknown."""
    try:
        with open(f"/proc/{pid}/statm", "rb") as fh:
            return int(fh.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return None
