"""Colours and materials of trimesh visuals: linear RGBA, `Material`s with sRGB textures.

sRGB-encoded 8-bit colours are decoded; glTF colours are linear by specification and kept.

Alpha follows each format's rules. glTF: ``alphaMode`` (default OPAQUE: alpha ignored; MASK
with ``alphaCutoff``, default 0.5; BLEND) becomes `Material.alpha_mode` / `alpha_cutoff`;
``doubleSided`` becomes `Material.double_sided`.
OBJ/MTL: alpha comes only from ``d`` (or ``Tr`` = 1 - d, when there is no ``d``; ``Tr 1``, which
exporters such as MeshLab write for opaque materials, is read as opaque with a warning) and
``map_d``; a material with d = 1 and no map_d is OPAQUE (an RGBA ``map_Kd``'s alpha channel
is unused), otherwise BLEND with the factor's alpha d, and the texture's alpha channel is
kept only when ``map_d`` names the ``map_Kd`` image (a separate map_d image is not read: one
warning). Formats without materials (PLY, OFF, STL vertex or face colours) are OPAQUE.

A texture image that cannot be decoded (corrupt or truncated data, or more pixels than
`max_texture_pixels()`) is not an error: the material keeps its colour factor without the
texture and `SurfaceReader.warnings` gets one line for it, which the merged mesh carries in
``extra["warnings"]``. No PIL warning reaches stderr.
"""

from __future__ import annotations

import contextvars
import warnings
from dataclasses import replace

import numpy as np
import trimesh
from PIL import Image

from ...colorspace import srgb_decode
from ...scene.mesh import ALPHA_MODES, Material
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


def uniform_colors(color, count: int) -> np.ndarray:
    """(count, 4) float64 of one colour, as a read-only view that takes no memory per vertex
    (a large mesh without colours would otherwise carry 32 bytes per vertex of them)."""
    return np.broadcast_to(np.asarray(color, dtype=np.float64), (count, 4))


class SurfaceReader:
    """Colours, UVs and `Material`s of trimesh visuals, each material and image read once.

    Parts of one file share trimesh materials and images; converting each once keeps equal
    materials identical objects, so merging them is cheap.
    """

    def __init__(self, srgb: bool):
        self.srgb = srgb
        #: one human-readable line per problem worked around (see the module docstring)
        self.warnings: list[str] = _start_reader_warnings()
        # keyed by id(); each entry keeps its trimesh object alive so the id stays its own
        self._materials: dict[int, tuple[object, Material]] = {}
        self._images: dict[int, tuple[object, np.ndarray]] = {}

    def surface(self, visual, count: int) -> tuple[np.ndarray, np.ndarray | None, Material]:
        """Linear vertex colours, UVs and the material of the `count` vertices of a visual."""
        if isinstance(visual, trimesh.visual.ColorVisuals) and visual.kind == "vertex":
            return decode_colors(visual.vertex_colors, self.srgb), None, Material()
        if not isinstance(visual, trimesh.visual.TextureVisuals):
            return uniform_colors(DEFAULT_COLOR, count), None, Material()
        material = self.material(visual.material)
        colors = uniform_colors((1.0, 1.0, 1.0, 1.0), count)
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
            mode, cutoff = _gltf_alpha(material)
            return Material(name, factor, self._texture(material.baseColorTexture, name),
                            alpha_mode=mode, alpha_cutoff=cutoff,
                            double_sided=bool(getattr(material, "doubleSided", False)))
        if isinstance(material, trimesh.visual.material.SimpleMaterial):
            image = None if _is_placeholder(material.image) else material.image
            kd = material.kwargs.get("kd")  # present only when the .mtl file gave Kd
            texture = self._texture(image, name)
            if kd is None:
                color = np.array(DEFAULT_COLOR if texture is None else (1.0, 1.0, 1.0, 1.0))
            else:
                kd = np.atleast_1d(np.asarray(kd, dtype=np.float64))
                rgb = kd[:3] if kd.size >= 3 else np.full(3, kd[0])
                color = np.append(srgb_decode(rgb), 1.0)
            dissolve, texture_alpha = self._mtl_alpha(material, name, image)
            color[3] = dissolve
            blend = dissolve < 1.0 or (texture_alpha and texture is not None)
            if blend and texture is not None and not texture_alpha \
                    and not (texture[..., 3] == 255).all():
                texture = texture.copy()  # alpha is d alone: the image's alpha is unused
                texture[..., 3] = 255
            return Material(name, color, texture, alpha_mode="BLEND" if blend else "OPAQUE")
        return Material(name, DEFAULT_COLOR)

    def _mtl_alpha(self, material, name: str, image) -> tuple[float, bool]:
        """MTL ``d`` (else 1 - ``Tr``) in [0, 1], and whether ``map_d`` uses the texture alpha."""
        kwargs = material.kwargs
        dissolve = _mtl_number(kwargs.get("d"))
        if dissolve is None:
            transparency = _mtl_number(kwargs.get("tr"))
            dissolve = 1.0 if transparency is None else 1.0 - transparency
            if transparency is not None and transparency >= 1.0:
                dissolve = 1.0  # MeshLab and others write Tr as the opacity: Tr 1 is opaque
                self.warnings.append(f"material '{name}': 'Tr {transparency:g}' would make it "
                                     "invisible; read as opaque (some exporters write Tr as "
                                     "the opacity; 'd 0' makes a material transparent)")
        map_d = kwargs.get("map_d")
        texture_alpha = False
        if map_d:
            file_name = " ".join(str(x) for x in map_d) if isinstance(map_d, list) else str(map_d)
            own = None if image is None else image.info.get("file_path")
            texture_alpha = own is not None and _same_file_name(file_name, own)
            if not texture_alpha:
                self.warnings.append(f"material '{name}': its map_d image '{file_name}' is not "
                                     "read (only a map_d naming the map_Kd image is); its "
                                     "alpha comes from d")
        return float(np.clip(dissolve, 0.0, 1.0)), texture_alpha

    def _texture(self, image, name: str) -> np.ndarray | None:
        """The image as an RGBA array, or None (and one warning) when it cannot be decoded."""
        if image is None:
            return None
        kept = self._images.get(id(image))
        if kept is None:
            array, problem = _texture_array(image)
            if problem:
                file_name = image.info.get("file_path") if hasattr(image, "info") else None
                what = f"'{file_name}'" if file_name else "image"
                self.warnings.append(f"material '{name}': its texture {what} {problem}; "
                                     "drawn with the material colour instead")
            kept = self._images[id(image)] = (image, array)
        return kept[1]


