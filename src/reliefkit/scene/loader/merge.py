"""Merging the placed parts into one `RenderMesh`, each distinct material kept once.

The warnings of the load (textures that could not be read, see :mod:`.materials`) go to the
mesh's ``extra["warnings"]``: one human-readable line each, present only when there are some.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...errors import MeshError
from ..mesh import Material, RenderMesh
from .badfile import BadFile
from .materials import take_warnings
from .normals import usable_normals
from .scene import Part


def render_mesh(parts: list[Part], label: str, path: Path) -> RenderMesh:
    """Concatenate the parts, give each triangle its part's material, complete the normals."""
    materials, part_material = _distinct([p.material for p in parts])
    offsets = np.cumsum([0] + [len(p.positions) for p in parts[:-1]])
    positions = np.concatenate([p.positions for p in parts])
    faces = np.concatenate([p.faces + o for p, o in zip(parts, offsets, strict=True)])
    material = np.repeat(part_material, [len(p.faces) for p in parts])
    uvs = None
    if any(p.uvs is not None for p in parts):  # parts without UVs have untextured materials
        uvs = np.concatenate([np.zeros((len(p.positions), 2)) if p.uvs is None else p.uvs
                              for p in parts])
    normals = usable_normals(np.concatenate([p.normals for p in parts]), positions, faces)
    colors = np.clip(np.concatenate([p.colors for p in parts]), 0.0, 1.0)
    extra: dict = {"source": str(path)}
    found = take_warnings()
    if found:
        extra["warnings"] = found
    try:
        return RenderMesh(positions, faces, normals, colors, uvs, name=label,
                          extra=extra, materials=materials, material=material)
    except MeshError as exc:  # the final guard; name the file like every other message
        raise BadFile(str(exc).removeprefix(f"{label}: ")) from None


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
