"""The one atomic writer: a failed or interrupted write never leaves a torn file behind.

The temporary file is ``.NAME.XXXXXXXX.tmp`` in the destination's folder, with NAME the
destination's name cut to `TEMP_NAME_BYTES` bytes: its length is bounded whatever the
destination's, so any name the folder accepts can be written, and every error names the
destination, never the temporary file.
"""

from __future__ import annotations

import contextlib
import contextvars
import functools
import os
import tempfile
from pathlib import Path

from ..errors import UsageError
from ..interrupts import raise_pending

TEMP_NAME_BYTES = 40  # of the destination's name in the temporary file's (then 8 random + .tmp)
TEMP_SUFFIX = ".tmp"
# inside `written_together`: the (temporary, destination) pairs waiting to be moved together
_deferred: contextvars.ContextVar[list | None] = contextvars.ContextVar("deferred",
                                                                       default=None)


@functools.cache
def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _reason(exc: OSError) -> str:
    """The OS's words for an error (``No space left on device``), without any file name."""
    return exc.strerror or str(exc) or type(exc).__name__


def temp_prefix(name: str) -> str:
    """``.NAME.`` with NAME cut to at most `TEMP_NAME_BYTES` bytes in the file system's
    encoding (never inside a character)."""
    cut = ""
    for char in name:
        if len(os.fsencode(cut + char)) > TEMP_NAME_BYTES:
            break
        cut += char
    return f".{cut}."


def check_writable(path, flag: str | None = None, *, folder: bool = False,
                   error: type = UsageError) -> Path:
    """Refuse, before any work, an output that cannot be written: a missing or read-only
    folder, or a destination that is a directory (for ``folder=True``: a destination that
    exists and is no directory, or whose nearest existing ancestor is not writable). A file
    name ending in ``/`` is refused: pathlib would drop the slash and write ``x.png``.

    ``flag`` names the option in the message (``--aovs x/y.npz: the folder x does not
    exist``). Returns the path.
    """
    dest = Path(path)
    label = f"{flag} {dest}" if flag else str(dest)
    if folder:
        if dest.exists() and not dest.is_dir():
            raise error(f"{label}: exists and is not a folder")
        parent = dest
        while not parent.exists():
            if parent.parent == parent:
                break
            parent = parent.parent
        if dest.exists():
            parent = dest
    else:
        if str(path).endswith(tuple(filter(None, (os.sep, os.altsep)))):
            raise error(f"{flag + ' ' if flag else ''}{path}: a trailing "
                        f"'{str(path)[-1]}' names a folder; name a file")
        if dest.is_dir():
            raise error(f"{label}: is a directory; name a file")
        parent = dest.parent if str(dest.parent) else Path(".")
        if not parent.exists():
            raise error(f"{label}: the folder {parent} does not exist")
    if not parent.is_dir():
        raise error(f"{label}: {parent} is not a folder")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise error(f"{label}: the folder {parent} is not writable")
    return dest


@contextlib.contextmanager
def atomic_path(path, *, error: type = UsageError):
    """Yield a temporary path beside ``path``; on success fsync it, move it into place and
    fsync the folder so the rename survives a crash.

    On any exception (also KeyboardInterrupt and the CLI's SIGTERM, even one a dependency
    swallowed: `interrupts.raise_pending`) the temporary file is removed and an existing
    ``path`` stays intact; an OSError (disk full, file too large, a directory in the way)
    becomes ``error`` (a ReliefkitError subclass) with a one-line message naming ``path``.
    """
    dest = Path(path)
    folder = dest.parent if str(dest.parent) else Path(".")
    if dest.is_dir():
        raise error(f"cannot write {dest}: it is a directory; name a file")
    try:
        fd, tmp = tempfile.mkstemp(dir=folder, prefix=temp_prefix(dest.name),
                                   suffix=TEMP_SUFFIX)
    except OSError as exc:
        raise error(f"cannot write {dest}: {_reason(exc)}; check that the folder "
                    "exists and is writable") from None
    os.close(fd)
    try:
        yield Path(tmp)
        raise_pending()  # interrupted, though something swallowed it: commit nothing
        with open(tmp, "rb+") as handle:
            os.fsync(handle.fileno())
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600; give outputs the usual mode
        group = _deferred.get()
        if group is not None:  # moved into place with the others at the group's end
            group.append((tmp, dest))
            return
        os.replace(tmp, dest)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        if isinstance(exc, OSError):
            raise error(f"cannot write {dest}: {_reason(exc)}; nothing was "
                        "written") from exc
        raise
    _fsync_folder(folder)


@contextlib.contextmanager
def written_together(*, error: type = UsageError):
    """Every `atomic_path` inside the block writes its temporary file, and all of them are
    moved into place at the block's end, or none (a failure or an interruption on the way
    removes them all): a command with several outputs (an image, its AOVs and its stats)
    never leaves some of them new and others missing or old."""
    if _deferred.get() is not None:  # already in a group: join it
        yield
        return
    group: list[tuple[str, Path]] = []
    token = _deferred.set(group)
    try:
        yield
        raise_pending()
    except BaseException:
        _remove(tmp for tmp, _ in group)
        raise
    finally:
        _deferred.reset(token)
    for k, (tmp, dest) in enumerate(group):
        try:
            os.replace(tmp, dest)
        except OSError as exc:
            _remove(tmp for tmp, _ in group[k:])
            raise error(f"cannot write {dest}: {_reason(exc)}") from exc
    for folder in {dest.parent for _, dest in group}:
        _fsync_folder(folder)


def _remove(paths) -> None:
    for path in paths:
        with contextlib.suppress(OSError):
            os.unlink(path)


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
