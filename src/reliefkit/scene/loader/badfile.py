"""What every part of the loader shares: the `BadFile` exception and small text/index checks.

trimesh silently accepts some broken files (a truncated STL reads as an empty scene, a
truncated ASCII PLY or OFF loses its last faces, missing .mtl/texture/image files are
skipped, out-of-range PLY and glTF indices are kept as they are), so each format gets a
small structural check before trimesh parses it (one module per format family), and the
parsed geometry is checked again afterwards. Each check raises `BadFile`; `load_mesh` turns
it into one `MeshError` that starts with the path.
"""

from __future__ import annotations

import numpy as np


class BadFile(Exception):
    """Internal: what is wrong with the file; `load_mesh` adds the path."""


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
