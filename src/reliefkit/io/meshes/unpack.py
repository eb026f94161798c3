"""A mesh file and the files it references, given as bytes, unpacked into a private
temporary folder under their own names (`load_mesh_bytes` loads it from there, so every
format resolves its references exactly as on disk), and messages that name that folder
rewritten to name the caller's file instead.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterator, Mapping
from pathlib import Path, PurePosixPath

from ...errors import MeshError


@contextlib.contextmanager
def unpacked(file_name: str, data, files: Mapping[str, bytes]) -> Iterator[Path]:
    """The path of ``data`` saved as ``file_name``'s last part in a private folder, with
    ``files`` beside it at their relative names (POSIX); the folder is removed on exit.
    A name that is absolute or goes up (``..``) is refused before anything is written: a
    caller's bytes never land outside the folder."""
    base = Path(file_name).name
    if base in ("", ".", ".."):
        raise MeshError(f"a mesh's bytes need its file name (its suffix picks the "
                        f"format), got {file_name!r}")
    for name in files:
        relative = PurePosixPath(name)
        if relative.is_absolute() or ".." in relative.parts or not relative.parts:
            raise MeshError(f"{file_name}: {name!r} names a file outside its folder (the "
                            "files a mesh comes with are named relative to it, without '..')")
    with tempfile.TemporaryDirectory(prefix="reliefkit-mesh-") as folder:
        for name, content in {**files, base: data}.items():
            path = Path(folder).joinpath(*PurePosixPath(name).parts)
            try:
                path.parent.mkdir(parents=True, exist_ok=True)
                path.write_bytes(content)
            except OSError as exc:
                raise MeshError(f"{file_name}: could not unpack {name!r} "
                                f"({exc.strerror or exc})") from None
        yield Path(folder) / base


def renamed(text: str, private: Path, file_name: str) -> str:
    """``text`` with the private folder of ``private`` (the unpacked file) replaced by
    ``file_name``'s folder (none for a bare name), so it names the caller's files."""
    folder, shown = str(private.parent), str(Path(file_name).parent)
    prefix = "" if shown == "." else shown + os.sep
    return text.replace(folder + os.sep, prefix).replace(folder, shown)
