"""Drawing a `DisplacementMap` by slicing (§3): per frame the slice polygons are computed on
the CPU (`displacement_slices`), uploaded as one triangle list and drawn in one call with the
depth test; shaders/displacement.glsl keeps a fragment by the alpha test against its h.

The slices are alpha-tested opaque fragments, so their order does not matter (the depth test
keeps the nearest). The number of h slices K is the ``slices`` option, or automatic: a
spacing scale / K of at most one pixel's world footprint at the object (so the eye cannot see
between slices seen face-on), but no finer than one height texel's world size (finer slices
show nothing new), K clamped to [2, 512] (`auto_slices`), and halved while the frame would
need more than `displacement_slices.MAX_POLYGONS` polygons; the slices across the volume
(orthogonal u and v, screen planes) are then never closer than that spacing either, so a
displacement thinner than a pixel costs the base and a few slices, not 1 / scale of them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...bake.uv_atlas import atlas_uniforms
from ...core.params import param
from ...core.technique import DrawableSpec, ProgramVariant
from ...gl.context import check_gl_error
from ...gl.objects import GLObjects
from ...gl.shaders import program
from ...gl.textures import texture2d, texture_array
from ...gl.uniforms import camera_uniforms, model_offset, set_uniforms
from .displacement import DisplacementMap
from .displacement_slices import MODES, TooManyPolygons, slice_triangles
from .slices import auto_slice_count, pixel_world_size, projected_area

PROGRAM = "slicing:displacement.glsl"
PROGRAMS = (ProgramVariant(PROGRAM, {}), ProgramVariant(PROGRAM, {"UNLIT": True}))
ALPHA_TESTS = ("fill", "bound")
AUTO_MIN, AUTO_MAX = 2, 512
_HEIGHT_UNIT, _COLOR_UNIT, _SURFACE_UNIT = 0, 1, 2


@dataclass(frozen=True)
class DisplacementRenderOptions:
    """The render options of displacement maps."""

    slicing: str = param("orthogonal", "slice planes: offset surfaces h = const (§3.1), the "
                         "per-triangle direction most perpendicular to the view (§3.2), or "
                         "planes facing the screen cut exactly through the volume (§3.3)",
                         choices=MODES)
    slices: int | None = param(None, "h slices K (none: automatic from the size on screen, "
                               f"clamped to [{AUTO_MIN}, {AUTO_MAX}])", kind="int", lo=1,
                               hi=4096)
    alpha_test: str = param("fill", "surface slicing: draw where height >= h (fill, "
                            "Dietrich) or only within one slice of it (bound, Schaufler)",
                            choices=ALPHA_TESTS)
    unlit: bool = param(False, "the colour texture without lighting")


def texel_world_size(rep: DisplacementMap) -> float:
    """World size of one height texel on the base (the finest of its two directions)."""
    base = rep.base
    tris = np.asarray(base.indices, np.int64)
    p = base.world_positions[tris]
    uv = np.asarray(base.uvs, np.float64)[tris]
    area = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1).sum()
    d1, d2 = uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0]
    uv_area = 0.5 * np.abs(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]).sum()
    per_uv = math.sqrt(area / uv_area) if uv_area > 0 else math.sqrt(area)
    h, w = rep.height.shape
    return per_uv / max(w * rep.tile[0], h * rep.tile[1])


def finest_spacing(rep: DisplacementMap, camera) -> float:
    """The closest useful slice spacing: one pixel's world size at the object's centre, but
    no finer than one height texel's world size."""
    lo, hi = rep.bounds
    return max(pixel_world_size(camera, 0.5 * (lo + hi)), texel_world_size(rep))


def auto_slices(rep: DisplacementMap, camera) -> int:
    """K = ceil(scale / spacing), spacing = `finest_spacing`, clamped to [AUTO_MIN,
    AUTO_MAX] (`slices.auto_slice_count`)."""
    lo, hi = rep.bounds
    return auto_slice_count(rep.scale, camera, 0.5 * (lo + hi), texel_world_size(rep),
                            maximum=AUTO_MAX)


def vertex_data(tris, origin, layers) -> np.ndarray:
    """(3M, 16) float32: position relative to ``origin``, (u, v, h), d/du, d/dv, d/dh, the
    surface layer (``layers`` (F,) per base triangle: `DisplacementMap.surface_layers`)."""
    j = tris.jacobian
    out = np.concatenate([tris.positions - origin, tris.box, j[:, :, 0], j[:, :, 1],
                          j[:, :, 2], layers[tris.triangle][:, None]], axis=1)
    return np.ascontiguousarray(out, np.float32)


