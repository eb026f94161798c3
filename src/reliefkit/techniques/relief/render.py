"""Relief textures: draw the box (or frustum) and intersect each pixel's ray in the shader."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...core.params import param
from ...errors import UsageError
from ...gl.context import check_gl_error
from ...gl.shaders import program
from ...gl.textures import texture2d, texture_array
from ...gl.uniforms import box_uniforms, camera_uniforms, model_offset, set_uniforms
from ...render.frame import window_depth
from ...render.proxy import (
    aabb_planes,
    box_planes,
    convex_proxy,
    cull_face,
    proxy_raster_state,
)
from .maxmip import max_pyramid_texture
from .representation import ReliefObject, ReliefTexture

METHODS = ("binary", "exact", "robust", "maxmip", "cone")
PROGRAM = "relief:relief.glsl"


@dataclass(frozen=True)
class ReliefRenderOptions:
    """The render options of relief textures (``reliefkit render --help`` shows them)."""

    method: str = param("robust", "ray/heightfield intersection: binary search, the exact "
                        "walk, safety radii (robust: needs them baked), a maximum mipmap "
                        "(maxmip: exact, built when drawn) or relaxed cone stepping (cone: "
                        "its cone map computed when drawn)", choices=METHODS)
    depth_mode: str = param("conservative", "keep the box depth in the Z-buffer, or write "
                            "the hit's depth (exact: correct with other objects)",
                            choices=("conservative", "exact"))
    shadows: bool = param(False, "self-shadowing: a ray from each hit to the light")
    zero_radius: str = param("exact", "robust method at a zero safety radius: walk exactly "
                             "to the next centreline, or clamp the radius to 1",
                             choices=("exact", "clamp"))
    exact_below: int = param(0, "robust: rays crossing fewer texels than this are walked "
                             "exactly (0: the paper's walk for every ray)", lo=0, hi=65536)
    exact_field: int = param(256, "robust: fields with W + H <= N are drawn with the exact "
                             "walk's program, the cheaper one there (0: every field jumps)",
                             lo=0, hi=65536)
    cell_test: str = param("quadratic", "exact walk: test each cell's exact quadratic, or "
                           "only its far end as the paper does",
                           choices=("quadratic", "linear"))
    linear_steps: int = param(16, "binary: fixed pre-steps", lo=1, hi=4096)
    binary_steps: int = param(8, "binary, cone: binary search steps once a hit is bracketed",
                              lo=1, hi=4096)
    cone_steps: int = param(32, "cone: steps before the ray stops where it is (GPU Gems 3 "
                            "uses 15)",
                            lo=1, hi=4096)
    maxmip_leaf: int = param(2, "maxmip: nodes of 2^L texels are walked cell by cell "
                             "(0: descend to single texels, as Tevs et al.)", lo=0, hi=15)
    max_iterations: int = param(0, "bound on every walk (0: 4 (W + H) + 64)", lo=0,
                                hi=16384)


def relief_proxy(relief: ReliefTexture):
    """The box (frustum) of a relief texture, cut to its ``clip_bounds`` when it has them."""
    planes = box_planes(relief.world_to_box)
    if relief.clip_bounds is not None:
        planes = np.vstack([planes, aabb_planes(relief.clip_bounds)])
    return convex_proxy(planes, near=relief.center)


def robust_jumps(width: int, height: int, options: ReliefRenderOptions) -> bool:
    """Whether robust jumps by safety radii on a W x H field. Robust walks every ray shorter
    than ``exact_below`` texels exactly, so when no ray of the field can be longer (W + H
    bounds |dx| + |dy|) the exact walk's own program draws the same hits without the robust
    code around it; so does a field so small (``exact_field``) that the exact walk is the
    cheaper one (up to 128² on llvmpipe; docs/benchmarks.md). Such a field never reads its
    radii."""
    return not (width + height <= options.exact_field or width + height < options.exact_below)


def drawn_method(relief: ReliefTexture, options: ReliefRenderOptions) -> str:
    """The method whose program draws ``relief``: robust's own, or the exact walk's where
    robust would not jump (`robust_jumps`)."""
    if options.method == "robust" and not robust_jumps(*relief.depth_resolution, options):
        return "exact"
    return options.method


class ReliefDrawable:
    """GPU textures and proxy of one ReliefTexture, drawn with one intersection method.

    The exact walk takes one bilinear cell per step (its four corners, the ray's exact
    quadratic in it, the exact root). ``cell_test="linear"`` is the paper's walk (a cell is
    hit only when its far end is below, §3.3); ``"quadratic"`` (default) also finds the
    saddle grazes inside a cell (Fig. 3).
    """

    def __init__(self, ctx, relief: ReliefTexture, options: ReliefRenderOptions | None = None,
                 instrument: bool = False):
        opts = options or ReliefRenderOptions()
        self.ctx, self.relief, self.options = ctx, relief, opts
        self.extra_attachments = 1 if instrument else 0
        w, h = relief.depth_resolution
        self.method = drawn_method(relief, opts)
        if self.method == "robust" and relief.safety is None:
            raise UsageError(f"this {w}x{h} relief texture has no safety radii, which robust "
                             "jumps by here (bakes leave them out where robust's default "
                             "draws the exact walk): bake it with --safety, or render with "
                             "--method maxmip (exact, needs no radii)")
        self.prog = program(ctx, PROGRAM, {
            f"METHOD_{self.method.upper()}": True,
            "SAFETY_OCTANTS": self.method == "robust" and relief.safety.ndim == 3,
            "WRITE_DEPTH": opts.depth_mode == "exact",
            "SHADOWS": opts.shadows, "COUNT_ITERATIONS": instrument})
        self.textures = {}
        self.vao = self.vbo = self.ibo = None
        try:
            self.textures["u_height"] = texture2d(ctx, relief.height, what="height",
                                                  filter="nearest")
            self.textures["u_color"] = texture2d(ctx, relief.color, what="color", srgb=True,
                                                 mipmaps=True)
            self.textures["u_normal"] = texture2d(ctx, relief.normal, what="normal")
            if self.method == "robust" and relief.safety.ndim == 3:
                self.textures["u_safety_octants"] = texture_array(
                    ctx, relief.safety.astype(np.float32), what="safety octants",
                    filter="nearest")
            elif self.method == "robust":
                packed = np.stack([relief.height, relief.safety.astype(np.float32)], axis=-1)
                self.textures["u_height_safety"] = texture2d(ctx, packed, what="height and safety",
                                                             filter="nearest")
            if self.method == "cone":
                from .cone import relaxed_cone_ratios  # numba: slow to import

                self.textures["u_cone"] = texture2d(ctx, relaxed_cone_ratios(relief.height),
                                                    what="cone ratios", filter="nearest")
            if self.method == "maxmip":
                self.textures["u_maxmip"], self.top_level = max_pyramid_texture(
                    ctx, relief.height, self.textures["u_height"])
            self.proxy = relief_proxy(relief)
            self.vbo = ctx.buffer(self.proxy.positions.tobytes())
            self.ibo = ctx.buffer(self.proxy.triangles.tobytes())
            self.vao = ctx.vertex_array(self.prog, [(self.vbo, "3f", "in_position")], self.ibo,
                                        index_element_size=4)
        except BaseException:
            self.release()
            raise
        self.uniforms = {
            "u_hf_size": (w, h), "u_linear_steps": opts.linear_steps,
            "u_binary_steps": opts.binary_steps,
            "u_max_iterations": opts.max_iterations or 4 * (w + h) + 64,
            "u_zero_exact": opts.zero_radius == "exact",
            "u_exact_below": float(opts.exact_below),
            "u_quadratic_cells": opts.cell_test == "quadratic",
            "u_top_level": getattr(self, "top_level", 0),
            "u_cone_steps": opts.cone_steps,
            "u_leaf_level": min(opts.maxmip_leaf, getattr(self, "top_level", 0)),
        }
        check_gl_error(ctx, "uploading a relief texture")

    def draw(self, camera, light) -> None:
        set_uniforms(self.prog, self.uniforms | box_uniforms(camera, self.relief.box_to_world)
                     | camera_uniforms(camera) | model_offset(camera, self.proxy.origin)
                     | light.uniforms())
        for unit, (name, tex) in enumerate(self.textures.items()):
            tex.use(unit)
            set_uniforms(self.prog, {name: unit})
        with proxy_raster_state(self.ctx):
            self.ctx.cull_face = cull_face(self.proxy, camera)
            self.vao.render()

    def finish(self, frame) -> None:
        """Depth AOV from the hit positions (in conservative mode the Z-buffer holds the box)."""
        frame.depth = window_depth(frame.position, frame.view, frame.proj, frame.depth)

    def release(self) -> None:
        for obj in (self.vao, self.vbo, self.ibo, *self.textures.values()):
            if obj is not None:
                obj.release()
        self.vao = self.vbo = self.ibo = None
        self.textures = {}


class ReliefObjectDrawable:
    """Every part of a ReliefObject (six frusta of a cube) with the same options.

    The parts always write their hit depth: a part whose proxy reaches the near plane is
    drawn by its back faces, and box depths of front and back faces would not order parts.
    """

    def __init__(self, ctx, obj: ReliefObject, options: ReliefRenderOptions | None = None,
                 instrument: bool = False):
        from dataclasses import replace

        opts = replace(options or ReliefRenderOptions(), depth_mode="exact")
        self.parts = []
        try:
            for part in obj.parts:
                self.parts.append(ReliefDrawable(ctx, part, opts, instrument))
        except BaseException:
            self.release()
            raise
        self.extra_attachments = self.parts[0].extra_attachments

    def draw(self, camera, light) -> None:
        for part in self.parts:
            part.draw(camera, light)

    def finish(self, frame) -> None:
        self.parts[0].finish(frame)

    def release(self) -> None:
        for part in self.parts:
            part.release()
