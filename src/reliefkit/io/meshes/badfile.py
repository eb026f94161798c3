"""What every part of the loader shares: the `BadFile` exception and small text/index checks.

trimesh silently accepts some broken files (a truncated STL reads as an empty scene, a
truncated ASCII PLY or OFF loses its last faces, missing .mtl/texture/image files are
skipped, out-of-range PLY and glTF indices are kept as they are), so each format gets a
small structural check before trimesh parses it (one module per format family), and the
parsed geometry is checked again afterwards. Each check raises `BadFile`; `load_mesh` turns
it into one `MeshError` that starts with the path.
"""

from __future__ import annotations

import contextlib
import contextvars
import os
import stat
from pathlib import Path

import numpy as np

#: The largest file (the mesh or one it references) the loader reads, in bytes: 4 GiB.
#: Anything larger is refused before a byte is read.
MAX_FILE_BYTES = 4 * 1024**3


class BadFile(Exception):
    """Internal: what is wrong with the file; `load_mesh` adds the path."""


# inside `reads_recorded`: every file `read_regular` has read, in order
_reads: contextvars.ContextVar[list | None] = contextvars.ContextVar("reads", default=None)


@contextlib.contextmanager
def reads_recorded():
    """Yield the list of the paths `read_regular` reads inside the block: every file the
    loader reads goes through it, so this says which files a mesh depends on
    (`reliefkit.io.meshes.references`)."""
    read: list[Path] = []
    token = _reads.set(read)
    try:
        yield read
    finally:
        _reads.reset(token)


def regular_file_size(path: str | os.PathLike) -> int:
    """The size of `path`, checked to be a regular file (symlinks followed) within the cap.

    FIFOs, devices (a link to /dev/zero), sockets and directories raise `BadFile`, so nothing
    blocks on a pipe or reads an endless device.
    """
    try:
        info = os.stat(path)
    except OSError as exc:
        raise BadFile(f"cannot read the file ({exc.strerror or exc})") from None
    _check_stat(info)
    return info.st_size


def read_regular(path: str | os.PathLike) -> bytes:
    """The bytes of `path`, a regular file of at most `MAX_FILE_BYTES` (else `BadFile`).

    The file is opened without blocking and checked again on the open descriptor, so a
    file swapped for a FIFO after the first check cannot block either, and at most the
    cap plus one byte is ever read.
    """
    regular_file_size(path)
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    except OSError as exc:
        raise BadFile(f"cannot read the file ({exc.strerror or exc})") from None
    try:
        info = os.fstat(fd)
        _check_stat(info)
        with os.fdopen(fd, "rb", closefd=False) as stream:
            data = _read_capped(stream, info.st_size)
    except OSError as exc:
        raise BadFile(f"cannot read the file ({exc.strerror or exc})") from None
    finally:
        os.close(fd)
    if len(data) > MAX_FILE_BYTES:
        raise BadFile(_too_large(len(data)))
    read = _reads.get()
    if read is not None:
        read.append(Path(path))
    return data


_CHUNK_BYTES = 1 << 20  # what is read at a time past the size the file reported


def _read_capped(stream, size: int) -> bytes:
    """Everything `stream` holds, up to `MAX_FILE_BYTES` plus one byte.

    It asks for the reported `size` plus one byte (not the cap, whose buffer tracemalloc and
    the allocator would count); a file that turns out longer (it grew, or reports 0 bytes
    as /proc files do) is read on in chunks until its end or past the cap.
    """
    limit = MAX_FILE_BYTES + 1
    data = stream.read(min(size + 1, limit))
    if len(data) <= size or len(data) >= limit:  # its end (where reported, or before) or the cap
        return data
    chunks, total = [data], len(data)
    while total < limit:
        chunk = stream.read(min(_CHUNK_BYTES, limit - total))
        if not chunk:
            break
        chunks.append(chunk)
        total += len(chunk)
    return b"".join(chunks)


def _check_stat(info: os.stat_result) -> None:
    if stat.S_ISDIR(info.st_mode):
        raise BadFile("is a directory, not a mesh file")
    if not stat.S_ISREG(info.st_mode):
        kind = ("a FIFO (named pipe)" if stat.S_ISFIFO(info.st_mode)
                else "a device" if stat.S_ISCHR(info.st_mode) or stat.S_ISBLK(info.st_mode)
                else "a socket" if stat.S_ISSOCK(info.st_mode) else "not a plain file")
        raise BadFile(f"is not a regular file (it is {kind}); give a file on disk")
    if info.st_size > MAX_FILE_BYTES:
        raise BadFile(_too_large(info.st_size))


def _too_large(size: int) -> str:
    return (f"is too large ({size} bytes; the loader reads files of at most "
            f"{MAX_FILE_BYTES} bytes)")


def decode_text(data: bytes, what: str) -> str:
    """Decode a text format: UTF-8, else Latin-1 (which every byte string decodes as)."""
    if b"\0" in data:
        raise BadFile(f"is not a text {what} file (it contains NUL bytes); is it corrupt?")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        return data.decode("latin-1")


def as_utf8(data: bytes, what: str) -> bytes:
    """Text re-encoded as UTF-8, so trimesh never needs to guess an encoding."""
    return decode_text(data, what).encode("utf-8")


def check_range(indices: np.ndarray, count: int, where: str = "") -> None:
    """Raise for the first index outside [0, count)."""
    bad = indices[(indices < 0) | (indices >= count)]
    if bad.size:
        raise BadFile(f"face index {int(bad[0])} out of range for {count} vertices{where}")
