"""Drawing `BillboardBoxes` (Mantler, Jeschke & Wimmer §3.2, §3.4.1): each box's proxy is
rasterized and every fragment marches its pixel's ray through the box's voxel cells.

The ray is rebuilt from the window position (as relief textures do), clipped to the box in
box coordinates and marched in voxel coordinates (box coordinates times (W, H, D)) by one of
three modes (``BoxRenderOptions.march``):

* ``exact`` -- volumetric: a 3D DDA (Amanatides & Woo) over the voxels, the hit is the entry
  point of the first occupied cell; shells: a 2D DDA over the texel columns, in each column
  the ray's w-interval is intersected with the texel's occupied interval ([d - t/2, d + t/2]
  or [lo, hi]). Exact for the nearest-sampled representation: the reference of the others.
* ``uniform`` -- the paper's linear sampling: points ``1 / samples`` voxel apart, the first
  inside the occupied set.
* ``sphere`` -- sphere tracing over the distance texture (§3.4.1, Donnelly): jump by the
  cell's safe step where it is positive, else one exact DDA step (a cell or a column), so no
  occupied cell is skipped.

Safety of the sphere step. The distance texel of cell c holds, as box_bake.py computes it,
the world distance between c's centre and the nearest occupied voxel's centre in units of
the smallest voxel side, rounded down (for the shells an occupied voxel is one that meets
the texel's interval, `distance.occupancy`). The paper subtracts half a voxel
diagonal; that is not enough when the occupied set is whole cells: a point p anywhere in c
and a point q anywhere in an occupied cell o are at least |c - o| - (half diagonal of c) -
(half diagonal of o) apart, so the safe world radius is ``stored * s_min - diagonal`` (the
corner-touching neighbour of a cubic grid has |c - o| = sqrt(3) and distance 0, where
sqrt(3) - sqrt(3)/2 would step 0.87 voxel into it; a test checks both by brute force). The march
runs in voxel coordinates, where a step r covers at most ``r * sigma`` of world (sigma: the
largest singular value of the voxel's edge matrix), so the step is ``stored *
u_distance_scale - u_distance_margin`` with scale ``s_min / sigma`` and margin ``diagonal /
sigma`` (`distance_uniforms`; 1 and sqrt(3) for cubic voxels), from the box as baked (not as
flattened: flattening changes no cell).

Textures (one set per box, every lookup a ``texelFetch`` of the cell, NEAREST filtering):
volumetric colour (D, H, W, 4) RGBA8 3D, decoded from sRGB in the shader (moderngl cannot
give a 3D texture an sRGB internal format; with nearest fetches the decode is what an sRGB
texture would return), normal RGB8 3D; shells colour SRGB8_ALPHA8 2D, normal RGB8 2D,
displacement R16UI / RG16UI 2D (integer textures read with a ``usampler2D``: the uint16 value
exactly, w = value / 65535); every variant its (D, H, W) uint8 distance 3D texture
(normalised, times 255 in the shader). The executor checks all sizes of all boxes against
the GL limits before anything is allocated.

Each box is one draw plan (`render.plan`): its proxy relative to an interior point, the
plan's ``origin`` (camera-relative rendering), its textures and fixed uniforms. Its view
hook `box_view` gives what changes with the camera: the box transforms relative to the
camera's origin (``translation(-camera.origin) @ box_to_world`` and its `invert_box`),
flattened as the options or the distance say, and the proxy's faces to cull. With lod auto
the cloud's own plan follows the boxes', and `view_lod` switches between them per view.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ...compact.encodings import encoding_of
from ...core.params import param
from ...core.technique import DrawableSpec, ProgramVariant
from ...core.transforms import invert_box
from ...errors import UsageError
from ...gl.uniforms import box_uniforms
from ...render.instancing import per_object
from ...render.plan import (
    Attribute,
    DrawPlan,
    Geometry,
    Program,
    Texture,
    ViewHook,
    ViewUpdate,
)
from ...render.proxy import PROXY_RASTER, Proxy, box_planes, convex_proxy, cull_face
from ...scene.camera import Camera
from .boxes import BillboardBox, BillboardBoxes
from .lod import flatten_factor
from .render import cloud_plan

PROGRAM = "billboard:boxes.glsl"
MARCHES = ("sphere", "uniform", "exact")
VARIANT_DEFINES = {"volumetric": "VOLUMETRIC", "shell": "SHELL", "thick-shell": "THICK_SHELL"}
#: ``flatten`` below this is drawn at this: a box of zero depth has no inside to rasterize.
MIN_FLATTEN = 1e-3

PROGRAMS = tuple(ProgramVariant(PROGRAM, {define: True, f"MARCH_{march.upper()}": True}
                                | ({"COUNT_ITERATIONS": True} if counted else {}))
                 for define in VARIANT_DEFINES.values() for march in MARCHES
                 for counted in (False, True))  # every draw-path variant (GLSL ES test)


@dataclass(frozen=True)
class BoxRenderOptions:
    """The render options of displacement-mapped billboard boxes."""

    march: str = param("sphere", "how rays walk the voxels: sphere tracing over the distance "
                       "texture, uniform samples, or an exact DDA (the reference)",
                       choices=MARCHES)
    samples: int = param(2, "uniform march: samples per voxel along the ray", lo=1, hi=64)
    flatten: float = param(1.0, "scale of the boxes' depth about their rectangles (1: full "
                           "depth; toward 0 flat, §3.4.2; below 0.001 drawn at 0.001)",
                           lo=0.0, hi=1.0)
    max_iterations: int = param(0, "bound on every march (0: from the box's resolution)",
                                lo=0, hi=16384)
    lod: str = param("off", "auto: flatten the boxes with distance and draw the flat "
                     "billboard cloud beyond the distance where epsilon is under a pixel "
                     "(§3.4.2)", choices=("off", "auto"))
    transition: float = param(0.5, "lod auto: flattening starts at this fraction of the "
                              "switch distance", lo=0.0, hi=0.999)


def _check_applicable(opts: BoxRenderOptions) -> None:
    """Refuse options the other options make meaningless (they were silently ignored, or,
    for flatten under lod auto, honoured near and dropped far)."""
    default = BoxRenderOptions()
    if opts.lod == "auto" and opts.flatten != default.flatten:
        raise UsageError("--flatten applies with --lod off: --lod auto sets the flattening from "
                         "the distance (§3.4.2); give one or the other")
    if opts.lod != "auto" and opts.transition != default.transition:
        raise UsageError("--transition applies only with --lod auto")
    if opts.march != "uniform" and opts.samples != default.samples:
        raise UsageError(f"--samples applies only to --march uniform, not {opts.march}")


def scale_w(factor: float) -> np.ndarray:
    """Box coordinates scaled by ``factor`` along w about the box's mid-plane w = 0.5."""
    m = np.eye(4)
    m[2, 2] = factor
    m[2, 3] = 0.5 * (1.0 - factor)
    return m


