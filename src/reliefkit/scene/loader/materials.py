"""Colours, materials and textures of trimesh visuals, as linear RGBA and sRGB texture bytes.

sRGB-encoded 8-bit colours are decoded; glTF colours are linear by specification and kept.
"""

from __future__ import annotations

import numpy as np
import trimesh

from ...colorspace import srgb_decode
from .badfile import BadFile

#: Linear base colour of a surface whose file gives none.
DEFAULT_COLOR = (0.8, 0.8, 0.8, 1.0)

_SRGB_BYTE_TO_LINEAR = srgb_decode(np.arange(256) / 255.0)


def is_face_colored(visual) -> bool:
    return isinstance(visual, trimesh.visual.ColorVisuals) and visual.kind == "face"


def decode_colors(colors, srgb: bool) -> np.ndarray:
    """(N, 3 or 4) colours (8/16-bit integers or floats in [0, 1]) -> (N, 4) linear float."""
    colors = np.asarray(colors)
    if np.issubdtype(colors.dtype, np.integer):
        unit = colors / float(np.iinfo(colors.dtype).max)
    else:
        unit = np.nan_to_num(colors.astype(np.float64), nan=0.0)
    unit = np.clip(unit, 0.0, 1.0)
    if unit.shape[1] == 3:
        unit = np.column_stack([unit, np.ones(len(unit))])
    if srgb and colors.dtype == np.uint8:
        return np.column_stack([_SRGB_BYTE_TO_LINEAR[colors[:, :3]], unit[:, 3]])
    if srgb:
        return np.column_stack([srgb_decode(unit[:, :3]), unit[:, 3]])
    return unit


def base_color(
    visual, count: int, srgb: bool
) -> tuple[np.ndarray, np.ndarray | None, np.ndarray | None]:
    """Linear colours, UVs and base-colour texture of the `count` vertices of a visual."""
    if isinstance(visual, trimesh.visual.ColorVisuals):
        if visual.kind == "vertex":
            return decode_colors(visual.vertex_colors, srgb), None, None
        return np.tile(DEFAULT_COLOR, (count, 1)), None, None
    if not isinstance(visual, trimesh.visual.TextureVisuals):
        return np.tile(DEFAULT_COLOR, (count, 1)), None, None
    factor, image = _material(visual.material)
    colors = np.tile(factor, (count, 1))
    vertex_colors = visual.vertex_attributes.get("color")
    if vertex_colors is not None and len(vertex_colors) == count:
        colors = colors * decode_colors(vertex_colors, srgb)
    uvs = visual.uv
    if uvs is None or len(uvs) != count:
        return colors, None, None
    uvs = np.asarray(uvs, dtype=np.float64)
    bad = int((~np.isfinite(uvs)).any(axis=1).sum())
    if bad:
        raise BadFile(f"{bad} texture coordinates are NaN or Inf")
    texture = None if image is None else _texture_array(image)
    return colors, uvs, texture


def _material(material) -> tuple[np.ndarray, object]:
    """(linear RGBA factor, PIL image or None) of a trimesh material."""
    if isinstance(material, trimesh.visual.material.PBRMaterial):
        factor = material.baseColorFactor  # linear by the glTF specification
        factor = np.ones(4) if factor is None else np.asarray(factor) / 255.0
        return factor, material.baseColorTexture
    if isinstance(material, trimesh.visual.material.SimpleMaterial):
        image = material.image
        kd = material.kwargs.get("kd")  # present only when the .mtl file gave Kd
        if kd is None:
            return np.array(DEFAULT_COLOR if image is None else (1.0, 1.0, 1.0, 1.0)), image
        kd = np.atleast_1d(np.asarray(kd, dtype=np.float64))
        rgb = kd[:3] if kd.size >= 3 else np.full(3, kd[0])
        return np.append(srgb_decode(rgb), 1.0), image
    return np.array(DEFAULT_COLOR), None


def _texture_array(image) -> np.ndarray:
    """A PIL image as (h, w, 4) uint8 RGBA with row 0 at v = 0 (PIL's row 0 is the top)."""
    try:
        rgba = np.asarray(image.convert("RGBA"), dtype=np.uint8)
    except Exception as exc:  # noqa: BLE001 - PIL decodes lazily, so errors surface here
        raise BadFile(f"its texture image could not be decoded ({exc})") from None
    return np.ascontiguousarray(rgba[::-1])


def sample_linear(texture: np.ndarray, uvs: np.ndarray) -> np.ndarray:
    """Bilinear, repeating lookup of an sRGB texture at UVs, returning linear RGBA."""
    h, w = texture.shape[:2]
    linear = np.concatenate(
        [_SRGB_BYTE_TO_LINEAR[texture[..., :3]], texture[..., 3:] / 255.0], axis=-1
    )
    x = uvs[:, 0] * w - 0.5
    y = uvs[:, 1] * h - 0.5
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = (x - x0)[:, None], (y - y0)[:, None]
    i0, j0 = x0.astype(np.int64) % w, y0.astype(np.int64) % h  # UVs are finite here
    i1, j1 = (i0 + 1) % w, (j0 + 1) % h
    top = linear[j0, i0] * (1 - fx) + linear[j0, i1] * fx
    bottom = linear[j1, i0] * (1 - fx) + linear[j1, i1] * fx
    return top * (1 - fy) + bottom * fy
