"""Drawing a `TexturedShell` (semi-transparent 3D texture paper, §4-§5) as one draw plan.

Every frame: the tetrahedra are sorted front to back (SXMPVO, order.py, its A-buffer at the
frame's resolution so that the order is exact on every pixel's ray; or the centroid
baseline) by the plan's view hook, which gives the instance order, and drawn in that order
in one instanced call of 12 vertices per tetrahedron (shaders/shell.glsl); the transparent
pass composites each fragment "under" what is in front of it. Opaque textures are drawn in
the opaque pass, depth-tested, without sorting.

What is not one draw is a multi-pass kind of the executor (`render.multipass`): the copy of
the opaque depth the segments stop at ("opaque-depth"); the Frame's AOVs of a
semi-transparent shell, which belong to the point where the accumulated opacity first
reaches 0.5, found in extra passes per pixel by a base-16 search over the rank of the
tetrahedron where it lies ("half-opacity-search"); depth peeling ("depth-peel"); and the
shadow map from the light ("shadow-map", nearest depth, compared in the shader).
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from ...bake.uv_atlas import atlas_uniforms
from ...compact.encodings import encoding_of
from ...core.params import param
from ...core.technique import DrawableSpec, ProgramVariant
from ...render.instancing import per_object
from ...render.plan import (
    Attribute,
    DrawPlan,
    Geometry,
    MultiPass,
    Program,
    Raster,
    Texture,
    ViewHook,
    ViewUpdate,
)
from .filtering import mip_pyramid, naive_pyramid
from .representation import TET_TEXELS, TETS_PER_ROW, TexturedShell
from .sorts import METHODS
from .textures import density_floor, density_normals, marched_volume

PROGRAM = "shellvolume:shell.glsl"
TET_ROW_TEXELS = TET_TEXELS * TETS_PER_ROW  # 2048, shaders/include/tets.glsl
MAX_LEVELS = 4                          # shaders/include/volume.glsl
SHADOW_SIZE = 1024
SHADOW_DEPTH_BIAS = 2.0 ** -16  # window depth: the shadow map's rounding, not its texels
# units of the samplers a draw may leave unbound (the opaque depth in the opaque pass, the
# surface materials of a shell without them): above the ones the executor binds, one per
# sampler type
_SPARE_ARRAY_UNIT, _SPARE_2D_UNIT = 13, 14
EXITS = ("fragment", "vertex")
SORTS = (*METHODS, "peel")  # peel: depth peeling, the baseline the paper measured against
MAX_PEELS = 1024
COMPOSITES = ("auto", "sorted", "opaque")

LAYER_PROGRAM = "shellvolume:layer.glsl"
PROGRAMS = tuple(ProgramVariant(PROGRAM, d) for d in (
    {"LIT": True}, {"LIT": True, "SHADOWS": True}, {}, {"EXIT_VERTEX": True, "LIT": True},
    {"OPAQUE": True, "LIT": True}, {"OPAQUE": True}, {"AOV_BINS": True},
    {"AOV_FINAL": True}, {"SHADOW_MAP": True}, {"PEEL": True, "LIT": True})) + (
    ProgramVariant(LAYER_PROGRAM, {}),)


@dataclass(frozen=True)
class ShellRenderOptions:
    """The render options of shell volumes."""

    samples: int = param(16, "samples along each tetrahedron's segment (§5.1)", lo=1, hi=256)
    sort: str = param("sxmpvo", "visibility order: SXMPVO (exact), the centroid sort "
                      "(approximate), or depth peeling (exact, one pass per layer; its AOVs "
                      "come from opaque objects only)", choices=SORTS)
    shadows: bool = param(False, "self and volumetric shadows from a shadow map (§5.3)")
    unlit: bool = param(False, "composite the stored colours without lighting (what "
                        "measurements compare against)")
    time: float | None = param(None, "animation time: the base deforms and the texture "
                               "sways (period 1; none: at rest)", kind="float",
                               lo=-1e6, hi=1e6)
    exit: str = param("fragment", "where the ray leaves a tetrahedron: per fragment, or "
                      "the paper's per-vertex planes with the perspective correction",
                      choices=EXITS)
    mip: bool = param(True, "filter with the opacity-compositing mip pyramid (§5.2)")
    composite: str = param("auto", "sorted blending, opaque depth test, or auto (opaque "
                           "for solid textures)", choices=COMPOSITES)
    half_opacity: bool = param(True, "find the point where opacity reaches 0.5 for the "
                               "AOVs (extra passes; off: AOVs only from opaque objects)")


def tet_texels(shell, origin, tile, layers=None) -> np.ndarray:
    """(rows, TET_ROW_TEXELS, 4) float32: shaders/include/tets.glsl's block per tetrahedron,
    relative to ``origin`` (float64), the tiling folded into the texture map; ``layers``
    (T,): the surface material layer of each tetrahedron (0 when None)."""
    origin = np.asarray(origin, np.float64)
    count = len(shell.tets)
    block = np.zeros((count, TET_TEXELS, 4), np.float64)
    corners = shell.positions[shell.tets]
    block[:, 0:4, :3] = corners - origin
    block[:, 0:4, 3] = np.einsum("tfk,tfk->tf", shell.planes[..., :3], corners) + \
        shell.planes[..., 3]  # vertex f's value in the plane of face f: minus its height
    normals = shell.planes[..., :3]
    block[:, 4:8, :3] = normals
    block[:, 4:8, 3] = shell.planes[..., 3] + normals @ origin
    scale = np.array([tile[0], tile[1], 1.0])
    rows = shell.object_to_texture[:, :3, :] * scale[None, :, None]
    block[:, 8:11, :3] = rows[..., :3]
    block[:, 8:11, 3] = rows[..., 3] + rows[..., :3] @ origin
    block[:, 11:15, :3] = shell.normals[shell.tets]
    block[:, 15, 0] = ray_reach(shell)
    if layers is not None:
        block[:, 15, 1] = layers
    padded = np.zeros((-(-count // TETS_PER_ROW) * TETS_PER_ROW, TET_TEXELS, 4), np.float32)
    padded[:count] = block
    return padded.reshape(-1, TET_ROW_TEXELS, 4)


def ray_reach(shell) -> np.ndarray:
    """(T,) the longest segment a ray can have in each tetrahedron or in one it may come
    from (a face neighbour): the longest edge among them. The shadow test steps back by it
    over the sample count (shaders/shell.glsl, light_visibility)."""
    corners = shell.positions[shell.tets]
    pairs = [(i, j) for i in range(4) for j in range(i + 1, 4)]
    own = np.max([np.linalg.norm(corners[:, i] - corners[:, j], axis=-1)
                  for i, j in pairs], axis=0)
    beside = np.where(shell.neighbors >= 0, own[np.maximum(shell.neighbors, 0)], 0.0)
    return np.maximum(own, beside.max(axis=1))


def level_count(shape) -> int:
    """Levels of the pyramid: halve while every size is even or 1, up to `MAX_LEVELS`."""
    levels, shape = 1, tuple(shape)
    while levels < MAX_LEVELS and max(shape) > 1 and all(n == 1 or n % 2 == 0 for n in shape):
        shape = tuple(max(n // 2, 1) for n in shape)
        levels += 1
    return levels


def texture_levels(texture, thickness: float) -> list[tuple[np.ndarray, np.ndarray]]:
    """Per level: (colour + optical density (D,H,W,4), normal + glow (D,H,W,4)) float32,
    §5.2's filtering; the GPU interpolates densities (`textures.marched_volume`)."""
    levels = level_count(texture.shape)
    colours = mip_pyramid(texture, levels, thickness / texture.length)
    glow = texture.glow if texture.glow is not None else np.zeros(texture.shape, np.float32)
    glows = naive_pyramid(np.repeat(glow[..., None], 4, axis=-1), levels)
    out = []
    for k, (rgba, g) in enumerate(zip(colours, glows, strict=True)):
        normal = texture.normal if k == 0 else density_normals(rgba[..., 3])
        marched = marched_volume(rgba, texture.length, thickness)
        out.append((marched, np.concatenate([normal, g[..., :1]], axis=-1).astype(np.float32)))
    return out