def max_texture_pixels() -> int | None:
    """Most pixels a texture may have: PIL's decompression-bomb limit, read at each use (so a
    caller that changes `PIL.Image.MAX_IMAGE_PIXELS` is honoured; None: no limit)."""
    return Image.MAX_IMAGE_PIXELS


# The warnings of the load in progress, in the list of its `SurfaceReader` (`merge.render_mesh`
# takes them), and the notes made while parsing, before that reader exists.
_WARNINGS: contextvars.ContextVar[list[str] | None] = contextvars.ContextVar(
    "reliefkit_loader_warnings", default=None)
_PENDING: contextvars.ContextVar[list[str] | None] = contextvars.ContextVar(
    "reliefkit_loader_pending_warnings", default=None)


def begin_warnings() -> None:
    """Start a new load: forget the warnings a load that failed may have left."""
    _WARNINGS.set(None)
    _PENDING.set(None)


def note_texture_problem(name: str, problem: str) -> None:
    """Record that texture `name` could not be used (`problem`, e.g. "could not be opened").

    For the parsing step, which sees images that trimesh drops without a trace; the next
    `SurfaceReader` (the same load's, when `begin_warnings` started it) takes the note.
    """
    pending = _PENDING.get()
    if pending is None:
        pending = []
        _PENDING.set(pending)
    pending.append(f"texture '{name}' {problem}; drawn with the material colour instead")


def take_warnings() -> list[str]:
    """The current load's warnings (each once), and forget them."""
    collected = _WARNINGS.get() or []
    _WARNINGS.set(None)
    return list(dict.fromkeys(collected))


def _start_reader_warnings() -> list[str]:
    """The list of a new reader: the notes made while parsing, then its own."""
    fresh = list(_PENDING.get() or [])
    _PENDING.set(None)
    _WARNINGS.set(fresh)
    return fresh


def _gltf_alpha(material) -> tuple[str, float]:
    """glTF's alphaMode (OPAQUE when absent or unknown) and alphaCutoff (0.5 when absent)."""
    mode = getattr(material, "alphaMode", None)
    mode = mode.upper() if isinstance(mode, str) else "OPAQUE"
    cutoff = getattr(material, "alphaCutoff", None)
    try:
        cutoff = float(cutoff)
    except (TypeError, ValueError):
        cutoff = 0.5
    if not 0.0 <= cutoff <= 1.0:  # also NaN
        cutoff = 0.5
    return (mode if mode in ALPHA_MODES else "OPAQUE"), cutoff


def _mtl_number(value) -> float | None:
    """The first number of an MTL statement's values (trimesh keeps them as strings)."""
    if isinstance(value, (list, tuple)):
        value = value[0] if value else None
    try:
        number = float(value)
    except (TypeError, ValueError):
        return None
    return number if np.isfinite(number) else None


def _same_file_name(a: str, b: str) -> bool:
    a, b = (str(x).replace("\\", "/").strip().lower() for x in (a, b))
    return a == b or a.rsplit("/", 1)[-1] == b.rsplit("/", 1)[-1]


def _is_placeholder(image) -> bool:
    """Whether `image` is the grey 2x2 trimesh invents for UVs without a material."""
    if image is None or getattr(image, "format", None) is not None:  # read from a file
        return False
    placeholder = trimesh.visual.material.color_image()
    return image.size == placeholder.size and np.array_equal(np.asarray(image),
                                                             np.asarray(placeholder))


def _texture_array(image) -> tuple[np.ndarray | None, str | None]:
    """A PIL image as (h, w, 4) uint8 RGBA with row 0 at v = 0 (PIL's row 0 is the top), or
    None and why not."""
    limit = max_texture_pixels()
    try:
        width, height = image.size
    except Exception:  # noqa: BLE001 - not an image at all
        return None, "is not an image"
    if limit is not None and width * height > limit:
        return None, (f"is {width}x{height}, more than {limit} pixels; scale it down to "
                      "use it")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # PIL warns as well as failing; say it once
            rgba = np.asarray(image.convert("RGBA"), dtype=np.uint8)
    except Exception as exc:  # noqa: BLE001 - PIL decodes lazily, so errors surface here
        detail = " ".join(str(exc).split())[:120] or type(exc).__name__
        return None, f"could not be decoded ({detail}); is it corrupt or truncated?"
    if rgba.ndim != 3 or rgba.shape[2] != 4 or rgba.size == 0:
        return None, "is empty"
    return np.ascontiguousarray(rgba[::-1]), None
