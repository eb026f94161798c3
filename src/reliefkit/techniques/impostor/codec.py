"""The .rk kind of the impostor technique: ``octahedral-impostor``.

Arrays: ``color`` uint8 (S, S, 4) sRGB with coverage alpha, ``normal`` uint8 (S, S, 3)
object-space normals, ``depth`` uint8 (S, S) heights along each frame's direction, ``center``
float64 (3,), ``source_bounds``; params ``grid``, ``hemi``, ``radius``, ``padding`` (the
typed fields that change rendering) and the bake's parameters. ``bake --compress bc``
stores colour and normals as BC7 (or BC1) (`reliefkit.compact`). Depths stay R8: BC4's
interpolated levels decode differently per GL (the format allows it), and the parallax
search turns that 1/255 into another texel at outlines (1.7% of a sphere's pixels moved).
"""

from __future__ import annotations

from ...errors import FormatError, UsageError
from ...io.rk import SOURCE_BOUNDS, ArraySpec, Codec
from .representation import MAX_ATLAS, OctahedralImpostor


def _atlas(channels: int | None, role: str | None) -> ArraySpec:
    ndim, trailing = (2, None) if channels is None else (3, (None, None, channels))
    return ArraySpec(("uint8",), ndim=ndim, trailing=trailing,
                     max_size=MAX_ATLAS * MAX_ATLAS * (channels or 1), role=role)


ARRAYS = {"color": _atlas(4, "color"), "normal": _atlas(3, "normal"),
          "depth": _atlas(None, None),
          "center": ArraySpec(("float64",), ndim=1, trailing=(3,), finite=True),
          "source_bounds": SOURCE_BOUNDS}
OWN = ("grid", "hemi", "radius", "padding")  # the codec's params, written last


def _check_shapes(shapes: dict) -> None:
    """The three atlases are squares of one side (checked before anything is inflated)."""
    sides = {name: shapes[name][:2] for name in ("color", "normal", "depth") if name in shapes}
    if len({*sides.values()}) > 1 or any(s[0] != s[1] for s in sides.values()):
        raise FormatError(f"octahedral-impostor atlases must be squares of one side, got "
                          f"{', '.join(f'{n} {s}' for n, s in sides.items())}")


def _to_arrays(rep: OctahedralImpostor) -> tuple[dict, dict]:
    arrays = {"color": rep.color, "normal": rep.normal, "depth": rep.depth,
              "center": rep.center, "source_bounds": rep.source_bounds}
    params = {k: v for k, v in rep.params.items() if k not in OWN}
    return arrays, params | {"grid": rep.grid, "hemi": rep.hemi, "radius": rep.radius,
                             "padding": rep.padding}


def _from_arrays(arrays: dict, params: dict) -> OctahedralImpostor:
    params = dict(params)
    grid, hemi, radius, padding = (params.pop(k, None) for k in OWN)
    for name, value, ok in (("grid", grid, isinstance(grid, int)),
                            ("hemi", hemi, isinstance(hemi, bool)),
                            ("radius", radius, isinstance(radius, int | float)),
                            ("padding", padding, isinstance(padding, int))):
        if not ok or (name != "hemi" and isinstance(value, bool)):
            raise FormatError(f"octahedral-impostor param {name!r} is missing or of the "
                              f"wrong type ({value!r})")
    try:
        return OctahedralImpostor(grid, hemi, arrays["center"], radius, padding,
                                  arrays["color"], arrays["normal"], arrays["depth"],
                                  source_bounds=arrays.get("source_bounds"), params=params)
    except UsageError as exc:
        raise FormatError(f"invalid octahedral impostor: {exc}") from None


CODECS = (Codec(kind="octahedral-impostor", cls=OctahedralImpostor, arrays=ARRAYS,
                to_arrays=_to_arrays, from_arrays=_from_arrays, version=1,
                check_shapes=_check_shapes),)
