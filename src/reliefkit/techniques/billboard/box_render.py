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
the texel's interval, `box_reference.occupied_voxels`). The paper subtracts half a voxel
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
(normalised, times 255 in the shader). All sizes of all boxes are checked against the GL
limits before anything is allocated.

Camera-relative rendering: each proxy is stored in float32 relative to an interior point and
placed with ``u_model_offset``; the box transforms are handed over relative to the camera's
origin (``translation(-camera.origin) @ box_to_world`` and its `invert_box`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...core.params import param
from ...core.technique import DrawableSpec, ProgramVariant
from ...core.transforms import invert_box
from ...errors import UsageError
from ...gl.context import check_gl_error
from ...gl.shaders import program
from ...gl.textures import check_3d_size, texture2d, texture3d
from ...gl.uniforms import box_uniforms, camera_uniforms, model_offset, set_uniforms
from ...render.proxy import box_planes, convex_proxy, cull_face, proxy_raster_state
from ...scene.camera import Camera
from .boxes import BillboardBox, BillboardBoxes
from .lod import flatten_factor

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
        raise UsageError("flatten applies with lod off: lod auto sets the flattening from "
                         "the distance (§3.4.2); give one or the other")
    if opts.lod != "auto" and opts.transition != default.transition:
        raise UsageError("transition applies only with lod auto")
    if opts.march != "uniform" and opts.samples != default.samples:
        raise UsageError(f"samples applies only to the uniform march, not {opts.march}")


def scale_w(factor: float) -> np.ndarray:
    """Box coordinates scaled by ``factor`` along w about the box's mid-plane w = 0.5."""
    m = np.eye(4)
    m[2, 2] = factor
    m[2, 3] = 0.5 * (1.0 - factor)
    return m


def drawn_box_to_world(box: BillboardBox, flatten: float = 1.0) -> np.ndarray:
    """The box as drawn: ``box_to_world @ scale_w(flatten)``, flatten clamped to
    `MIN_FLATTEN`; the box coordinates of the data (u, v, w) are unchanged."""
    return np.asarray(box.box_to_world, np.float64) @ scale_w(max(float(flatten), MIN_FLATTEN))


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


def check_box_sizes(ctx, boxes: BillboardBoxes) -> None:
    """Every texture of every box against the GL limits, before any is allocated."""
    from ...gl.textures import _check_2d

    for k, box in enumerate(boxes.boxes):
        w, h, d = box.resolution
        check_3d_size(ctx, w, h, d, f"box {k} distance", nbytes=box.distance.nbytes)
        if boxes.variant == "volumetric":
            check_3d_size(ctx, w, h, d, f"box {k} colour", nbytes=box.color.nbytes)
        else:
            _check_2d(ctx, w, h, f"box {k} colour")


def box_textures(ctx, box: BillboardBox, variant: str) -> dict:
    """The box's textures by sampler name (released by the caller, also on failure: they
    are added to ``out`` one by one)."""
    out = {}
    try:
        out["u_distance"] = texture3d(ctx, box.distance, what="distance", filter="nearest")
        if variant == "volumetric":
            out["u_color"] = texture3d(ctx, box.color, what="colour", filter="nearest")
            out["u_normal"] = texture3d(ctx, box.normal, what="normal", filter="nearest")
        else:
            out["u_color"] = texture2d(ctx, box.color, what="colour", srgb=True,
                                       filter="nearest")
            out["u_normal"] = texture2d(ctx, box.normal, what="normal", filter="nearest")
            out["u_displacement"] = texture2d(ctx, box.displacement, what="displacement",
                                              filter="nearest")
    except BaseException:
        for tex in out.values():
            tex.release()
        raise
    return out


class _BoxPart:
    """One box's GL objects: textures, proxy buffers, its fixed uniforms."""

    def __init__(self, ctx, prog, box: BillboardBox, variant: str, opts, thickness):
        self.box = box
        full = np.asarray(box.box_to_world, np.float64)  # contains every flattening of it
        self.proxy = convex_proxy(box_planes(invert_box(full)),
                                  near=full[:3, 3] + full[:3, :3] @ [0.5, 0.5, 0.5])
        self.textures, self.vao, self.vbo, self.ibo = {}, None, None, None
        try:
            self.textures = box_textures(ctx, box, variant)
            self.vbo = ctx.buffer(self.proxy.positions.tobytes())
            self.ibo = ctx.buffer(self.proxy.triangles.tobytes())
            self.vao = ctx.vertex_array(prog, [(self.vbo, "3f", "in_position")], self.ibo,
                                        index_element_size=4)
        except BaseException:
            self.release()
            raise
        distance = distance_uniforms(box)
        min_step = _min_sphere_step(distance["u_distance_scale"], distance["u_distance_margin"])
        self.uniforms = distance | {
            "u_res": box.resolution, "u_samples": opts.samples,
            "u_half_thickness": 0.5 * float(thickness or 0.0),
            "u_max_iterations": opts.max_iterations or automatic_iterations(
                box.resolution, opts.march, variant, opts.samples, min_step)}

    def box_uniforms(self, camera, flatten: float) -> dict:
        """The box transforms, flattened, in the camera's relative world space."""
        return box_uniforms(camera, drawn_box_to_world(self.box, flatten))

    def release(self) -> None:
        for obj in (self.vao, self.vbo, self.ibo, *self.textures.values()):
            if obj is not None:
                obj.release()
        self.vao = self.vbo = self.ibo = None
        self.textures = {}


class BillboardBoxesDrawable:
    """Every box of a `BillboardBoxes`, drawn one after another with the depth test on; each
    fragment writes its hit's depth, so overlapping boxes and other objects resolve."""

    def __init__(self, ctx, boxes: BillboardBoxes, options: BoxRenderOptions | None = None,
                 instrument: bool = False):
        opts = options or BoxRenderOptions()
        if opts.march not in MARCHES:
            raise UsageError(f"march must be one of {', '.join(MARCHES)}, got {opts.march!r}")
        _check_applicable(opts)
        self.ctx, self.boxes, self.options = ctx, boxes, opts
        self.extra_attachments = 1 if instrument else 0
        check_box_sizes(ctx, boxes)
        self.prog = program(ctx, PROGRAM, {
            VARIANT_DEFINES[boxes.variant]: True, f"MARCH_{opts.march.upper()}": True,
            "COUNT_ITERATIONS": instrument})
        self.parts: list[_BoxPart] = []
        self.cloud = None  # the flat cloud, drawn beyond the switch distance (lod auto)
        self.drawn = {}
        try:
            for k, box in enumerate(boxes.boxes):
                self.parts.append(_BoxPart(ctx, self.prog, box, boxes.variant, opts,
                                           boxes.thickness))
                self.parts[-1].uniforms |= _atlas_uniforms(boxes.cloud, k)
            if opts.lod == "auto":
                from ...render.executor import Executor
                from .render import cloud_plan

                self.cloud_plan = cloud_plan(boxes.cloud, instrument)
                self.cloud = Executor(ctx)
                self.cloud.upload([self.cloud_plan])
        except BaseException:
            self.release()
            raise
        check_gl_error(ctx, "uploading billboard boxes")

    def draw(self, camera, light) -> None:
        flatten = self.options.flatten  # lod auto's own where it applies (not both)
        if self.cloud is not None and isinstance(camera, Camera):
            flatten = flatten_factor(camera, self.boxes.epsilon, self.boxes.center,
                                     self.options.transition)
        self.drawn = {"lod": "boxes", "flatten": flatten}
        if self.cloud is not None and flatten <= 0.0:
            self.drawn["lod"] = "billboard cloud"
            self.cloud.draw(self.cloud_plan, camera, light)
            return
        self._draw_boxes(camera, light, flatten,
                         handoff=1.0 - flatten if self.cloud is not None else 0.0)

    def _handoff_uniforms(self, camera, handoff: float) -> dict:
        """What the shader needs to fade into the cloud's own filtered colour and normal."""
        values = {"u_handoff": float(handoff), "u_bbc_color": _CLOUD_COLOR_UNIT,
                  "u_bbc_normal": _CLOUD_NORMAL_UNIT}
        if handoff > 0.0:
            self.cloud.texture(self.cloud_plan.textures["u_color_atlas"]).use(_CLOUD_COLOR_UNIT)
            self.cloud.texture(self.cloud_plan.textures["u_normal_atlas"]).use(
                _CLOUD_NORMAL_UNIT)
        return values

    def _draw_boxes(self, camera, light, flatten: float, handoff: float = 0.0) -> None:
        set_uniforms(self.prog, camera_uniforms(camera) | light.uniforms()
                     | self._handoff_uniforms(camera, handoff))
        with proxy_raster_state(self.ctx):
            for part in self.parts:
                set_uniforms(self.prog, part.uniforms | part.box_uniforms(camera, flatten)
                             | model_offset(camera, part.proxy.origin))
                for unit, (name, tex) in enumerate(part.textures.items()):
                    tex.use(unit)
                    set_uniforms(self.prog, {name: unit})
                self.ctx.cull_face = cull_face(part.proxy, camera)
                part.vao.render()

    def finish(self, frame) -> None:
        frame.stats["boxes"] = len(self.parts)
        frame.stats |= self.drawn

    def release(self) -> None:
        for part in self.parts:
            part.release()
        self.parts = []
        if self.cloud is not None:
            self.cloud.release()
            self.cloud = None


_CLOUD_COLOR_UNIT, _CLOUD_NORMAL_UNIT = 4, 5  # after a box's own (at most 4) textures


def _atlas_uniforms(cloud, k: int) -> dict:
    """Where box k's rectangle lies in the cloud's atlas (box u, v = the rectangle's s, t)."""
    page, x, y, w, h = (float(v) for v in cloud.rects[k])
    height, width = cloud.color.shape[1:3]
    return {"u_atlas_rect": (x / width, y / height, w / width, h / height),
            "u_atlas_page": page}


def drawable_spec() -> DrawableSpec:
    """The `DrawableSpec` of `BillboardBoxes` for the package's Technique."""
    return DrawableSpec(BillboardBoxes, BillboardBoxesDrawable, BoxRenderOptions)
