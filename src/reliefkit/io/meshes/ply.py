"""The structural check of PLY files (ASCII and binary): the body holds what the header says."""

from __future__ import annotations

import re
from dataclasses import dataclass, replace

import numpy as np

from .badfile import BadFile

# PLY property types and their numpy codes
_PLY_TYPES = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1",
    "short": "i2", "int16": "i2", "ushort": "u2", "uint16": "u2",
    "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
    "float": "f4", "float32": "f4", "double": "f8", "float64": "f8",
}  # fmt: skip


@dataclass(frozen=True)
class _PlyProperty:
    name: str
    type: str  # numpy code of the value (of each list item, for a list)
    count_type: str | None = None  # numpy code of the list length; None for a scalar


@dataclass(frozen=True)
class _PlyElement:
    name: str
    count: int
    properties: tuple[_PlyProperty, ...]


def check_ply(data: bytes) -> bytes:
    """Check that the body holds every row the PLY header declares."""
    encoding, elements, body = _ply_header(data)
    if encoding == "ascii":
        _check_ply_ascii(data[body:], elements)
    else:
        endian = "<" if encoding == "binary_little_endian" else ">"
        _check_ply_binary(data, body, elements, endian)
    return data


def _ply_header(data: bytes) -> tuple[str, list[_PlyElement], int]:
    """Parse a PLY header: (encoding, elements, offset of the body)."""
    if not data.startswith(b"ply"):
        raise BadFile("is not a PLY file (it does not start with 'ply')")
    end = re.search(rb"\bend_header[^\n]*\n", data)
    if end is None:
        raise BadFile("truncated PLY: the header has no 'end_header' line")
    encoding, elements = None, []
    for line in data[: end.start()].decode("latin-1").splitlines()[1:]:
        words = line.split()
        try:
            if words[:1] == ["format"]:
                encoding = words[1]
            elif words[:1] == ["element"]:
                elements.append(_PlyElement(words[1], int(words[2]), ()))
            elif words[:2] == ["property", "list"]:
                prop = _PlyProperty(words[4], _PLY_TYPES[words[3]], _PLY_TYPES[words[2]])
                elements[-1] = replace(elements[-1], properties=elements[-1].properties + (prop,))
            elif words[:1] == ["property"]:
                prop = _PlyProperty(words[2], _PLY_TYPES[words[1]])
                elements[-1] = replace(elements[-1], properties=elements[-1].properties + (prop,))
        except (IndexError, KeyError, ValueError):
            raise BadFile(f"malformed PLY header line '{line.strip()}'") from None
    if encoding not in ("ascii", "binary_little_endian", "binary_big_endian"):
        raise BadFile(f"unknown PLY format '{encoding}'")
    if any(e.count < 0 for e in elements):
        raise BadFile("malformed PLY header (a negative element count)")
    return encoding, elements, end.end()


def _check_ply_ascii(body: bytes, elements: list[_PlyElement]) -> None:
    """ASCII PLY rows are lines (as trimesh reads them); a cut file ends in a short row."""
    lines = body.splitlines()
    start = 0
    for element in elements:
        have = max(0, min(element.count, len(lines) - start))
        if have < element.count:
            raise BadFile(
                f"truncated PLY: element '{element.name}' has {have} of its {element.count} rows"
            )
        start += element.count
    last = next((e for e in reversed(elements) if e.count), None)
    if last is not None and not _ply_ascii_row_complete(lines[start - 1].split(), last):
        raise BadFile(f"truncated PLY: the last row of element '{last.name}' is cut off")


def _ply_ascii_row_complete(tokens: list[bytes], element: _PlyElement) -> bool:
    need = 0
    for prop in element.properties:
        if prop.count_type is not None:
            if need >= len(tokens):
                return False
            try:
                need += int(float(tokens[need]))
            except (ValueError, OverflowError):
                return False
        need += 1
    return len(tokens) >= need


def _check_ply_binary(data: bytes, offset: int, elements: list[_PlyElement], endian: str) -> None:
    """Binary PLY: each element's rows must fit; lists must keep their first row's length."""
    for element in elements:
        if element.count == 0 or not element.properties:
            continue
        row = _ply_row_dtype(data, offset, element, endian)
        if row is None:
            raise BadFile(f"truncated PLY: element '{element.name}' is cut off")
        size = element.count * row.itemsize
        present = min(element.count, (len(data) - offset) // max(row.itemsize, 1))
        rows = np.frombuffer(data, dtype=row, count=present, offset=offset)
        if any(np.any(rows[f] != rows[f][0]) for f in row.names if f.endswith("#count")):
            raise BadFile(
                f"binary PLY element '{element.name}' mixes list lengths (e.g. triangles "
                "and quads), which the reader (trimesh) cannot load; triangulate it"
            )
        if offset + size > len(data):
            raise BadFile(
                f"truncated PLY: element '{element.name}' needs {size} bytes, "
                f"{max(0, len(data) - offset)} remain"
            )
        offset += size


def _ply_row_dtype(data: bytes, offset: int, element: _PlyElement, endian: str) -> np.dtype | None:
    """The structured dtype of a binary row, with list lengths taken from the first row.

    None when the first row is cut off.
    """
    fields, width = [], 0
    for prop in element.properties:
        if prop.count_type is None:
            fields.append((prop.name, endian + prop.type))
            width += np.dtype(prop.type).itemsize
            continue
        count_type = np.dtype(endian + prop.count_type)
        if offset + width + count_type.itemsize > len(data):
            return None
        length = int(np.frombuffer(data, count_type, 1, offset + width)[0])
        fields += [(prop.name + "#count", count_type), (prop.name, endian + prop.type, (length,))]
        width += count_type.itemsize + length * np.dtype(prop.type).itemsize
    try:
        return np.dtype(fields)
    except (TypeError, ValueError) as exc:  # duplicate property names, absurd list lengths
        raise BadFile(f"malformed PLY element '{element.name}' ({exc})") from None
