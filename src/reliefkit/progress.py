"""Progress of long work, on stderr so that stdout stays clean for tables and JSON.

On a terminal this draws a rich bar. Anywhere else (a log file, a pipe, CI) a bar would be
noise or nothing at all, so progress becomes plain lines such as ``demo: 3/8``: at most one
every `PLAIN_INTERVAL` seconds, plus a final ``demo: 8/8, done in 12.3 s``. This module is the one
place that decides; commands only call `progress_bar`, `activity` or `waiting`.
"""

from __future__ import annotations

import contextlib
import sys
import threading
import time

from .interrupts import raise_pending

PLAIN_INTERVAL = 5.0  # seconds between two plain progress lines
QUIET_WAIT = 10.0     # seconds a call without steps (a render) runs before `waiting` shows it


def _is_terminal(stream) -> bool:
    isatty = getattr(stream, "isatty", None)
    return bool(isatty and isatty())


@contextlib.contextmanager
def progress_bar(description: str, total: int, *, enabled: bool = True, stream=None,
                 interval: float = PLAIN_INTERVAL, eta: bool = False):
    """Yield ``advance(done, total=None)``, the callback long loops (and bakers) call; each
    call also stops the work if Ctrl-C or SIGTERM came and was swallowed (`interrupts`).
    With ``eta`` the bar (or each plain line) also says the time left at the rate so far."""
    stream = stream if stream is not None else sys.stderr
    if not enabled:
        yield _checked(lambda done, total_=None: None)
    elif _is_terminal(stream):
        with _rich_bar(description, total, stream, eta) as advance:
            yield _checked(advance)
    else:
        lines = _PlainLines(description, total, stream, interval, eta)
        yield _checked(lines.advance)
        lines.finish()


def _checked(advance):
    """``advance`` that first raises a pending interruption."""
    def checked(done: int, total: int | None = None) -> None:
        raise_pending()
        advance(done, total)

    return checked


@contextlib.contextmanager
def activity(description: str, *, stream=None):
    """Yield ``log(message)`` for work that reports steps rather than counts (benchmarks):
    each message is a line prefixed with ``description``; a terminal also shows a spinner
    with the elapsed time."""
    stream = stream if stream is not None else sys.stderr
    start = time.monotonic()
    if _is_terminal(stream):
        from rich.console import Console

        console = Console(file=stream)
        with console.status(description) as status:
            def log(message: str) -> None:
                console.print(f"{description}: {message}", highlight=False, markup=False)
                status.update(f"{description}: {message}")

            yield log
    else:
        def log(message: str) -> None:
            print(f"{description}: {message}", file=stream, flush=True)

        yield log
    print(f"{description}: done in {time.monotonic() - start:.1f} s", file=stream, flush=True)


@contextlib.contextmanager
def waiting(description: str, *, stream=None, after: float | None = None,
            interval: float | None = None):
    """For one long call that reports no steps (a single render): nothing if the block ends
    within ``after`` seconds (default `QUIET_WAIT`), so quick commands stay silent; then
    the elapsed time, as a spinner on a terminal or a plain line every ``interval`` seconds
    elsewhere (``render: 10 s``), and a final ``render: done in 46.0 s``. The time is shown
    from a thread, so the call itself needs no callback."""
    stream = stream if stream is not None else sys.stderr
    after = QUIET_WAIT if after is None else after
    interval = PLAIN_INTERVAL if interval is None else interval
    start = time.monotonic()
    finished = threading.Event()
    shown = threading.Event()

    def elapsed() -> str:
        return f"{description}: {time.monotonic() - start:.0f} s"

    def show() -> None:
        if finished.wait(after):
            return
        shown.set()
        if _is_terminal(stream):
            from rich.console import Console

            with Console(file=stream).status(elapsed()) as status:
                while not finished.wait(1.0):
                    status.update(elapsed())
            return
        print(elapsed(), file=stream, flush=True)
        while not finished.wait(interval):
            print(elapsed(), file=stream, flush=True)

    thread = threading.Thread(target=show, name=f"progress: {description}", daemon=True)
    thread.start()
    try:
        yield
    finally:
        finished.set()
        thread.join()
    if shown.is_set():
        print(f"{description}: done in {time.monotonic() - start:.1f} s", file=stream,
              flush=True)


@contextlib.contextmanager
def _rich_bar(description: str, total: int, stream, eta: bool = False):
    from rich.console import Console
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
               TimeElapsedColumn(), *((TextColumn("eta"), TimeRemainingColumn()) if eta else ()))
    with Progress(*columns, console=Console(file=stream)) as bar:
        task = bar.add_task(description, total=total)

        def advance(done: int, total_: int | None = None) -> None:
            bar.update(task, completed=done, total=total_ if total_ is not None else total)

        yield advance
        bar.update(task, completed=bar.tasks[0].total)  # done, also where nothing reported


class _PlainLines:
    """``description: done/total`` lines, rate-limited, and one final line on success."""

    def __init__(self, description: str, total: int, stream, interval: float,
                 eta: bool = False):
        self.description, self.total, self.stream = description, total, stream
        self.interval, self.eta = interval, eta
        self.start = self.last = time.monotonic()
        self.first: tuple[float, int] | None = None  # when something was first done, and how much

    def advance(self, done: int, total: int | None = None) -> None:
        self.total = total if total is not None else self.total
        now = time.monotonic()
        if done and self.first is None:
            self.first = (now, done)
        if now - self.last >= self.interval and done < self.total:
            self.last = now
            shown = f", eta {left:.0f} s" if self.eta and (left := self._left(now, done)) \
                is not None else ""
            self._line(f"{done}/{self.total}{shown}")

    def _left(self, now: float, done: int) -> float | None:
        """Seconds left at the rate since the first item was done: the start-up before it
        (a batch's workers starting) made the first estimate ten times too long."""
        if self.first is None or done <= self.first[1]:
            return None
        since, first_done = self.first
        return (now - since) * (self.total - done) / (done - first_done)

    def finish(self) -> None:
        self._line(f"{self.total}/{self.total}, done in {time.monotonic() - self.start:.1f} s")

    def _line(self, text: str) -> None:
        print(f"{self.description}: {text}", file=self.stream, flush=True)
