"""The `reliefkit` command line: parses arguments, calls the library, prints results.

Every failure is one line ``error: ...`` on stderr and a non-zero exit status: 2 for a usage
error (argparse's or a `UsageError`), 1 for bad input (a mesh, an .rk file, the GPU), 3 for
an internal error (docs/cli.md). The package: `parser` builds the argument parser from the
technique registry, `options` turns declared options into flags and checks their values,
`commands` holds the subcommands, `exits` the exit statuses; `main` here runs one command
with its error handling.
"""

from __future__ import annotations

import contextlib
import os
import sys
import warnings

from ..errors import ReliefkitError, UsageError
from ..interrupts import Terminated, handled, raise_pending
from .exits import (
    EXIT_BROKEN_PIPE,
    EXIT_INPUT,
    EXIT_INTERNAL,
    EXIT_INTERRUPTED,
    EXIT_TERMINATED,
    EXIT_USAGE,
)


def main(argv: list[str] | None = None) -> int:
    """Run one command. Ctrl-C and SIGTERM are taken from the start, before the heavy
    imports (the parser imports every technique), so at any moment they end in one line."""
    with handled():
        try:
            return _parse_and_run(argv)
        except KeyboardInterrupt:
            print("error: interrupted", file=sys.stderr)
            return EXIT_INTERRUPTED
        except Terminated:
            print("error: terminated (SIGTERM); no output was left half-written",
                  file=sys.stderr)
            return EXIT_TERMINATED


def run() -> None:
    """The console script and ``python -m reliefkit.cli``: `main`, then exit. After Ctrl-C or
    SIGTERM it exits at once (the interpreter would report a KeyboardInterrupt a library
    once saw as a death by SIGINT, and finalizers could still print)."""
    status = main()
    if status in (EXIT_INTERRUPTED, EXIT_TERMINATED):
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(status)
    sys.exit(status)


def _parse_and_run(argv: list[str] | None) -> int:
    try:
        from ..builtins import registry
        from .parser import build_parser

        registry()
        parser = build_parser()
    except Exception as exc:
        raise_pending()  # a signal a library turned into its own error (a RuntimeError)
        if not isinstance(exc, ReliefkitError):
            raise
        print(f"error: {exc}", file=sys.stderr)  # a technique failed to register
        return EXIT_INPUT
    raise_pending()  # a signal an import guard swallowed
    args = parser.parse_args(argv)
    if not getattr(args, "run", None):
        parser.print_help()
        return EXIT_USAGE
    with _one_line_warnings():
        return _run(args)


@contextlib.contextmanager
def _one_line_warnings():
    """Python warnings become one ``warning: ...`` line each; numpy's floating-point
    RuntimeWarnings (overflow, invalid value) are silenced: bad values are refused by the
    checks that follow them, with their own one-line error. Deprecations are silenced, and
    ResourceWarnings (a file a library's import left open when Ctrl-C cut it short: a
    line before "error: interrupted" a user can do nothing with); PIL's
    DecompressionBombWarning stays (one line)."""
    def show(message, category, filename, lineno, file=None, line=None):
        text = " ".join(str(message).split())
        print(f"warning: {text}", file=sys.stderr)

    with warnings.catch_warnings():
        warnings.simplefilter("default")
        warnings.filterwarnings("ignore", category=DeprecationWarning)
        warnings.filterwarnings("ignore", category=PendingDeprecationWarning)
        warnings.filterwarnings("ignore", category=ResourceWarning)
        warnings.filterwarnings("ignore", category=RuntimeWarning)
        # ... but PIL's DecompressionBombWarning (a RuntimeWarning) matters: one line
        warnings.filterwarnings("default", message=r"Image size \(", category=RuntimeWarning)
        warnings.showwarning = show
        yield


def _run(args) -> int:
    try:
        status = args.run(args)
        sys.stdout.flush()  # a closed pipe shows here, not in the interpreter's exit
        return status
    except BrokenPipeError:
        return _broken_pipe()
    except ReliefkitError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return EXIT_USAGE if isinstance(exc, UsageError) else EXIT_INPUT
    except OSError as exc:
        name = f" {exc.filename}" if getattr(exc, "filename", None) else ""
        print(f"error: cannot access{name}: {exc.strerror or exc}", file=sys.stderr)
        return EXIT_INPUT
    except Exception as exc:  # a bug, not bad input: still one line, details on request
        raise_pending()  # ... unless a library turned Ctrl-C or SIGTERM into this error
        if os.environ.get("RELIEFKIT_DEBUG"):
            raise
        print(f"error: internal error ({type(exc).__name__}: {exc}); "
              "rerun with RELIEFKIT_DEBUG=1 for a traceback", file=sys.stderr)
        return EXIT_INTERNAL


def _broken_pipe() -> int:
    """The reader of stdout went away (``... | head``): stop quietly, as `cat` would.

    stdout is pointed at /dev/null so the interpreter's final flush cannot fail again.
    """
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, sys.stdout.fileno())
    os.close(devnull)
    return EXIT_BROKEN_PIPE


if __name__ == "__main__":
    run()

