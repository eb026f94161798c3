"""The .rk kind ``shell-volume``: the base mesh, its per-vertex thickness and the 3D texture.

Arrays: ``positions`` float64 (V, 3) world, ``indices`` int32 (F, 3), ``normals`` float32
(V, 3), ``uvs`` float32 (V, 2), ``thickness`` float64 (V,), ``texture_rgba`` float32
(D, H, W, 4), ``texture_normal`` float32 (D, H, W, 3), optional ``texture_glow`` float32
(D, H, W); optional ``surface`` uint8 (M, H, W, 4) sRGB, the base's materials in uv space
(`reliefkit.bake.uv_atlas`), with ``material`` uint16 (F,) per triangle (absent: 0) and the
param ``surface_box`` [u0, v0, u1, v1]; params ``texture`` (its name), ``tile`` [U, V]
and ``alpha_length`` (the object-space length the alphas are the opacity of: 1, or the shell
thickness the generated textures are authored over); optional ``source_bounds`` float64
(2, 3), the baked mesh's box that views frame the shell by. The shell's tetrahedra are
rebuilt from these when the file is read (nothing else is precomputed).
"""

from __future__ import annotations

import numpy as np

from ...bake.uv_atlas import ATLAS_SIZE, MAX_MATERIALS, MaterialAtlas
from ...errors import FormatError, MeshError, UsageError
from ...io.mesh_codec import (
    BASE_MESH_ARRAYS,
    MAX_BASE_TRIANGLES,
    MAX_BASE_VERTICES,
    check_base_arrays,
)
from ...io.rk import SOURCE_BOUNDS, ArraySpec, Codec
from .representation import TexturedShell
from .textures import MAX_VOXELS, VolumeTexture

ARRAYS = BASE_MESH_ARRAYS | {
    "thickness": ArraySpec(("float64",), ndim=1, finite=True, max_size=MAX_BASE_VERTICES),
    "texture_rgba": ArraySpec(("float32",), ndim=4, trailing=(4,), finite=True,
                              max_size=4 * MAX_VOXELS),
    "texture_normal": ArraySpec(("float32",), ndim=4, trailing=(3,), finite=True,
                                max_size=3 * MAX_VOXELS),
    "texture_glow": ArraySpec(("float32",), ndim=3, required=False, finite=True,
                              max_size=MAX_VOXELS),
    "source_bounds": SOURCE_BOUNDS,
    "surface": ArraySpec(("uint8",), ndim=4, trailing=(4,), required=False,
                         max_size=4 * MAX_MATERIALS * ATLAS_SIZE ** 2),
    "material": ArraySpec(("uint16",), ndim=1, required=False, max_size=MAX_BASE_TRIANGLES),
}


def _to_arrays(rep: TexturedShell) -> tuple[dict, dict]:
    base, tex = rep.base, rep.texture
    arrays = {"positions": base.world_positions, "indices": base.indices.astype(np.int32),
              "normals": base.normals, "uvs": base.uvs, "thickness": rep.thickness,
              "texture_rgba": tex.rgba, "texture_normal": tex.normal,
              "texture_glow": tex.glow, "source_bounds": rep.source_bounds}
    own = ("texture", "tile", "alpha_length", "surface_box")
    params = {k: v for k, v in rep.params.items() if k not in own}
    params |= {"texture": tex.name, "tile": list(tex.tile), "alpha_length": tex.length}
    if rep.surface is not None:
        arrays |= {"surface": rep.surface.rgba8,
                   "material": np.asarray(base.material, np.uint16)}
        params["surface_box"] = list(rep.surface.box)
    return arrays, params


def _from_arrays(arrays: dict, params: dict) -> TexturedShell:
    from ...scene.mesh import Material, RenderMesh

    params = dict(params)
    name, tile = params.pop("texture", None), params.pop("tile", None)
    length = params.pop("alpha_length", 1.0)
    if isinstance(length, bool) or not isinstance(length, int | float) or not (
            np.isfinite(length) and length > 0):
        raise FormatError(f"shell-volume param 'alpha_length' must be a positive number, got "
                          f"{length!r}")
    if not isinstance(name, str):
        raise FormatError(f"shell-volume param 'texture' must be a name, got {name!r}")
    if not (isinstance(tile, list) and len(tile) == 2
            and all(isinstance(t, int) and not isinstance(t, bool) for t in tile)):
        raise FormatError(f"shell-volume param 'tile' must be two whole numbers, got {tile!r}")
    positions = arrays["positions"]
    count = check_base_arrays(arrays, "shell-volume", ("normals", "uvs", "thickness"))
    rgba = arrays["texture_rgba"]  # at most MAX_VOXELS: ARRAYS' max_size
    surface, material = _surface(arrays, params.pop("surface_box", None),
                                 len(arrays["indices"]))
    try:
        texture = VolumeTexture(rgba, arrays["texture_normal"], name, tuple(tile),
                                arrays.get("texture_glow"), float(length))
        colors = np.broadcast_to(np.float32(0.8), (count, 4))
        base = RenderMesh(positions, arrays["indices"], arrays["normals"], colors,
                          arrays["uvs"], name=params.get("source", "shell base"),
                          materials=[Material()] * (1 if surface is None
                                                    else len(surface.rgba8)),
                          material=material)
        return TexturedShell(base, arrays["thickness"], texture, params,
                             source_bounds=arrays.get("source_bounds"), surface=surface)
    except (UsageError, MeshError, ValueError) as exc:
        raise FormatError(f"invalid shell volume: {exc}") from None


def _surface(arrays: dict, box, triangles: int):
    """The stored material atlas and the per-triangle material (None, None without one)."""
    layers, material = arrays.get("surface"), arrays.get("material")
    if layers is None:
        if material is not None or box is not None:
            raise FormatError("a shell's 'material' and 'surface_box' come with 'surface'")
        return None, None
    if not (isinstance(box, list) and len(box) == 4 and all(
            isinstance(b, int | float) and not isinstance(b, bool) and np.isfinite(b)
            for b in box) and box[2] > box[0] and box[3] > box[1]):
        raise FormatError(f"shell-volume param 'surface_box' must be [u0, v0, u1, v1] with "
                          f"u1 > u0 and v1 > v0, got {box!r}")
    if material is None:
        material = np.zeros(triangles, np.uint16)
    if len(material) != triangles:
        raise FormatError(f"shell-volume array 'material' has {len(material)} entries, the "
                          f"base has {triangles} triangles")
    if min(layers.shape[:3]) < 1 or len(layers) > MAX_MATERIALS:
        raise FormatError(f"shell-volume array 'surface' has shape {layers.shape}; expected "
                          f"1..{MAX_MATERIALS} layers of at least 1x1")
    return MaterialAtlas(layers, tuple(float(b) for b in box)), material


CODECS = (Codec(kind="shell-volume", cls=TexturedShell, arrays=ARRAYS, to_arrays=_to_arrays,
                from_arrays=_from_arrays, version=1),)
