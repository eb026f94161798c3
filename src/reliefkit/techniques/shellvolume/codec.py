"""The .rk kind ``shell-volume``: the base mesh, its per-vertex thickness and the 3D texture.

Arrays: ``positions`` float64 (V, 3) world, ``indices`` int32 (F, 3), ``normals`` float32
(V, 3), ``uvs`` float32 (V, 2), ``thickness`` float64 (V,), ``texture_rgba`` float32
(D, H, W, 4), ``texture_normal`` float32 (D, H, W, 3), optional ``texture_glow`` float32
(D, H, W); the optional surface arrays (`reliefkit.io.mesh_codec.SURFACE_ARRAYS`: the base's
materials in uv space, which tint the volume); params ``texture`` (its name), ``tile`` [U, V]
and ``alpha_length`` (the object-space length the alphas are the opacity of: 1, or the shell
thickness the generated textures are authored over); optional ``source_bounds`` float64
(2, 3), the baked mesh's box that views frame the shell by. The shell's tetrahedra are
rebuilt from these when the file is read (nothing else is precomputed).
"""

from __future__ import annotations

import numpy as np

from ...errors import FormatError, MeshError, UsageError
from ...io.mesh_codec import (
    BASE_MESH_ARRAYS,
    MAX_BASE_VERTICES,
    SURFACE_ARRAYS,
    check_base_arrays,
    surface_from_arrays,
    surface_to_arrays,
)
from ...io.rk import SOURCE_BOUNDS, ArraySpec, Codec
from ...scene.mesh import Material, RenderMesh
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
} | SURFACE_ARRAYS


def _to_arrays(rep: TexturedShell) -> tuple[dict, dict]:
    base, tex = rep.base, rep.texture
    arrays = {"positions": base.world_positions, "indices": base.indices.astype(np.int32),
              "normals": base.normals, "uvs": base.uvs, "thickness": rep.thickness,
              "texture_rgba": tex.rgba, "texture_normal": tex.normal,
              "texture_glow": tex.glow, "source_bounds": rep.source_bounds}
    own = ("texture", "tile", "alpha_length", "surface_box")
    params = {k: v for k, v in rep.params.items() if k not in own}
    params |= {"texture": tex.name, "tile": list(tex.tile), "alpha_length": tex.length}
    surface_arrays, surface_params = surface_to_arrays(rep.surface, base)
    return arrays | surface_arrays, params | surface_params


def _from_arrays(arrays: dict, params: dict) -> TexturedShell:
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
    surface, material = surface_from_arrays(arrays, params, "shell-volume")
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


CODECS = (Codec(kind="shell-volume", cls=TexturedShell, arrays=ARRAYS, to_arrays=_to_arrays,
                from_arrays=_from_arrays, version=1),)
