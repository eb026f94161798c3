"""The .rk kind ``displacement``: a base mesh and its displacement texture.

Arrays: ``positions`` float64 (V, 3) world, ``indices`` int32 (F, 3), ``normals`` float32
(V, 3), ``uvs`` float32 (V, 2), ``color`` float32 (H, W, 4) linear straight alpha, ``height``
float32 (H, W) in [0, 1]. Typed params (they change rendering, so they are checked here):
``scale`` (a positive number), ``tile`` [U, V] (positive numbers), ``wrap`` (a bool); the
rest (``source``, ``texture``) is provenance. Optional ``source_bounds`` float64 (2, 3): the baked
mesh's box, which views frame the map by; the optional surface arrays
(`reliefkit.io.mesh_codec.SURFACE_ARRAYS`: the base's materials in uv space, which tint the
texture's colours). The volume's tetrahedra are rebuilt when drawn.
"""

from __future__ import annotations

import numpy as np

from ...errors import FormatError, MeshError, UsageError
from ...io.mesh_codec import (
    BASE_MESH_ARRAYS,
    SURFACE_ARRAYS,
    check_base_arrays,
    surface_from_arrays,
    surface_to_arrays,
)
from ...io.rk import SOURCE_BOUNDS, ArraySpec, Codec
from ...scene.mesh import Material, RenderMesh
from .displacement import MAX_TEXELS, MAX_TILE, DisplacementMap

ARRAYS = BASE_MESH_ARRAYS | {
    "color": ArraySpec(("float32",), ndim=3, trailing=(4,), finite=True,
                       max_size=4 * MAX_TEXELS, role="color"),
    "height": ArraySpec(("float32",), ndim=2, finite=True, max_size=MAX_TEXELS, role="height"),
    "source_bounds": SOURCE_BOUNDS,
} | SURFACE_ARRAYS
OWN = ("scale", "tile", "wrap")


def _to_arrays(rep: DisplacementMap) -> tuple[dict, dict]:
    base = rep.base
    arrays = {"positions": base.world_positions, "indices": base.indices.astype(np.int32),
              "normals": base.normals, "uvs": base.uvs, "color": rep.color,
              "height": rep.height, "source_bounds": rep.source_bounds}
    params = {k: v for k, v in rep.params.items() if k not in (*OWN, "surface_box")}
    surface_arrays, surface_params = surface_to_arrays(rep.surface, base)
    return arrays | surface_arrays, params | surface_params | {
        "scale": rep.scale, "tile": list(rep.tile), "wrap": rep.wrap}


def _number(value) -> bool:
    return not isinstance(value, bool) and isinstance(value, int | float) and bool(
        np.isfinite(value))


def _check_shapes(shapes: dict) -> None:
    """The colour image is the height field's size (on the declared shapes: before reading)."""
    if shapes["color"] != (*shapes["height"], 4):
        raise FormatError(f"displacement arrays 'color' {shapes['color']} and 'height' "
                          f"{shapes['height']} must be (H, W, 4) and (H, W)")


def _from_arrays(arrays: dict, params: dict) -> DisplacementMap:
    params = dict(params)
    scale, tile, wrap = (params.pop(k, None) for k in OWN)
    if not (_number(scale) and scale > 0):
        raise FormatError(f"displacement param 'scale' must be a positive number, got "
                          f"{scale!r}")
    if not (isinstance(tile, list) and len(tile) == 2
            and all(_number(t) and 0 < t <= MAX_TILE for t in tile)):
        raise FormatError(f"displacement param 'tile' must be two numbers in (0, "
                          f"{MAX_TILE:g}], got {tile!r}")
    if not isinstance(wrap, bool):
        raise FormatError(f"displacement param 'wrap' must be true or false, got {wrap!r}")
    positions = arrays["positions"]
    count = check_base_arrays(arrays, "displacement map")
    height, color = arrays["height"], arrays["color"]
    if height.size and (height.min() < 0 or height.max() > 1):
        raise FormatError("displacement array 'height' must lie in [0, 1]")
    if color.size and (color.min() < 0 or color.max() > 1):
        raise FormatError("displacement array 'color' must lie in [0, 1]")
    surface, material = surface_from_arrays(arrays, params, "displacement")
    try:
        colors = np.broadcast_to(np.float32(1.0), (count, 4))
        base = RenderMesh(positions, arrays["indices"], arrays["normals"], colors,
                          arrays["uvs"], name=str(params.get("source", "displacement base")),
                          materials=[Material()] * (1 if surface is None
                                                    else len(surface.rgba8)),
                          material=material)
        return DisplacementMap(base, color, height, float(scale),
                               (float(tile[0]), float(tile[1])), wrap, params,
                               arrays.get("source_bounds"), surface)
    except (UsageError, MeshError, ValueError) as exc:
        raise FormatError(f"invalid displacement map: {exc}") from None


CODECS = (Codec(kind="displacement", cls=DisplacementMap, arrays=ARRAYS, to_arrays=_to_arrays,
                from_arrays=_from_arrays, version=1, check_shapes=_check_shapes),)