class TexturedShellDrawable:
    """One TexturedShell at one animation time as one draw plan: 12 vertices per
    tetrahedron, instanced; sorted per view by its hook (transparent), and drawn by a
    multi-pass kind where it needs more than one draw. Timed: its stats report the draw's
    wall time beside the sort's (the bench reads the sort's share of it)."""

    timed = True

    def __init__(self, rep: TexturedShell, options: ShellRenderOptions | None = None,
                 instrument: bool = False):
        self.rep = rep
        self.options = options or ShellRenderOptions()
        self.shell = rep.shell_at(self.options.time)
        self.extra_attachments = 0
        self.plans = [shell_plan(rep, self.shell, self.options)]

    def finish(self, frame, stats: dict) -> None:
        frame.stats.update({"tetrahedra": len(self.shell.tets),
                            "samples": self.options.samples, "unlit": self.options.unlit,
                            "mip": self.options.mip, **stats})
        if stats.get("cycles"):
            frame.warnings.append(cycles_warning(stats["cycles"]))


def shell_plan(rep: TexturedShell, shell, options: ShellRenderOptions) -> DrawPlan:
    """The draw plan of ``shell`` (``rep``'s at the options' time): its textures, the
    tetrahedra's block, the uniforms; transparent: the visibility order as a view hook and
    the multi-pass kind that draws it ("opaque-depth", "half-opacity-search" or
    "depth-peel"); opaque: depth-tested, unsorted, shadowed by the "shadow-map" kind."""
    transparent = options.composite == "sorted" or (
        options.composite == "auto" and not rep.opaque)
    lit = not options.unlit
    shadows = lit and options.shadows
    exit_vertex = options.exit == "vertex"
    peel = transparent and options.sort == "peel"
    lo, hi = rep.bounds
    origin = 0.5 * (lo + hi)  # float64: the tetrahedra are stored relative to it
    count = len(shell.tets)
    if transparent:
        main = {"LIT": lit, "SHADOWS": shadows, "EXIT_VERTEX": exit_vertex, "PEEL": peel}
    else:
        main = {"OPAQUE": True, "LIT": lit, "SHADOWS": shadows, "EXIT_VERTEX": exit_vertex}
    multipass = _multipass(options, transparent, peel, shadows, rep.bounds)
    hook = None
    if transparent and not peel:
        # the A-buffer samples the frame's own pixel rays: the order is exact on them
        from .order import order_cells  # numba: slow to import

        cells = order_cells(shell)
        hook = ViewHook(f"{__name__}:visibility_hook", {
            "cells": {f.name: getattr(cells, f.name) for f in fields(cells)},
            "method": options.sort})
    textures, uniforms = shell_textures(rep, shell, origin)
    return DrawPlan(
        name=f"a shell of {count} tetrahedra",
        program=Program(PROGRAM, main),
        geometry=Geometry({"in_tet": Attribute(np.arange(count, dtype=np.int32),
                                               per_instance=True)},
                          vertices=12, instances=count),
        textures=textures,
        uniforms=uniforms | {
            "u_mip": options.mip, "u_samples": options.samples,
            "u_time": float(options.time or 0.0),
            "u_sway": 0.04 if options.time is not None else 0.0,
            "u_clip_opaque": False,  # the kinds that copy the opaque depth say otherwise
            "u_shadow_length": float(np.mean(rep.thickness))},
        raster=Raster(depth_write=not transparent, cull="back",
                      blend="under" if transparent else "none"),
        render_pass="transparent" if transparent else "opaque",
        origin=tuple(float(x) for x in origin),
        per_view=hook, multipass=multipass)


