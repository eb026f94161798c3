"""The one atomic writer: a failed or interrupted write never leaves a torn file behind."""

from __future__ import annotations

import contextlib
import functools
import os
import tempfile
from pathlib import Path

from ..errors import UsageError


@functools.cache
def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


@contextlib.contextmanager
def atomic_path(path, *, error: type = UsageError):
    """Yield a temporary path beside ``path``; on success fsync it, move it into place and
    fsync the folder so the rename survives a crash.

    On any exception the temporary file is removed and an existing ``path`` stays intact;
    an OSError becomes ``error`` (a ReliefkitError subclass) with a one-line message.
    """
    dest = Path(path)
    folder = dest.parent if str(dest.parent) else Path(".")
    try:
        fd, tmp = tempfile.mkstemp(dir=folder, prefix=f".{dest.name}.",
                                   suffix=dest.suffix + ".tmp")
    except OSError as exc:
        raise error(f"cannot write {dest}: {exc.strerror or exc}; check that the folder "
                    "exists and is writable") from None
    os.close(fd)
    try:
        yield Path(tmp)
        with open(tmp, "rb+") as handle:
            os.fsync(handle.fileno())
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600; give outputs the usual mode
        os.replace(tmp, dest)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        if isinstance(exc, OSError):
            raise error(f"cannot write {dest}: {exc.strerror or exc}; nothing was "
                        "written") from exc
        raise
    _fsync_folder(folder)


def _fsync_folder(folder: Path) -> None:
    """Make the rename durable where the OS allows syncing a directory."""
    if os.name != "posix":
        return
    with contextlib.suppress(OSError):
        fd = os.open(folder, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
