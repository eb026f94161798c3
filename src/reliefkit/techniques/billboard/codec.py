"""The .rk kinds of the billboard technique (registered through its technique record).

``billboard-cloud``: the rectangles (``corners``, ``u_axes``, ``v_axes`` float64 (P, 3),
``rects`` int32 (P, 5) page, x, y, w, h) and their atlases (``color`` uint8 (L, H, W, 4) sRGB
with coverage alpha, ``normal`` uint8 (L, H, W, 3)); param ``epsilon_world``.

``dmbbc``: the flat cloud's arrays prefixed ``bbc_`` (its params under param ``cloud``), and
per box K ``bK_box_to_world`` float64 (4, 4), ``bK_color``, ``bK_normal``, ``bK_distance``
uint8 and, for the shells, ``bK_displacement`` uint16; params ``variant``, ``boxes`` (the
count), ``thickness``. The distance textures are checked against the maps on reading
(`distance.box_distance`).
"""

from __future__ import annotations

from dataclasses import replace

from ...errors import FormatError, UsageError
from ...io.rk import ArraySpec, Codec
from .boxes import BillboardBox, BillboardBoxes
from .distance import box_distance
from .representation import BillboardCloud

MAX_RECTANGLES = 4096
MAX_BOXES = 256  # a DMBBC's boxes (the paper's have 8 to 31)


def _rows(dtype: str, cols: int) -> ArraySpec:
    """One row per rectangle, at most `MAX_RECTANGLES` (refused before inflating)."""
    return ArraySpec((dtype,), ndim=2, trailing=(cols,), finite=True,
                     max_size=cols * MAX_RECTANGLES)


CLOUD_ARRAYS = {
    "corners": _rows("float64", 3),
    "u_axes": _rows("float64", 3),
    "v_axes": _rows("float64", 3),
    "rects": ArraySpec(("int32",), ndim=2, trailing=(5,), max_size=5 * MAX_RECTANGLES),
    "color": ArraySpec(("uint8",), ndim=4, trailing=(None, None, 4), role="color"),
    "normal": ArraySpec(("uint8",), ndim=4, trailing=(None, None, 3), role="normal"),
    "source_bounds": ArraySpec(("float64",), ndim=2, trailing=(2, 3), required=False,
                               finite=True),
}


def _cloud_to_arrays(cloud: BillboardCloud) -> tuple[dict, dict]:
    arrays = {"corners": cloud.corners, "u_axes": cloud.u_axes, "v_axes": cloud.v_axes,
              "rects": cloud.rects, "color": cloud.color, "normal": cloud.normal,
              "source_bounds": cloud.source_bounds}
    return arrays, dict(cloud.params) | {"epsilon_world": cloud.epsilon}


def _cloud_from_arrays(arrays: dict, params: dict) -> BillboardCloud:
    params = dict(params)
    epsilon = params.pop("epsilon_world", None)
    if isinstance(epsilon, bool) or not isinstance(epsilon, int | float):
        raise FormatError(f"billboard-cloud param 'epsilon_world' must be a number, got "
                          f"{epsilon!r}")
    try:
        return BillboardCloud(arrays["corners"], arrays["u_axes"], arrays["v_axes"],
                              arrays["rects"], arrays["color"], arrays["normal"], epsilon,
                              source_bounds=arrays.get("source_bounds"), params=params)
    except (UsageError, TypeError, ValueError) as exc:
        raise FormatError(f"invalid billboard cloud: {exc}") from None


def _optional(spec: ArraySpec) -> ArraySpec:
    return replace(spec, required=False)


BOX_ARRAYS = {
    "box_to_world": ArraySpec(("float64",), ndim=2, trailing=(4, 4), finite=True),
    "color": ArraySpec(("uint8",), ndim=(3, 4), trailing=(None, 4), role="color"),
    "normal": ArraySpec(("uint8",), ndim=(3, 4), trailing=(None, 3), role="normal"),
    "distance": ArraySpec(("uint8",), ndim=3),
    "displacement": ArraySpec(("uint16",), ndim=3, required=False),
}
BOXES_ARRAYS = ({f"bbc_{name}": spec for name, spec in CLOUD_ARRAYS.items()}
                | {f"b{k}_{name}": spec if k == 0 else _optional(spec)
                   for k in range(MAX_BOXES) for name, spec in BOX_ARRAYS.items()}
                | {"source_bounds": CLOUD_ARRAYS["source_bounds"]})


