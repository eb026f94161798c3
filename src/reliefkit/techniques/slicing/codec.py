"""The .rk kinds ``depth-object`` and ``visual-hull``: six depth images on a cube.

Arrays: ``depth`` float32 (6, N, N) in [0, 1], ``mask`` uint8 (6, N, N) 0 or 1, ``color``
float32 (6, N, N, 4) linear straight alpha, ``normal`` float32 (6, N, N, 3), and
``cube_to_world`` float64 (4, 4) (a uniform scale and a translation: the faces' boxes are
derived from it), and optionally ``source_bounds`` float64 (2, 3), the baked mesh's box that
views frame the object by. See `depth_images` for the conventions.
"""

from __future__ import annotations

import numpy as np

from ...errors import FormatError, UsageError
from ...io.rk import SOURCE_BOUNDS, ArraySpec, Codec
from .depth_images import MAX_RESOLUTION, DepthImages, check_side, face_boxes
from .representation import DepthObject, VisualHull

_TEXELS = 6 * MAX_RESOLUTION**2  # six faces of N x N
ARRAYS = {
    "depth": ArraySpec(("float32",), ndim=3, trailing=(None, None), finite=True,
                       max_size=_TEXELS),
    "mask": ArraySpec(("uint8",), ndim=3, trailing=(None, None), max_size=_TEXELS),
    "color": ArraySpec(("float32",), ndim=4, trailing=(None, None, 4), finite=True,
                       max_size=4 * _TEXELS, role="color"),
    "normal": ArraySpec(("float32",), ndim=4, trailing=(None, None, 3), finite=True,
                        max_size=3 * _TEXELS, role="normal"),
    "cube_to_world": ArraySpec(("float64",), ndim=2, trailing=(4, 4), finite=True),
    "source_bounds": SOURCE_BOUNDS,
}


def _to_arrays(rep: DepthObject) -> tuple[dict, dict]:
    im = rep.images
    return ({"depth": im.depth, "mask": im.mask.astype(np.uint8), "color": im.color,
             "normal": im.normal, "cube_to_world": im.cube_to_world,
             "source_bounds": rep.source_bounds}, dict(rep.params))


def _check_cube(cube: np.ndarray) -> None:
    side = cube[0, 0]
    expected = np.eye(4) * side
    expected[3, 3] = 1.0
    expected[:3, 3] = cube[:3, 3]
    if not (side > 0 and np.array_equal(cube, expected)):
        raise FormatError("cube_to_world must be a positive uniform scale and a translation")
    try:
        check_side(float(side))
    except UsageError as exc:
        raise FormatError(str(exc)) from None


def _name(cls) -> str:
    return "visual hull" if cls.hull else "depth object"


def _shape_checker(cls):
    """Six N x N faces in every image (on the declared shapes: before reading)."""
    kind = _name(cls)

    def check_shapes(shapes: dict) -> None:
        n = shapes["depth"][-1]
        if shapes["depth"] != (6, n, n) or not 2 <= n <= MAX_RESOLUTION:
            raise FormatError(f"{kind}: depth must be (6, N, N) with N in [2, "
                              f"{MAX_RESOLUTION}], got {shapes['depth']}")
        for name, shape in (("mask", (6, n, n)), ("color", (6, n, n, 4)),
                            ("normal", (6, n, n, 3))):
            if shapes[name] != shape:
                raise FormatError(f"{kind}: {name} must have shape {shape}, got "
                                  f"{shapes[name]}")

    return check_shapes


def _decoder(cls):
    kind = _name(cls)

    def from_arrays(arrays: dict, params: dict) -> DepthObject:
        depth, mask = arrays["depth"], arrays["mask"]
        if mask.max(initial=0) > 1:
            raise FormatError(f"{kind}: mask values must be 0 or 1")
        cube = arrays["cube_to_world"]
        _check_cube(cube)
        try:
            images = DepthImages(depth, mask.astype(bool), arrays["color"], arrays["normal"],
                                 face_boxes(cube), cube)
            return cls(images, dict(params), arrays.get("source_bounds"))
        except UsageError as exc:
            raise FormatError(f"invalid {kind}: {exc}") from None

    return from_arrays


CODECS = tuple(Codec(kind=kind, cls=cls, arrays=ARRAYS, to_arrays=_to_arrays,
                     from_arrays=_decoder(cls), version=1, check_shapes=_shape_checker(cls))
               for kind, cls in (("depth-object", DepthObject), ("visual-hull", VisualHull)))
