"""Merging the placed parts into one `RenderMesh`, each distinct material kept once.

The warnings of the load (textures that could not be read, see :mod:`.materials`) go to the
mesh's ``extra["warnings"]``: one human-readable line each, present only when there are some.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...errors import MeshError
from ...scene.mesh import Material, RenderMesh
from .badfile import BadFile
from .materials import take_warnings
from .normals import usable_normals
from .scene import Part


def render_mesh(parts: list[Part], label: str, path: Path) -> RenderMesh:
    """Concatenate the parts, give each triangle its part's material, complete the normals.

    A single part's arrays are used as they are, and colours are clipped straight into
    float32, so a large mesh is not held twice.
    """
    materials, part_material = _distinct([p.material for p in parts])
    positions = _joined([p.positions for p in parts])
    faces = _joined_faces(parts)
    material = np.repeat(part_material, [len(p.faces) for p in parts])
    uvs = None
    if any(p.uvs is not None for p in parts):  # parts without UVs have untextured materials
        uvs = _joined([np.zeros((len(p.positions), 2)) if p.uvs is None else p.uvs
                       for p in parts])
    normals = usable_normals(_file_normals(parts), positions, faces)
    colors = _clipped_colors(parts)
    extra: dict = {"source": str(path)}
    found = take_warnings()
    if found:
        extra["warnings"] = found
    try:
        return RenderMesh(positions, faces, normals, colors, uvs, name=label,
                          extra=extra, materials=materials, material=material)
    except MeshError as exc:  # the final guard; name the file like every other message
        raise BadFile(str(exc).removeprefix(f"{label}: ")) from None


def _joined(arrays: list[np.ndarray]) -> np.ndarray:
    return arrays[0] if len(arrays) == 1 else np.concatenate(arrays)


def _joined_faces(parts: list[Part]) -> np.ndarray:
    """Every part's faces, offset by the vertices of the parts before it."""
    faces = _joined([p.faces for p in parts])
    start = vertices = 0
    for part in parts:
        if vertices:
            faces[start:start + len(part.faces)] += vertices
        start, vertices = start + len(part.faces), vertices + len(part.positions)
    return faces


def _file_normals(parts: list[Part]) -> np.ndarray | None:
    """The parts' file normals joined (NaN rows for parts without), None if none has some."""
    if all(p.normals is None for p in parts):
        return None
    return _joined([np.full((len(p.positions), 3), np.nan) if p.normals is None else p.normals
                    for p in parts])


def _clipped_colors(parts: list[Part]) -> np.ndarray:
    """(V, 4) float32 vertex colours clipped to [0, 1] (clipped in float64, then rounded);
    one colour shared by every vertex stays a broadcast view (no memory per vertex)."""
    rows = [p.colors[:1] for p in parts if p.colors.strides[0] == 0 and len(p.colors)]
    if len(rows) == len(parts) and all(np.array_equal(r, rows[0]) for r in rows):
        row = np.clip(rows[0], 0.0, 1.0).astype(np.float32)
        return np.broadcast_to(row[0], (sum(len(p.colors) for p in parts), 4))
    colors = np.empty((sum(len(p.colors) for p in parts), 4), np.float32)
    start = 0
    for part in parts:
        np.clip(part.colors, 0.0, 1.0, out=colors[start:start + len(part.colors)])
        start += len(part.colors)
    return colors


def _distinct(materials: list[Material]) -> tuple[list[Material], list[int]]:
    """The distinct materials in order of first use, and each input's index among them.

    Parts of one trimesh material share one `Material` object, so most look-ups are by
    identity; only a new object is compared by value (a file that repeats a material).
    """
    distinct: list[Material] = []
    by_id: dict[int, int] = {}
    index = []
    for material in materials:
        found = by_id.get(id(material))
        if found is None:
            found = next((k for k, m in enumerate(distinct) if m == material), len(distinct))
            if found == len(distinct):
                distinct.append(material)
            by_id[id(material)] = found
        index.append(found)
    return distinct, index
