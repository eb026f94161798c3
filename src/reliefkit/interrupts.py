"""Ctrl-C and SIGTERM that stop a command whatever runs when they arrive.

While `handled()` is active, SIGINT raises `KeyboardInterrupt` and SIGTERM `Terminated`, and
each signal is also remembered. Raising is not enough on its own: a dependency may import
under ``except BaseException`` (trimesh's optional-module guards do) and swallow the
exception, and the command would then finish and write its output. So the atomic writer
and the progress callbacks call `raise_pending()`, which raises the remembered signal
again: an interrupted command never commits an output, and long work stops at its next
progress step. After an interruption, finalizers of objects the signal left half-built
(llvmlite's, inside a numba compile) would print "Exception ignored" tracebacks after the
command's one line; they are dropped.
"""

from __future__ import annotations

import contextlib
import signal
import sys


class Terminated(BaseException):
    """SIGTERM arrived: unwinds like KeyboardInterrupt, so every `atomic_path` removes its
    temporary file, and is no Exception, so no `except Exception` swallows it."""


_pending: int | None = None  # the signal received while `handled()` was active, if any


def _raise_for(signum: int):
    raise KeyboardInterrupt if signum == signal.SIGINT else Terminated


def _handler(signum, frame):
    global _pending
    _pending = signum
    _raise_for(signum)


def raise_pending() -> None:
    """Raise the interruption received earlier, even if something swallowed it then."""
    if _pending is not None:
        _raise_for(_pending)


def _unraisable(previous):
    """``sys.unraisablehook`` that is silent once a signal came (the process is unwinding)."""
    def hook(unraisable) -> None:
        if _pending is None:
            previous(unraisable)

    return hook


def _silent(unraisable) -> None:
    pass


@contextlib.contextmanager
def handled():
    """SIGINT and SIGTERM raise (and are remembered) inside the block; the previous handlers
    come back after it. Outside the main thread (a test's thread) signals are left alone."""
    global _pending
    _pending = None
    try:
        previous = {sig: signal.signal(sig, _handler) for sig in (signal.SIGINT, signal.SIGTERM)}
    except ValueError:  # not the main thread
        yield
        return
    previous_hook = sys.unraisablehook
    sys.unraisablehook = _unraisable(previous_hook)
    try:
        yield
    finally:
        for sig, old in previous.items():
            signal.signal(sig, old)
        sys.unraisablehook = previous_hook if _pending is None else _silent
        _pending = None
