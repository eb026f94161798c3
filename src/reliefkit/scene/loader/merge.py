"""Merging the placed parts into one `RenderMesh`: one shared texture or baked colours."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from ...errors import MeshError
from ..mesh import RenderMesh
from .badfile import BadFile
from .materials import sample_linear
from .normals import usable_normals
from .scene import Part


def render_mesh(parts: list[Part], label: str, path: Path) -> RenderMesh:
    """Concatenate the parts and complete the normals."""
    parts, texture = _resolve_textures(parts)
    offsets = np.cumsum([0] + [len(p.positions) for p in parts[:-1]])
    positions = np.concatenate([p.positions for p in parts])
    faces = np.concatenate([p.faces + o for p, o in zip(parts, offsets, strict=True)])
    uvs = None
    if all(p.uvs is not None for p in parts):
        uvs = np.concatenate([p.uvs for p in parts])
    normals = usable_normals(np.concatenate([p.normals for p in parts]), positions, faces)
    colors = np.clip(np.concatenate([p.colors for p in parts]), 0.0, 1.0)
    try:
        return RenderMesh(
            positions, faces, normals, colors, uvs, texture, name=label,
            extra={"source": str(path)},
        )  # fmt: skip
    except MeshError as exc:  # the final guard; name the file like every other message
        raise BadFile(str(exc).removeprefix(f"{label}: ")) from None


def _resolve_textures(parts: list[Part]) -> tuple[list[Part], np.ndarray | None]:
    """Keep one texture shared by every part; otherwise bake textures into vertex colours.

    A `RenderMesh` has one texture and no way to mark vertices as untextured, so the texture
    is kept only when every part uses the same one.
    """
    textures = [p.texture for p in parts if p.texture is not None]
    if not textures:
        return parts, None
    first = textures[0]
    if len(textures) == len(parts) and all(_same(t, first) for t in textures):
        return parts, first
    baked = [
        p if p.texture is None
        else replace(p, colors=p.colors * sample_linear(p.texture, p.uvs), texture=None)
        for p in parts
    ]  # fmt: skip
    return [replace(p, uvs=None) for p in baked], None


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    return a is b or (a.shape == b.shape and np.array_equal(a, b))