def drawn_box_to_world(box_to_world, flatten: float = 1.0) -> np.ndarray:
    """A box as drawn: ``box_to_world @ scale_w(flatten)``, flatten clamped to
    `MIN_FLATTEN`; the box coordinates of the data (u, v, w) are unchanged."""
    return np.asarray(box_to_world, np.float64) @ scale_w(max(float(flatten), MIN_FLATTEN))


def distance_uniforms(box: BillboardBox) -> dict:
    """``u_distance_scale`` and ``u_distance_margin``: a stored distance -> a safe step in
    voxel coordinates (module docstring), from the box as baked."""
    edges = np.asarray(box.box_to_world, np.float64)[:3, :3] / np.array(box.resolution)
    sides = np.linalg.norm(edges, axis=0)
    sigma = float(np.linalg.norm(edges, ord=2))
    diagonal = max(float(np.linalg.norm(edges @ signs))
                   for signs in ([1, 1, 1], [1, 1, -1], [1, -1, 1], [-1, 1, 1]))
    return {"u_distance_scale": float(sides.min()) / sigma,
            "u_distance_margin": diagonal / sigma}


def automatic_iterations(res, march: str, variant: str, samples: int, min_step: float) -> int:
    """A bound no correct march of a (W, H, D) box reaches: a DDA visits at most W + H + D
    cells (W + H columns), uniform samples the diagonal ``samples`` times per voxel, and
    every sphere step covers at least ``min_step`` voxel."""
    w, h, d = res
    diagonal = math.ceil(math.sqrt(w * w + h * h + d * d))
    cells = w + h + d if variant == "volumetric" else w + h
    if march == "uniform":
        return samples * diagonal + 2
    if march == "exact":
        return cells + 2
    return cells + math.ceil(diagonal / max(min_step, 0.05)) + 4