def _multipass(options, transparent: bool, peel: bool, shadows: bool,
               bounds) -> MultiPass | None:
    """The multi-pass kind that draws the shell, its extra programs and params: shadows
    from a map of the first dense sample seen from the light (back faces culled, the nearest
    depth compared in shell.glsl, a window-depth bias, no order needed); transparent: the
    opaque depth copied, then depth peeling or the half-opacity search, or a single draw."""
    exit_vertex = options.exit == "vertex"
    shadow_map = {"bounds": np.asarray(bounds, np.float64), "size": SHADOW_SIZE,
                  "cull": "back", "sampler": "depth", "bias": SHADOW_DEPTH_BIAS,
                  "caster_hooks": False}
    programs = {"caster": Program(PROGRAM, {"SHADOW_MAP": True})} if shadows else {}
    if not transparent:
        return MultiPass("shadow-map", programs, shadow_map) if shadows else None
    params = {"shadow_map": shadow_map} if shadows else {}
    if peel:
        return MultiPass("depth-peel", programs | {"layer": Program(LAYER_PROGRAM)},
                         params | {"max_layers": MAX_PEELS})
    if options.half_opacity:
        return MultiPass("half-opacity-search", programs | {
            "bins": Program(PROGRAM, {"AOV_BINS": True, "EXIT_VERTEX": exit_vertex}),
            "final": Program(PROGRAM, {"AOV_FINAL": True, "EXIT_VERTEX": exit_vertex})},
            params)
    return MultiPass("opaque-depth", programs, params)


