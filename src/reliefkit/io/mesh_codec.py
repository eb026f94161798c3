"""The core's own .rk kind, ``mesh``: a RenderMesh stored as plain arrays, every material kept.

Version 2 added materials to the arrays of version 1, which describe a one-material mesh
with at most one texture (``texture``); version 3 the origin. Arrays that would only repeat
the defaults are left out, so older files are valid newer ones and one reader reads all:

- ``material`` (F,) uint16 per-triangle material index (absent: every triangle uses 0);
- ``material_colors`` (M, 4) float32 linear colour factors (absent: one white material);
- ``texture`` material 0's texture, ``texture_K`` material K's (K < `MAX_TEXTURED`);
- ``uv_transforms`` (M, 3, 3) float32 (absent: none); param ``materials``: their names;
- param ``alpha_modes``: M of "OPAQUE", "MASK", "BLEND" (absent: every material OPAQUE, the
  `Material` default, also for files written before alpha modes existed: their texture and
  factor alpha is then ignored, as glTF's default alphaMode says);
- ``alpha_cutoffs`` (M,) float32 MASK thresholds in [0, 1] (absent: 0.5 each);
- param ``double_sided``: M booleans (absent: every material single-sided, the default);
- ``origin`` (3,) float64 world point ``positions`` are relative to (absent: the zero
  vector; `RenderMesh.origin`, set for meshes far from the world origin).
"""

from __future__ import annotations

import numpy as np

from ..bake.uv_atlas import ATLAS_SIZE, MAX_MATERIALS, MaterialAtlas
from ..errors import FormatError
from ..scene.mesh import ALPHA_MODES, Material, RenderMesh
from .rk import ArraySpec, Codec

#: Materials 0 .. MAX_TEXTURED - 1 can keep a texture in a .rk file.
MAX_TEXTURED = 64

_WHITE = np.ones(4, np.float32)
_CUTOFF = 0.5  # `Material.alpha_cutoff`'s default


def texture_array_name(k: int) -> str:
    """The array holding material k's texture (``texture`` for material 0, as in version 1)."""
    return "texture" if k == 0 else f"texture_{k}"


def _mesh_to_arrays(mesh: RenderMesh) -> tuple[dict[str, np.ndarray], dict]:
    materials = mesh.materials
    arrays = {"positions": mesh.positions, "indices": mesh.indices, "normals": mesh.normals,
              "colors": mesh.colors, "uvs": mesh.uvs}
    params = {"name": mesh.name}
    if mesh.origin.any():
        arrays["origin"] = mesh.origin
    if len(materials) > 1:
        arrays["material"] = mesh.material
    if len(materials) > 1 or not np.array_equal(materials[0].color, _WHITE):
        arrays["material_colors"] = np.stack([m.color for m in materials])
    if any(m.uv_transform is not None for m in materials):
        arrays["uv_transforms"] = np.stack(
            [np.eye(3, dtype=np.float32) if m.uv_transform is None else m.uv_transform
             for m in materials])
    if any(m.name for m in materials):
        params["materials"] = [m.name for m in materials]
    if any(m.alpha_mode != "OPAQUE" for m in materials):
        params["alpha_modes"] = [m.alpha_mode for m in materials]
    if any(m.alpha_cutoff != _CUTOFF for m in materials):
        arrays["alpha_cutoffs"] = np.array([m.alpha_cutoff for m in materials], np.float32)
    if any(m.double_sided for m in materials):
        params["double_sided"] = [m.double_sided for m in materials]
    for k, m in enumerate(materials):
        if m.texture is None:
            continue
        if k >= MAX_TEXTURED:
            raise FormatError(f"{mesh.name}: material {k} has a texture; a mesh .rk keeps the "
                              f"textures of its first {MAX_TEXTURED} materials only")
        arrays[texture_array_name(k)] = m.texture
    return arrays, params


