"""Colours and materials of trimesh visuals: linear RGBA, `Material`s with sRGB textures.

sRGB-encoded 8-bit colours are decoded; glTF colours are linear by specification and kept.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import trimesh

from ...colorspace import srgb_decode
from ..mesh import Material
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


class SurfaceReader:
    """Colours, UVs and `Material`s of trimesh visuals, each material and image read once.

    Parts of one file share trimesh materials and images; converting each once keeps equal
    materials identical objects, so merging them is cheap.
    """

    def __init__(self, srgb: bool):
        self.srgb = srgb
        # keyed by id(); each entry keeps its trimesh object alive so the id stays its own
        self._materials: dict[int, tuple[object, Material]] = {}
        self._images: dict[int, tuple[object, np.ndarray]] = {}

    def surface(self, visual, count: int) -> tuple[np.ndarray, np.ndarray | None, Material]:
        """Linear vertex colours, UVs and the material of the `count` vertices of a visual."""
        if isinstance(visual, trimesh.visual.ColorVisuals) and visual.kind == "vertex":
            return decode_colors(visual.vertex_colors, self.srgb), None, Material()
        if not isinstance(visual, trimesh.visual.TextureVisuals):
            return np.tile(DEFAULT_COLOR, (count, 1)), None, Material()
        material = self.material(visual.material)
        colors = np.ones((count, 4))
        vertex_colors = visual.vertex_attributes.get("color")
        if vertex_colors is not None and len(vertex_colors) == count:
            colors = decode_colors(vertex_colors, self.srgb)
        uvs = visual.uv
        if uvs is None or len(uvs) != count:
            untextured = material if material.texture is None else replace(material, texture=None)
            return colors, None, untextured
        uvs = np.asarray(uvs, dtype=np.float64)
        bad = int((~np.isfinite(uvs)).any(axis=1).sum())
        if bad:
            raise BadFile(f"{bad} texture coordinates are NaN or Inf")
        return colors, uvs, material

    def material(self, material) -> Material:
        """A trimesh material as a `Material` (linear factor, sRGB texture)."""
        kept = self._materials.get(id(material))
        if kept is None:
            kept = self._materials[id(material)] = (material, self._convert(material))
        return kept[1]

    def _convert(self, material) -> Material:
        name = getattr(material, "name", None) or ""
        if isinstance(material, trimesh.visual.material.PBRMaterial):
            factor = material.baseColorFactor  # linear by the glTF specification
            factor = np.ones(4) if factor is None else np.asarray(factor) / 255.0
            return Material(name, factor, self._texture(material.baseColorTexture))
        if isinstance(material, trimesh.visual.material.SimpleMaterial):
            image = None if _is_placeholder(material.image) else material.image
            kd = material.kwargs.get("kd")  # present only when the .mtl file gave Kd
            if kd is None:
                return Material(name, DEFAULT_COLOR if image is None else (1.0, 1.0, 1.0, 1.0),
                                self._texture(image))
            kd = np.atleast_1d(np.asarray(kd, dtype=np.float64))
            rgb = kd[:3] if kd.size >= 3 else np.full(3, kd[0])
            return Material(name, np.append(srgb_decode(rgb), 1.0), self._texture(image))
        return Material(name, DEFAULT_COLOR)

    def _texture(self, image) -> np.ndarray | None:
        if image is None:
            return None
        kept = self._images.get(id(image))
        if kept is None:
            kept = self._images[id(image)] = (image, _texture_array(image))
        return kept[1]


def _is_placeholder(image) -> bool:
    """Whether `image` is the grey 2x2 trimesh invents for UVs without a material."""
    if image is None or getattr(image, "format", None) is not None:  # read from a file
        return False
    placeholder = trimesh.visual.material.color_image()
    return image.size == placeholder.size and np.array_equal(np.asarray(image),
                                                             np.asarray(placeholder))


def _texture_array(image) -> np.ndarray:
    """A PIL image as (h, w, 4) uint8 RGBA with row 0 at v = 0 (PIL's row 0 is the top)."""
    try:
        rgba = np.asarray(image.convert("RGBA"), dtype=np.uint8)
    except Exception as exc:  # noqa: BLE001 - PIL decodes lazily, so errors surface here
        raise BadFile(f"its texture image could not be decoded ({exc})") from None
    return np.ascontiguousarray(rgba[::-1])
