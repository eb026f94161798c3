"""The structural check of OFF files: declared counts and face indices."""

from __future__ import annotations

import re

import numpy as np

from .badfile import BadFile, check_range, decode_text


def check_off(data: bytes) -> bytes:
    """Check an OFF file's counts and face indices, line by line as trimesh reads it."""
    text = re.sub(r"#[^\n]*", "", decode_text(data, "OFF"))
    found = re.search(r"COFF|OFF", text)
    if found is None:
        raise BadFile("is not an OFF file (no 'OFF' header)")
    lines = [line for line in text[found.end() :].splitlines() if line.strip()]
    counts = lines[0].split() if lines else []
    try:
        n_vertices, n_faces = int(counts[0]), int(counts[1])
    except (IndexError, ValueError):
        raise BadFile(f"malformed OFF count line '{' '.join(counts)}'") from None
    vertex_lines = lines[1 : 1 + n_vertices]
    face_lines = lines[1 + n_vertices : 1 + n_vertices + n_faces]
    if len(vertex_lines) < n_vertices or len(face_lines) < n_faces:
        raise BadFile(
            f"truncated: its header declares {n_vertices} vertices and {n_faces} faces, "
            f"the file has {len(vertex_lines)} and {len(face_lines)}"
        )
    try:
        indices = _off_face_indices(face_lines)
    except OverflowError:
        raise BadFile("has a face index too large to be real; is it corrupt?") from None
    check_range(indices, n_vertices)
    return data


def _off_face_indices(lines: list[str]) -> np.ndarray:
    """The vertex indices on OFF face lines ('n i1 ... in [colour]')."""
    try:  # fast path: every line holds n + 1 integers (and maybe an integer colour)
        values = np.array(list(map(int, " ".join(lines).split())), dtype=np.int64)
        table = values.reshape(len(lines), -1)
        n = int(table[0, 0])
        if n + 1 <= table.shape[1] and (table[:, 0] == n).all():
            return table[:, 1 : n + 1].ravel()
    except (ValueError, OverflowError, IndexError):
        pass  # float colours, mixed polygon sizes, ...: go line by line
    return np.array([i for line in lines for i in _off_face(line.split())], dtype=np.int64)


def _off_face(tokens: list[str]) -> list[int]:
    """The vertex indices of one OFF face line."""
    try:
        count = int(tokens[0])
        indices = [int(t) for t in tokens[1 : 1 + count]]
    except ValueError:
        raise BadFile(f"malformed OFF face line '{' '.join(tokens)}'") from None
    if len(indices) < count:
        raise BadFile(f"truncated or malformed OFF face line '{' '.join(tokens)}'")
    return indices