def _boxes_to_arrays(rep: BillboardBoxes) -> tuple[dict, dict]:
    cloud_arrays, cloud_params = _cloud_to_arrays(rep.cloud)
    arrays = {f"bbc_{name}": a for name, a in cloud_arrays.items()}
    for k, box in enumerate(rep.boxes):
        arrays |= {f"b{k}_box_to_world": box.box_to_world, f"b{k}_color": box.color,
                   f"b{k}_normal": box.normal, f"b{k}_distance": box.distance,
                   f"b{k}_displacement": box.displacement}
    arrays["source_bounds"] = rep.source_bounds
    own = ("variant", "boxes", "thickness", "cloud")  # the codec's, written last
    params = {k: v for k, v in rep.params.items() if k not in own}
    params |= {"variant": rep.variant, "boxes": len(rep.boxes), "thickness": rep.thickness,
               "cloud": cloud_params}
    return arrays, params


def _boxes_from_arrays(arrays: dict, params: dict) -> BillboardBoxes:
    params = dict(params)
    count, cloud_params = params.pop("boxes", None), params.pop("cloud", None)
    if isinstance(count, bool) or not isinstance(count, int) or not 1 <= count <= MAX_BOXES:
        raise FormatError(f"dmbbc param 'boxes' must be 1..{MAX_BOXES}, got {count!r}")
    if not isinstance(cloud_params, dict):
        raise FormatError("dmbbc param 'cloud' must be an object (the flat cloud's params)")
    extra = [k for k in range(count, MAX_BOXES) if f"b{k}_color" in arrays]
    missing = [k for k in range(count) if f"b{k}_color" not in arrays]
    if extra or missing:
        raise FormatError(f"dmbbc says {count} boxes but the arrays of box "
                          f"{(extra or missing)[0]} are {'there' if extra else 'missing'}")
    cloud = _cloud_from_arrays({name: arrays.get(f"bbc_{name}") for name in CLOUD_ARRAYS},
                               cloud_params)
    try:
        boxes = [BillboardBox(arrays[f"b{k}_box_to_world"], arrays[f"b{k}_color"],
                              arrays[f"b{k}_normal"], arrays[f"b{k}_distance"],
                              arrays.get(f"b{k}_displacement")) for k in range(count)]
        rep = BillboardBoxes(params.pop("variant", None), boxes, cloud,
                             thickness=params.pop("thickness", None),
                             source_bounds=arrays.get("source_bounds"), params=params)
    except KeyError as exc:
        raise FormatError(f"dmbbc box array {exc} is missing") from None
    except (UsageError, TypeError, ValueError) as exc:
        raise FormatError(f"invalid displacement-mapped billboard cloud: {exc}") from None
    _check_distances(rep)
    return rep


def _check_distances(rep: BillboardBoxes) -> None:
    """Refuse distance textures that promise more room than the boxes' own maps leave: the
    sphere march would jump over surfaces (a smaller distance only costs steps)."""
    for k, box in enumerate(rep.boxes):
        unsafe = int((box.distance > box_distance(box, rep.variant, rep.thickness)).sum())
        if unsafe:
            raise FormatError(f"dmbbc box {k}: its distance texture exceeds the distance to "
                              f"its occupied cells in {unsafe:,} of its {box.distance.size:,} "
                              "voxels (a damaged or forged file)")


CODECS = (
    Codec(kind="billboard-cloud", cls=BillboardCloud, arrays=CLOUD_ARRAYS,
          to_arrays=_cloud_to_arrays, from_arrays=_cloud_from_arrays, version=1),
    Codec(kind="dmbbc", cls=BillboardBoxes, arrays=BOXES_ARRAYS,
          to_arrays=_boxes_to_arrays, from_arrays=_boxes_from_arrays, version=1),
)