class DisplacementDrawable(GLObjects):
    """The displacement texture on the GPU; slices recomputed for every camera."""

    def __init__(self, ctx, rep: DisplacementMap,
                 options: DisplacementRenderOptions | None = None, instrument: bool = False):
        self.ctx, self.rep = ctx, rep
        self.options = options or DisplacementRenderOptions()
        self.extra_attachments = 1 if instrument else 0
        self.instrument = instrument
        lo, hi = rep.bounds
        self.origin = 0.5 * (lo + hi)
        self.volume = None if self.options.slicing == "surface" else rep.volume()
        self.stats: dict = {}
        self._upload_owned(self._upload)

    def _upload(self) -> None:
        ctx, rep = self.ctx, self.rep
        self.prog = program(ctx, PROGRAM, {"UNLIT": self.options.unlit,
                                           "COUNT_ITERATIONS": self.instrument})
        self.height = self.keep(texture2d(ctx, rep.height, what="displacement height",
                                          filter="nearest"))
        self.color = self.keep(texture2d(ctx, rep.color, what="displacement colour",
                                         repeat=rep.wrap))
        if rep.surface is not None:
            self.surface = self.keep(texture_array(ctx, rep.surface.rgba8, srgb=True,
                                                   what="displacement surface materials"))
        check_gl_error(ctx, "uploading a displacement texture")

    def draw(self, camera, light) -> None:
        import moderngl

        rep, opts, ctx = self.rep, self.options, self.ctx
        count = opts.slices if opts.slices is not None else auto_slices(rep, camera)
        finest = finest_spacing(rep, camera) if opts.slices is None else 0.0
        while True:
            try:
                tris = slice_triangles(rep, camera, opts.slicing, count, self.volume, finest)
                break
            except TooManyPolygons:
                if opts.slices is not None or count <= AUTO_MIN:
                    raise
                count = max(AUTO_MIN, count // 2)  # automatic: halve until the slices fit
        h, w = rep.height.shape
        test = opts.alpha_test if opts.slicing == "surface" else "fill"
        bound = 1.0 / (count - 1) if count > 1 else 1.0
        self.stats = {"slices": int(count), "slicing": opts.slicing,
                      "alpha_test": test,
                      "slice_planes": int(tris.slices), "slice_polygons": int(tris.polygons),
                      "slice_triangles": int(tris.triangle_count),
                      "slice_spacing": float(tris.spacing),
                      "fill_pixels": projected_area(tris.positions, camera),
                      **{f"direction_{k}": v for k, v in tris.directions.items()}}
        if not tris.triangle_count:
            return
        data = vertex_data(tris, self.origin, rep.surface_layers())
        vbo = ctx.buffer(data.tobytes())
        try:
            vao = ctx.vertex_array(self.prog, [(vbo, "3f 3f 3f 3f 3f 1f", "in_position",
                                                "in_uvh", "in_ju", "in_jv", "in_jh",
                                                "in_layer")])
            try:
                set_uniforms(self.prog, camera_uniforms(camera)
                             | model_offset(camera, self.origin) | light.uniforms()
                             | {"u_height": _HEIGHT_UNIT, "u_color": _COLOR_UNIT,
                                "u_hf_size": (w, h), "u_wrap": rep.wrap,
                                "u_tile": tuple(rep.tile),
                                "u_test": ALPHA_TESTS.index(test),
                                "u_bound": float(bound)}
                             | atlas_uniforms(rep.surface, _SURFACE_UNIT))
                self.height.use(_HEIGHT_UNIT)
                self.color.use(_COLOR_UNIT)
                if rep.surface is not None:
                    self.surface.use(_SURFACE_UNIT)
                ctx.enable(moderngl.DEPTH_TEST)
                ctx.disable(moderngl.CULL_FACE)
                vao.render(moderngl.TRIANGLES)
                check_gl_error(ctx, f"drawing {tris.polygons} displacement slice polygons")
            finally:
                vao.release()
        finally:
            vbo.release()

    def finish(self, frame) -> None:
        frame.stats.update(self.stats)


def drawable_spec() -> DrawableSpec:
    return DrawableSpec(DisplacementMap, DisplacementDrawable, DisplacementRenderOptions)