def _min_sphere_step(scale: float, margin: float) -> float:
    """The shortest positive step ``n * scale - margin`` over whole n."""
    return math.floor(margin / scale + 1.0) * scale - margin


#: Where ``u_bbc_color`` and ``u_bbc_normal`` point without lod auto: units no texture of a
#: box uses (the shader declares them, and two sampler types may not share a unit).
_NO_CLOUD_UNITS = {"u_bbc_color": 4, "u_bbc_normal": 5}


def box_textures(box: BillboardBox, variant: str, k: int) -> dict:
    """Box ``k``'s textures by sampler name, every one sampled with ``texelFetch``."""
    out = {"u_distance": Texture(box.distance, target="3d", filter="nearest",
                                 what=f"box {k} distance")}
    if variant == "volumetric":
        out["u_color"] = Texture(box.color, target="3d", filter="nearest",
                                 what=f"box {k} colour", encoded=encoding_of(box.color))
        out["u_normal"] = Texture(box.normal, target="3d", filter="nearest",
                                  what=f"box {k} normal", encoded=encoding_of(box.normal))
    else:
        out["u_color"] = Texture(box.color, srgb=True, filter="nearest", what=f"box {k} colour",
                                 encoded=encoding_of(box.color))
        out["u_normal"] = Texture(box.normal, filter="nearest", what=f"box {k} normal",
                                  encoded=encoding_of(box.normal))
        out["u_displacement"] = Texture(box.displacement, filter="nearest",
                                        what=f"box {k} displacement")
    return out


class BillboardBoxesDrawable:
    """Every box of a `BillboardBoxes` as one draw plan, drawn one after another with the
    depth test on; each fragment writes its hit's depth, so overlapping boxes and other
    objects resolve. With lod auto the flat cloud's plan comes last, drawn instead of the
    boxes beyond the switch distance."""

    def __init__(self, boxes: BillboardBoxes, options: BoxRenderOptions | None = None,
                 instrument: bool = False):
        opts = options or BoxRenderOptions()
        if opts.march not in MARCHES:
            raise UsageError(f"march must be one of {', '.join(MARCHES)}, got {opts.march!r}")
        _check_applicable(opts)
        self.boxes, self.options = boxes, opts
        self.extra_attachments = 1 if instrument else 0
        program = Program(PROGRAM, {VARIANT_DEFINES[boxes.variant]: True,
                                    f"MARCH_{opts.march.upper()}": True,
                                    "COUNT_ITERATIONS": instrument})
        lod = None if opts.lod != "auto" else {
            "epsilon": float(boxes.epsilon), "center": tuple(float(x) for x in boxes.center),
            "transition": float(opts.transition)}
        cloud = cloud_plan(boxes.cloud, instrument) if lod else None
        self.plans = [box_plan(boxes, k, program, opts, lod, cloud)
                      for k in range(len(boxes.boxes))]
        if cloud is not None:
            self.plans.append(replace(cloud, per_view=ViewHook(
                f"{__name__}:cloud_view", {"flatten": opts.flatten, "lod": lod})))

    def finish(self, frame, stats: dict) -> None:
        frame.stats["boxes"] = len(self.boxes.boxes)
        frame.stats |= stats


