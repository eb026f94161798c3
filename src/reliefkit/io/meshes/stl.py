"""The structural check of STL files (ASCII and binary): truncation; binary ones read in place.

trimesh reads a binary STL's body with ``read()``, a second copy of the whole file;
`binary_stl` gives it the same arrays as views of the bytes already read.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

from .badfile import BadFile

_HEADER = 84  # 80 bytes of text, the uint32 triangle count
_TRIANGLE = np.dtype([("normals", "<f4", (3,)), ("vertices", "<f4", (3, 3)),
                      ("attributes", "<u2")])  # 50 bytes, as trimesh reads them


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


@dataclass
class BinaryStl:
    """A binary STL (checked by `check_stl`) as the keyword arrays trimesh's reader makes."""

    data: bytes

    def scene_kwargs(self, name: str) -> dict:
        """What trimesh's `load_stl` returns for the file, its arrays views of the bytes."""
        from trimesh import util

        try:
            metadata = {"header": util.decode_text(self.data[:80]).strip()}
        except Exception:  # noqa: BLE001 - any garbage may be there, as trimesh allows
            metadata = {}
        blob = np.frombuffer(self.data, _TRIANGLE, offset=_HEADER)
        self.data = b""  # the views keep the bytes alive as long as trimesh needs them
        mesh = {"vertices": blob["vertices"].reshape(-1, 3),
                "face_normals": blob["normals"].reshape(-1, 3),
                "faces": np.arange(3 * len(blob)).reshape(-1, 3),
                "face_attributes": {"stl": blob["attributes"]},
                "metadata": metadata, "file_type": "stl", "process": False}
        return {"process": False, "geometry": {name: mesh},
                "graph": [{"geometry": name, "frame_to": name}]}


def binary_stl(data: bytes) -> BinaryStl | None:
    """`data` as a `BinaryStl` when it is one with at least one triangle, else None."""
    count = int.from_bytes(data[80:84], "little") if len(data) >= _HEADER else -1
    if count < 1 or len(data) != _HEADER + _TRIANGLE.itemsize * count:
        return None
    return BinaryStl(data)
