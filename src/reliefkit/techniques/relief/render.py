"""Relief textures: draw the box (or frustum) and intersect each pixel's ray in the shader.

A relief texture is one draw plan (`render.plan`): its proxy, its textures (the max pyramid
and the cone map computed here, on the CPU) and its uniforms; `proxy_view` gives per camera
the faces to cull and the box matrices relative to the camera. A ReliefObject is one plan
per part.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ...compact.encodings import encoding_of
from ...core.params import param
from ...errors import UsageError
from ...gl.uniforms import box_uniforms
from ...render.frame import window_depth
from ...render.instancing import instance_safe
from ...render.plan import (
    Attribute,
    DrawPlan,
    Geometry,
    Program,
    Texture,
    ViewHook,
    ViewUpdate,
)
from ...render.proxy import (
    PROXY_RASTER,
    Proxy,
    aabb_planes,
    box_planes,
    convex_proxy,
    cull_face,
)
from .maxmip import max_pyramid
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


def relief_plan(relief: ReliefTexture, options: ReliefRenderOptions,
                instrument: bool = False, name: str = "relief texture") -> DrawPlan:
    """The draw plan of one relief texture with ``options``: its proxy, the textures of the
    method that draws it (`drawn_method`) and its uniforms. Refuses robust jumps without
    safety radii."""
    w, h = relief.depth_resolution
    method = drawn_method(relief, options)
    if method == "robust" and relief.safety is None:
        raise UsageError(f"this {w}x{h} relief texture has no safety radii, which robust "
                         "jumps by here (bakes leave them out where robust's default "
                         "draws the exact walk): bake it with --safety, or render with "
                         "--method maxmip (exact, needs no radii)")
    octants = method == "robust" and relief.safety.ndim == 3
    textures = {"u_height": Texture(relief.height, filter="nearest", what="height",
                                    encoded=encoding_of(relief.height)),
                "u_color": Texture(relief.color, srgb=True, mipmaps=True, what="color",
                                   encoded=encoding_of(relief.color)),
                "u_normal": Texture(relief.normal, what="normal",
                                    encoded=encoding_of(relief.normal))}
    if octants:
        textures["u_safety_octants"] = Texture(relief.safety.astype(np.float32),
                                               target="2d_array", filter="nearest",
                                               what="safety octants")
    elif method == "robust":
        packed = np.stack([relief.height, relief.safety.astype(np.float32)], axis=-1)
        textures["u_height_safety"] = Texture(packed, filter="nearest",
                                              what="height and safety")
    if method == "cone":
        from .cone import relaxed_cone_ratios  # numba: slow to import

        textures["u_cone"] = Texture(relaxed_cone_ratios(relief.height), filter="nearest",
                                     what="cone ratios")
    top_level = 0
    if method == "maxmip":
        levels = tuple(max_pyramid(relief.height))
        textures["u_maxmip"] = Texture(levels[0], filter="nearest", levels=levels,
                                       what="max pyramid")
        top_level = len(levels) - 1
    proxy = relief_proxy(relief)
    return DrawPlan(
        name=name,
        program=Program(PROGRAM, {
            f"METHOD_{method.upper()}": True, "SAFETY_OCTANTS": octants,
            "WRITE_DEPTH": options.depth_mode == "exact", "SHADOWS": options.shadows,
            "COUNT_ITERATIONS": instrument}),
        geometry=Geometry({"in_position": Attribute(proxy.positions)},
                          indices=proxy.triangles.ravel()),
        textures=textures,
        uniforms={
            "u_hf_size": (w, h), "u_linear_steps": options.linear_steps,
            "u_binary_steps": options.binary_steps,
            "u_max_iterations": options.max_iterations or 4 * (w + h) + 64,
            "u_zero_exact": options.zero_radius == "exact",
            "u_exact_below": float(options.exact_below),
            "u_quadratic_cells": options.cell_test == "quadratic",
            "u_top_level": top_level, "u_cone_steps": options.cone_steps,
            "u_leaf_level": min(options.maxmip_leaf, top_level)},
        raster=PROXY_RASTER,
        origin=tuple(float(x) for x in proxy.origin),
        per_view=ViewHook(f"{__name__}:proxy_view",
                          {"box_to_world": np.asarray(relief.box_to_world, np.float64),
                           "planes": proxy.planes}))


@instance_safe
def proxy_view(plan: DrawPlan, camera, light, *, box_to_world: np.ndarray,
               planes: np.ndarray) -> ViewUpdate:
    """A proxy's view hook: the faces to cull from ``camera`` (`render.proxy.cull_face`)
    and the box matrices relative to it (`gl.uniforms.box_uniforms`)."""
    geometry = plan.geometry
    proxy = Proxy(geometry.attributes["in_position"].array, geometry.indices.reshape(-1, 3),
                  planes, np.asarray(plan.origin, np.float64))
    return ViewUpdate(uniforms=box_uniforms(camera, box_to_world),
                      cull=cull_face(proxy, camera))


def finish_depth(frame) -> None:
    """Depth AOV from the hit positions (in conservative mode the Z-buffer holds the box)."""
    frame.depth = window_depth(frame.position, frame.view, frame.proj, frame.depth)


class ReliefDrawable:
    """One ReliefTexture drawn with one intersection method, as one draw plan.

    The exact walk takes one bilinear cell per step (its four corners, the ray's exact
    quadratic in it, the exact root). ``cell_test="linear"`` is the paper's walk (a cell is
    hit only when its far end is below, §3.3); ``"quadratic"`` (default) also finds the
    saddle grazes inside a cell (Fig. 3).
    """

    def __init__(self, relief: ReliefTexture, options: ReliefRenderOptions | None = None,
                 instrument: bool = False):
        self.extra_attachments = 1 if instrument else 0
        self.plans = [relief_plan(relief, options or ReliefRenderOptions(), instrument)]

    def finish(self, frame, stats: dict) -> None:
        finish_depth(frame)


class ReliefObjectDrawable:
    """Every part of a ReliefObject (six frusta of a cube) with the same options, one plan
    per part.

    The parts always write their hit depth: a part whose proxy reaches the near plane is
    drawn by its back faces, and box depths of front and back faces would not order parts.
    """

    def __init__(self, obj: ReliefObject, options: ReliefRenderOptions | None = None,
                 instrument: bool = False):
        opts = replace(options or ReliefRenderOptions(), depth_mode="exact")
        self.extra_attachments = 1 if instrument else 0
        self.plans = [relief_plan(part, opts, instrument, f"relief part {k}")
                      for k, part in enumerate(obj.parts)]

    def finish(self, frame, stats: dict) -> None:
        finish_depth(frame)
