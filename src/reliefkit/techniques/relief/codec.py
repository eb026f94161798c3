"""The .rk kinds of relief textures (registered through the technique record).

``relief``: one ReliefTexture, arrays named as its fields (docs/format.md). ``relief-object``:
several parts (the six frusta of a cube), each part's arrays prefixed ``pK_``.
"""

from __future__ import annotations

import numpy as np

from ...errors import FormatError, UsageError
from ...io.rk import ArraySpec, Codec
from .representation import ReliefObject, ReliefTexture

MAX_PARTS = 6

RELIEF_ARRAYS = {
    "height": ArraySpec(("float32",), ndim=2, finite=True, role="height"),
    "color": ArraySpec(("uint8",), ndim=3, trailing=(None, 4), role="color"),
    "normal": ArraySpec(("float32",), ndim=3, trailing=(None, 3), finite=True, role="normal"),
    "safety": ArraySpec(("uint8", "uint16"), ndim=(2, 3), required=False),
    "box_to_world": ArraySpec(("float64",), ndim=2, trailing=(4, 4), finite=True),
    "clip_bounds": ArraySpec(("float64",), ndim=2, trailing=(2, 3), required=False, finite=True),
    "source_bounds": ArraySpec(("float64",), ndim=2, trailing=(2, 3), required=False,
                               finite=True),
}
PART_ARRAYS = {name: spec for name, spec in RELIEF_ARRAYS.items() if name != "source_bounds"}


def _relief_arrays(relief: ReliefTexture, prefix: str = "") -> dict[str, np.ndarray]:
    arrays = {"height": relief.height, "color": relief.color, "normal": relief.normal,
              "box_to_world": relief.box_to_world}
    if relief.safety is not None:
        arrays["safety"] = relief.safety
    for name in ("clip_bounds", "source_bounds"):
        if getattr(relief, name) is not None:
            arrays[name] = getattr(relief, name)
    return {prefix + name: a for name, a in arrays.items()}


def _relief_from(arrays: dict, params: dict, prefix: str = "") -> ReliefTexture:
    get = {name: arrays.get(prefix + name) for name in (PART_ARRAYS if prefix else RELIEF_ARRAYS)}
    params = dict(params)
    if get["clip_bounds"] is None and "clip_bounds" in params:  # files before it was an array
        get["clip_bounds"] = _old_clip_bounds(params.pop("clip_bounds"))
    try:
        return ReliefTexture(params=params, **get)
    except (UsageError, TypeError, ValueError) as exc:  # the representation refuses it
        raise FormatError(f"invalid relief texture: {exc}") from None


def _old_clip_bounds(value) -> np.ndarray:
    """``clip_bounds`` of an older file's params: two lists of three numbers."""
    try:
        box = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        box = None
    if box is None or box.shape != (2, 3):
        raise FormatError(f"params clip_bounds must be [[x, y, z], [x, y, z]], got {value!r}")
    return box


def _object_arrays(obj: ReliefObject):
    arrays = {"source_bounds": obj.source_bounds}
    for k, part in enumerate(obj.parts):
        part_arrays = _relief_arrays(part, f"p{k}_")
        part_arrays.pop(f"p{k}_source_bounds", None)  # the object's, stored once
        arrays |= part_arrays
    params = dict(obj.params) | {"parts": len(obj.parts),
                                 "part_params": [p.params for p in obj.parts]}
    return arrays, params


def _object_from(arrays: dict, params: dict) -> ReliefObject:
    count = params.get("parts")
    if not isinstance(count, int) or not 1 <= count <= MAX_PARTS:
        raise FormatError(f"relief-object needs 1..{MAX_PARTS} parts, manifest says {count!r}")
    part_params = params.get("part_params", [{}] * count)
    if not (isinstance(part_params, list) and len(part_params) == count
            and all(isinstance(p, dict) for p in part_params)):
        raise FormatError(f"relief-object part_params must be a list of {count} JSON objects "
                          "(one per part)")
    parts = []
    for k in range(count):
        if f"p{k}_height" not in arrays:
            raise FormatError(f"relief-object part {k} is missing its arrays")
        parts.append(_relief_from(arrays, part_params[k], f"p{k}_"))
    rest = {key: v for key, v in params.items() if key not in ("parts", "part_params")}
    try:
        return ReliefObject(parts=parts, params=rest, source_bounds=arrays.get("source_bounds"))
    except UsageError as exc:
        raise FormatError(f"invalid relief object: {exc}") from None


def _rederive_safety(arrays: dict, params: dict, prefix: str = "") -> dict:
    """Safety radii computed again from (quantized) heights, with the bake's tolerance: a
    radius of the exact heights may skip a crossing of the quantized ones."""
    safety = arrays.get(prefix + "safety")
    if safety is None:
        return arrays
    from .safety import safety_radii  # numba: slow to import

    radii = safety_radii(arrays[prefix + "height"],
                         tolerance=float(params.get("safety_tolerance", 0.0)),
                         octants=safety.ndim == 3)
    return arrays | {prefix + "safety": radii}


def _rederive_parts(arrays: dict, params: dict) -> dict:
    for k, part_params in enumerate(params.get("part_params", [])):
        arrays = _rederive_safety(arrays, part_params, f"p{k}_")
    return arrays


RELIEF = Codec(kind="relief", cls=ReliefTexture, arrays=RELIEF_ARRAYS,
               to_arrays=lambda r: (_relief_arrays(r), dict(r.params)),
               from_arrays=_relief_from, rederive=_rederive_safety)
RELIEF_OBJECT = Codec(
    kind="relief-object", cls=ReliefObject,
    arrays={"source_bounds": RELIEF_ARRAYS["source_bounds"]} | {
        f"p{k}_{name}": ArraySpec(spec.dtypes, spec.ndim, required=False, finite=spec.finite,
                                  trailing=spec.trailing, role=spec.role)
        for k in range(MAX_PARTS) for name, spec in PART_ARRAYS.items()},
    to_arrays=_object_arrays, from_arrays=_object_from, rederive=_rederive_parts)
CODECS = (RELIEF, RELIEF_OBJECT)