def _mesh_from_arrays(arrays: dict[str, np.ndarray], params: dict) -> RenderMesh:
    name = params.get("name", "mesh")
    if not isinstance(name, str):
        raise FormatError(f"mesh param 'name' must be a string, got {type(name).__name__}")
    colors = arrays.get("material_colors", _WHITE[None])
    count = len(colors)
    names = params.get("materials", [""] * count)
    if not isinstance(names, list) or not all(isinstance(n, str) for n in names):
        raise FormatError("mesh param 'materials' must be a list of material names")
    transforms = arrays.get("uv_transforms")
    modes = params.get("alpha_modes", ["OPAQUE"] * count)
    if not isinstance(modes, list) or not all(isinstance(m, str) and m in ALPHA_MODES
                                              for m in modes):
        raise FormatError(f"mesh param 'alpha_modes' must be a list of {', '.join(ALPHA_MODES)}")
    sides = params.get("double_sided", [False] * count)
    if not isinstance(sides, list) or not all(isinstance(b, bool) for b in sides):
        raise FormatError("mesh param 'double_sided' must be a list of booleans")
    cutoffs = arrays.get("alpha_cutoffs")
    if cutoffs is None:
        cutoffs = np.full(count, _CUTOFF, np.float32)
    elif cutoffs.size and (cutoffs.min() < 0 or cutoffs.max() > 1):
        raise FormatError("mesh array 'alpha_cutoffs' must hold values in [0, 1]")
    for what, n in (("names in param 'materials'", len(names)),
                    ("modes in param 'alpha_modes'", len(modes)),
                    ("alpha_cutoffs", len(cutoffs)),
                    ("flags in param 'double_sided'", len(sides)),
                    ("uv_transforms", count if transforms is None else len(transforms))):
        if n != count:
            raise FormatError(f"mesh has {count} material colours but {n} {what}")
    textured = [k for k in range(MAX_TEXTURED) if texture_array_name(k) in arrays]
    if textured and textured[-1] >= count:
        raise FormatError(f"array '{texture_array_name(textured[-1])}' belongs to material "
                          f"{textured[-1]}, but the mesh has {count} materials")
    materials = [Material(names[k], colors[k], arrays.get(texture_array_name(k)),
                          None if transforms is None else transforms[k], modes[k],
                          float(cutoffs[k]), sides[k]) for k in range(count)]
    return RenderMesh(arrays["positions"], arrays["indices"], arrays["normals"],
                      arrays["colors"], arrays.get("uvs"), name=name, materials=materials,
                      material=arrays.get("material"), origin=arrays.get("origin", np.zeros(3)))


def _rows(dtype: str, cols: int, **options) -> ArraySpec:
    """Spec of an (N, cols) per-vertex or per-triangle table."""
    return ArraySpec((dtype,), ndim=2, trailing=(cols,), **options)


_TEXTURE = ArraySpec(("uint8",), ndim=3, trailing=(4,), required=False, role="color")

#: The core's ``mesh`` kind; the composition root (`reliefkit.builtins`) registers it.
MESH_CODEC = Codec(
    kind="mesh",
    cls=RenderMesh,
    arrays={
        "positions": _rows("float32", 3, finite=True),
        "indices": _rows("uint32", 3),
        "normals": _rows("float32", 3, finite=True),
        "colors": _rows("float32", 4, finite=True),
        "uvs": _rows("float32", 2, finite=True, required=False),
        "material": ArraySpec(("uint16",), ndim=1, required=False),
        "material_colors": _rows("float32", 4, finite=True, required=False),
        "uv_transforms": ArraySpec(("float32",), ndim=3, trailing=(3, 3), finite=True,
                                   required=False),
        "alpha_cutoffs": ArraySpec(("float32",), ndim=1, finite=True, required=False),
        "origin": ArraySpec(("float64",), ndim=1, finite=True, required=False),
        **{texture_array_name(k): _TEXTURE for k in range(MAX_TEXTURED)},
    },
    to_arrays=_mesh_to_arrays,
    from_arrays=_mesh_from_arrays,
    version=3,
)