def shell_textures(rep: TexturedShell, shell, origin) -> tuple[dict, dict]:
    """The textures of shaders/include/volume.glsl and tets.glsl (the 3D texture's levels,
    the tetrahedra's block, the surface's materials) and the uniforms that describe them."""
    mean_thickness = float(np.mean(rep.thickness))
    levels = texture_levels(rep.texture, mean_thickness)
    textures = {}
    for k in range(MAX_LEVELS):  # missing levels repeat the last
        level = min(k, len(levels) - 1)
        for index, (name, what) in enumerate((("color", "colour"), ("normal", "normal"))):
            if k == level:  # w is clamped: the shell ends at its base and top
                textures[f"u_{name}{k}"] = Texture(
                    levels[level][index], target="3d",
                    wrap=("repeat", "repeat", "clamp"), what=f"shell {what} level {k}")
            else:
                textures[f"u_{name}{k}"] = textures[f"u_{name}{level}"]
    texels = tet_texels(shell, origin, rep.texture.tile, rep.surface_layers())
    textures["u_tets"] = Texture(texels, filter="nearest", what="shell tetrahedra")
    if rep.surface is not None:
        textures["u_surface"] = Texture(rep.surface.rgba8, target="2d_array", srgb=True,
                                        what="shell surface materials",
                                        encoded=encoding_of(rep.surface.rgba8))
    sizes = [(a.shape[2], a.shape[1], a.shape[0]) for a, _ in levels]
    sizes += [sizes[-1]] * (MAX_LEVELS - len(sizes))
    uniforms = {"u_levels": len(levels), "u_level_size": sizes,
                "u_density_floor": density_floor(mean_thickness),
                "u_tile": tuple(float(t) for t in rep.texture.tile)}
    # samplers a draw may leave unbound (never sampled then) stay off the bound units
    uniforms |= atlas_uniforms(rep.surface, _SPARE_ARRAY_UNIT) | {
        "u_opaque_depth": _SPARE_2D_UNIT}
    return textures, uniforms


@per_object("it sorts the object's own tetrahedra front to back for each "
            "camera")
def visibility_hook(plan, camera, light, *, cells: dict, method: str) -> ViewUpdate:
    """The view hook of a sorted shell: its tetrahedra front to back from ``camera`` as the
    instance order, and the sort's statistics."""
    from .order import OrderCells, visibility_order  # numba: slow to import

    order = visibility_order(OrderCells(**cells), camera, method=method,
                             resolution=max(camera.size))
    return ViewUpdate(attributes={"in_tet": order.order.astype(np.int32)},
                      stats={"sort": order.method, "sort_seconds": order.seconds,
                             "cycles": order.cycles})


def cycles_warning(cycles: int) -> str:
    """What a sort that broke ``cycles`` cycles tells the user: no order of the tetrahedra
    exists where they overlap (parts of the mesh pass through each other, or the shell is
    too thick there), so some pixels are composited out of order; peeling is exact."""
    return (f"the visibility order broke {cycles:,} cycles (tetrahedra that overlap, where "
            "parts of the mesh pass through each other or the shell is too thick): some "
            "pixels are composited out of order; --sort peel is exact (one pass per depth "
            "layer, slower)")


def drawable_spec() -> DrawableSpec:
    """How the technique draws its shells (the package's `Technique` declares it)."""
    return DrawableSpec(TexturedShell, TexturedShellDrawable, ShellRenderOptions)