def box_plan(boxes: BillboardBoxes, k: int, program: Program, opts: BoxRenderOptions,
             lod: dict | None, cloud: DrawPlan | None) -> DrawPlan:
    """Box ``k``'s draw: the proxy of the whole box (it contains every flattening of it),
    its textures and, with lod auto, the cloud's atlases to hand over to."""
    box = boxes.boxes[k]
    full = np.asarray(box.box_to_world, np.float64)
    proxy = convex_proxy(box_planes(invert_box(full)),
                         near=full[:3, 3] + full[:3, :3] @ [0.5, 0.5, 0.5])
    distance = distance_uniforms(box)
    min_step = _min_sphere_step(distance["u_distance_scale"], distance["u_distance_margin"])
    uniforms = distance | {
        "u_res": box.resolution, "u_samples": opts.samples,
        "u_half_thickness": 0.5 * float(boxes.thickness or 0.0),
        "u_max_iterations": opts.max_iterations or automatic_iterations(
            box.resolution, opts.march, boxes.variant, opts.samples, min_step),
    } | _atlas_uniforms(boxes.cloud, k)
    textures = box_textures(box, boxes.variant, k)
    if cloud is None:
        uniforms |= _NO_CLOUD_UNITS
    else:
        textures |= {"u_bbc_color": cloud.textures["u_color_atlas"],
                     "u_bbc_normal": cloud.textures["u_normal_atlas"]}
    return DrawPlan(
        name=f"box {k}", program=program,
        geometry=Geometry({"in_position": Attribute(proxy.positions)},
                          indices=proxy.triangles),
        textures=textures, uniforms=uniforms, raster=PROXY_RASTER,
        origin=tuple(float(x) for x in proxy.origin),
        per_view=ViewHook(f"{__name__}:box_view", {
            "box_to_world": full, "planes": proxy.planes, "flatten": opts.flatten,
            "lod": lod}))


def view_lod(camera, flatten: float, lod: dict | None) -> dict:
    """What the boxes draw from ``camera``: ``lod`` "boxes" or "billboard cloud" and the
    boxes' ``flatten``; with lod auto (``lod``: epsilon, center, transition) the flattening
    comes from the distance (§3.4.2) and the cloud is drawn where it reaches 0."""
    if lod is not None and isinstance(camera, Camera):
        flatten = flatten_factor(camera, lod["epsilon"], lod["center"], lod["transition"])
    cloud = lod is not None and flatten <= 0.0
    return {"lod": "billboard cloud" if cloud else "boxes", "flatten": flatten}


@per_object("it flattens each box and hands it over to the billboard cloud by the "
            "object's own distance from the camera")
def box_view(plan: DrawPlan, camera, light, *, box_to_world, planes, flatten: float,
             lod: dict | None) -> ViewUpdate:
    """A box from ``camera``: its transforms flattened, in the camera's relative world
    space, the hand-over to the cloud (lod auto), the proxy's faces to cull; nothing
    beyond the switch distance."""
    drawn = view_lod(camera, flatten, lod)
    if drawn["lod"] != "boxes":
        return ViewUpdate(count=0, stats=drawn)
    geometry = plan.geometry
    proxy = Proxy(geometry.attributes["in_position"].array, geometry.indices, planes,
                  np.asarray(plan.origin, np.float64))
    handoff = 1.0 - drawn["flatten"] if lod is not None else 0.0
    uniforms = {"u_handoff": float(handoff)} | box_uniforms(
        camera, drawn_box_to_world(box_to_world, drawn["flatten"]))
    return ViewUpdate(uniforms=uniforms, cull=cull_face(proxy, camera), stats=drawn)


@per_object("it draws the flat cloud or the boxes by the object's own distance "
            "from the camera")
def cloud_view(plan: DrawPlan, camera, light, *, flatten: float, lod: dict) -> ViewUpdate:
    """The flat cloud of lod auto from ``camera``: drawn only beyond the switch distance."""
    drawn = view_lod(camera, flatten, lod)
    return ViewUpdate(count=None if drawn["lod"] == "billboard cloud" else 0, stats=drawn)


def _atlas_uniforms(cloud, k: int) -> dict:
    """Where box k's rectangle lies in the cloud's atlas (box u, v = the rectangle's s, t)."""
    page, x, y, w, h = (float(v) for v in cloud.rects[k])
    height, width = cloud.color.shape[1:3]
    return {"u_atlas_rect": (x / width, y / height, w / width, h / height),
            "u_atlas_page": page}


def drawable_spec() -> DrawableSpec:
    """The `DrawableSpec` of `BillboardBoxes` for the package's Technique."""
    return DrawableSpec(BillboardBoxes, BillboardBoxesDrawable, BoxRenderOptions)