#: The arrays of a base mesh that a representation builds its volume on (a shell, a
#: displacement volume): world positions, triangles, the normals it extrudes along, uvs.
MAX_BASE_VERTICES = 1 << 22
MAX_BASE_TRIANGLES = 1 << 22
BASE_MESH_ARRAYS = {
    "positions": ArraySpec(("float64",), ndim=2, trailing=(3,), finite=True,
                           max_size=3 * MAX_BASE_VERTICES),
    "indices": ArraySpec(("int32",), ndim=2, trailing=(3,), max_size=3 * MAX_BASE_TRIANGLES),
    "normals": ArraySpec(("float32",), ndim=2, trailing=(3,), finite=True,
                         max_size=3 * MAX_BASE_VERTICES),
    "uvs": ArraySpec(("float32",), ndim=2, trailing=(2,), finite=True,
                     max_size=2 * MAX_BASE_VERTICES),
}


def check_base_arrays(arrays: dict, kind: str, per_vertex=("normals", "uvs")) -> int:
    """Refuse a base whose per-vertex arrays (``per_vertex``) have another length than
    ``positions`` (the size caps are `BASE_MESH_ARRAYS`' own); returns the vertex count."""
    count = len(arrays["positions"])
    for key in per_vertex:
        if len(arrays[key]) != count:
            raise FormatError(f"{kind} array '{key}' has {len(arrays[key])} rows, the base "
                              f"has {count} vertices")
    return count


#: A base's own materials in its uv space (`reliefkit.bake.uv_atlas`), optional arrays of
#: the kinds built on a base: ``surface`` uint8 (M, H, W, 4) sRGB, one layer per material,
#: with ``material`` uint16 (F,) per triangle (absent: 0) and the param ``surface_box``
#: [u0, v0, u1, v1]. Files without them load as before (no tint).
SURFACE_ARRAYS = {
    "surface": ArraySpec(("uint8",), ndim=4, trailing=(4,), required=False,
                         max_size=4 * MAX_MATERIALS * ATLAS_SIZE ** 2, role="color"),
    "material": ArraySpec(("uint16",), ndim=1, required=False, max_size=MAX_BASE_TRIANGLES),
}


def surface_to_arrays(atlas: MaterialAtlas | None, base) -> tuple[dict, dict]:
    """(arrays, params) storing ``atlas`` and ``base``'s per-triangle material (none: empty)."""
    if atlas is None:
        return {}, {}
    return ({"surface": atlas.rgba8, "material": np.asarray(base.material, np.uint16)},
            {"surface_box": list(atlas.box)})


def surface_from_arrays(arrays: dict, params: dict, kind: str):
    """The stored material atlas and the base's per-triangle material (None, None without
    one); pops ``surface_box`` from ``params``."""
    layers, material = arrays.get("surface"), arrays.get("material")
    box = params.pop("surface_box", None)
    if layers is None:
        if material is not None or box is not None:
            raise FormatError(f"a {kind}'s 'material' and 'surface_box' come with 'surface'")
        return None, None
    if not (isinstance(box, list) and len(box) == 4 and all(
            isinstance(b, int | float) and not isinstance(b, bool) and np.isfinite(b)
            for b in box) and box[2] > box[0] and box[3] > box[1]):
        raise FormatError(f"{kind} param 'surface_box' must be [u0, v0, u1, v1] with "
                          f"u1 > u0 and v1 > v0, got {box!r}")
    triangles = len(arrays["indices"])
    if material is None:
        material = np.zeros(triangles, np.uint16)
    if len(material) != triangles:
        raise FormatError(f"{kind} array 'material' has {len(material)} entries, the "
                          f"base has {triangles} triangles")
    if min(layers.shape[:3]) < 1 or len(layers) > MAX_MATERIALS:
        raise FormatError(f"{kind} array 'surface' has shape {layers.shape}; expected "
                          f"1..{MAX_MATERIALS} layers of at least 1x1")
    return MaterialAtlas(layers, tuple(float(b) for b in box)), material
