"""The structural check of STL files (ASCII and binary): truncation."""

from __future__ import annotations

import re

from .badfile import BadFile


def check_stl(data: bytes) -> bytes:
    """Detect truncated STL files, which trimesh reads as an empty scene."""
    count = int.from_bytes(data[80:84], "little") if len(data) >= 84 else -1
    expected = 84 + 50 * count
    if len(data) == expected:
        return data
    if data.lstrip()[:5].lower() == b"solid" and b"\0" not in data:
        if not re.search(rb"endsolid[^\n]*\s*$", data[-1024:]):
            raise BadFile("truncated ASCII STL (no final 'endsolid' line)")
        return data
    if count < 0:
        raise BadFile(
            f"truncated or not an STL file: {len(data)} bytes is less than a binary STL "
            "header (84 bytes) and it is not ASCII STL"
        )
    if len(data) < expected:
        raise BadFile(
            f"truncated or corrupt binary STL: its header declares {count} triangles "
            f"({expected} bytes) but the file has {len(data)} bytes"
        )
    return data[:expected]  # trailing bytes after the declared triangles are ignored
