"""Drawing a `TexturedShell` (semi-transparent 3D texture paper, §4-§5).

Every frame: the tetrahedra are sorted front to back (SXMPVO, order.py, its A-buffer at the
frame's resolution so that the order is exact on every pixel's ray; or the centroid
baseline), written to an instance buffer, and drawn in that order in one instanced call of 12
vertices per tetrahedron (shaders/shell.glsl); the transparent pass composites each
fragment "under" what is in front of it. Opaque textures are drawn in the opaque pass,
depth-tested, without sorting.

The Frame's AOVs of a semi-transparent shell belong to the point where the accumulated
opacity first reaches 0.5 (DESIGN.md). A fragment cannot read what lies in front of it inside
one draw, so `half_opacity_search` finds that point exactly in extra passes: per pixel, a
base-16 search over the rank of the tetrahedron where it lies (optical depths are summed
order-independently with additive blending into 16 rank bins per pass, ceil(log16 T) passes),
then that tetrahedron's fragment marches its segment and writes the point.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ...bake.uv_atlas import atlas_uniforms
from ...core.params import param
from ...core.technique import DrawableSpec, ProgramVariant
from ...gl.context import check_gl_error
from ...gl.objects import GLObjects
from ...gl.shaders import program
from ...gl.targets import use_transparent_blending
from ...gl.textures import read_depth, read_rgba, texture2d, texture3d, texture_array
from ...gl.uniforms import camera_uniforms, model_offset, set_uniforms
from ...render.shadows import light_camera
from .filtering import mip_pyramid, naive_pyramid
from .representation import TET_TEXELS, TETS_PER_ROW, TexturedShell
from .sorts import METHODS
from .textures import density_floor, density_normals, marched_volume

PROGRAM = "shellvolume:shell.glsl"
TET_ROW_TEXELS = TET_TEXELS * TETS_PER_ROW  # 2048, shaders/include/tets.glsl
MAX_LEVELS = 4                          # shaders/include/volume.glsl
SEARCH_BINS = 16
SHADOW_SIZE = 1024
SHADOW_DEPTH_BIAS = 2.0 ** -16  # window depth: the shadow map's rounding, not its texels
_COLOR_UNITS, _NORMAL_UNITS = range(0, 4), range(4, 8)
_TETS_UNIT, _SHADOW_UNIT, _DEPTH_UNIT, _SEARCH_UNIT, _SURFACE_UNIT = 8, 9, 10, 11, 13
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


class TexturedShellDrawable(GLObjects):
    """GPU textures of one TexturedShell at one animation time, sorted and drawn per frame."""

    def __init__(self, ctx, rep: TexturedShell, options: ShellRenderOptions | None = None,
                 instrument: bool = False):
        self.ctx, self.rep = ctx, rep
        self.options = options = options or ShellRenderOptions()
        self.shell = rep.shell_at(options.time)
        self.transparent = options.composite == "sorted" or (
            options.composite == "auto" and not rep.opaque)
        lo, hi = rep.bounds
        self.origin = 0.5 * (lo + hi)  # float64: the tetrahedra are stored relative to it
        self.extra_attachments = 0
        self.stats: dict = {}
        self._upload_owned(self._upload)

    # -- upload ---------------------------------------------------------------------------
    def _upload(self) -> None:
        ctx, rep, shell = self.ctx, self.rep, self.shell
        mean_thickness = float(np.mean(rep.thickness))
        self.levels = texture_levels(rep.texture, mean_thickness)
        self.level_textures = []
        for k, (rgba, normal) in enumerate(self.levels):
            pair = []
            for array, what in ((rgba, "colour"), (normal, "normal")):
                tex = self.keep(texture3d(ctx, array, what=f"shell {what} level {k}",
                                          repeat=True))
                tex.repeat_z = False  # w is clamped: the shell ends at its base and top
                pair.append(tex)
            self.level_textures.append(pair)
        if rep.surface is not None:
            self.surface = self.keep(texture_array(ctx, rep.surface.rgba8, srgb=True,
                                                   what="shell surface materials"))
        texels = tet_texels(shell, self.origin, rep.texture.tile, rep.surface_layers())
        self.tets = self.keep(texture2d(ctx, texels, what="shell tetrahedra",
                                        filter="nearest"))
        count = len(shell.tets)
        self.instances = self.keep(ctx.buffer(np.arange(count, dtype=np.int32).tobytes()))
        lit = not self.options.unlit
        exit_vertex = self.options.exit == "vertex"
        self.peel = self.transparent and self.options.sort == "peel"
        if self.transparent:
            main = {"LIT": lit, "SHADOWS": lit and self.options.shadows,
                    "EXIT_VERTEX": exit_vertex, "PEEL": self.peel}
        else:
            main = {"OPAQUE": True, "LIT": lit, "SHADOWS": lit and self.options.shadows,
                    "EXIT_VERTEX": exit_vertex}
        self.programs = {"main": program(ctx, PROGRAM, main)}
        if self.peel:
            self.layer_program = program(ctx, LAYER_PROGRAM)
            self.layer_vao = self.keep(ctx.vertex_array(self.layer_program, []))
        if self.transparent and self.options.half_opacity and not self.peel:
            self.programs["bins"] = program(ctx, PROGRAM, {"AOV_BINS": True,
                                                            "EXIT_VERTEX": exit_vertex})
            self.programs["final"] = program(ctx, PROGRAM, {"AOV_FINAL": True,
                                                             "EXIT_VERTEX": exit_vertex})
        if self.options.shadows and lit:
            self.programs["shadow"] = program(ctx, PROGRAM, {"SHADOW_MAP": True})
        self.vaos = {name: self.keep(ctx.vertex_array(prog, [(self.instances, "1i/i",
                                                              "in_tet")]))
                     for name, prog in self.programs.items()}
        check_gl_error(ctx, f"uploading a shell of {count} tetrahedra")

    # -- drawing --------------------------------------------------------------------------
    def _uniforms(self, camera, light) -> dict:
        sizes = [(a.shape[2], a.shape[1], a.shape[0]) for a, _ in self.levels]
        sizes += [sizes[-1]] * (MAX_LEVELS - len(sizes))
        units = {f"u_color{k}": _COLOR_UNITS[min(k, len(self.levels) - 1)]
                 for k in range(MAX_LEVELS)}
        units |= {f"u_normal{k}": _NORMAL_UNITS[min(k, len(self.levels) - 1)]
                  for k in range(MAX_LEVELS)}
        animated = self.options.time is not None
        return (camera_uniforms(camera) | model_offset(camera, self.origin) | light.uniforms()
                | units | {"u_tets": _TETS_UNIT, "u_levels": len(self.levels),
                           "u_level_size": sizes, "u_mip": self.options.mip,
                           "u_density_floor": density_floor(float(np.mean(self.rep.thickness))),
                           "u_samples": self.options.samples,
                           "u_time": float(self.options.time or 0.0),
                           "u_sway": 0.04 if animated else 0.0,
                           "u_opaque_depth": _DEPTH_UNIT, "u_search": _SEARCH_UNIT,
                           "u_shadow_map": _SHADOW_UNIT,
                           "u_tile": tuple(float(t) for t in self.rep.texture.tile)}
                | atlas_uniforms(self.rep.surface, _SURFACE_UNIT))

    def _bind(self) -> None:
        for k, (colour, normal) in enumerate(self.level_textures):
            colour.use(_COLOR_UNITS[k])
            normal.use(_NORMAL_UNITS[k])
        self.tets.use(_TETS_UNIT)
        if self.rep.surface is not None:
            self.surface.use(_SURFACE_UNIT)

    def _draw(self, name: str, uniforms: dict) -> None:
        set_uniforms(self.programs[name], uniforms)
        self.vaos[name].render(vertices=12, instances=len(self.shell.tets))

    def draw(self, camera, light) -> None:
        import moderngl

        ctx = self.ctx
        start = time.perf_counter()
        if self.transparent and not self.peel:
            from .order import visibility_order  # numba: slow to import

            # the A-buffer samples the frame's own pixel rays: the order is exact on them
            order = visibility_order(self.shell, camera, method=self.options.sort,
                                     resolution=max(camera.size))
            self.instances.write(order.order.astype(np.int32).tobytes())
            self.stats.update(sort=order.method, sort_seconds=order.seconds,
                              cycles=order.cycles)
        uniforms = self._uniforms(camera, light)
        made = []
        outer = ctx.fbo
        enabled = moderngl.DEPTH_TEST | (moderngl.BLEND if self.transparent else 0)
        try:
            self._bind()
            if "shadow" in self.programs:
                uniforms |= self._shadow_map(light, made)
                outer.use()
            if self.transparent:
                uniforms |= self._opaque_depth(outer, made)
            search = "bins" in self.programs
            front = _read_alpha(outer) if search else None
            ctx.cull_face, ctx.front_face = "back", "ccw"
            if self.peel:
                self._draw_peeled(outer, uniforms, made)
            elif self.transparent:
                use_transparent_blending(ctx, moderngl.CULL_FACE)
                self._draw("main", uniforms)
            else:
                ctx.enable_only(enabled | moderngl.CULL_FACE)
                self._draw("main", uniforms)
            if search:
                self._half_opacity_point(outer, front, uniforms, made)
            check_gl_error(ctx, f"drawing a shell of {len(self.shell.tets)} tetrahedra")
        finally:
            for obj in reversed(made):
                obj.release()
            outer.use()
            ctx.enable_only(enabled)
        self.stats["draw_seconds"] = time.perf_counter() - start

    def _shadow_map(self, light, made) -> dict:
        """Render the shadow map (depth of the first dense sample seen from the light)."""
        import moderngl

        ctx = self.ctx
        cam = light_camera(self.rep.bounds, light)
        depth = ctx.depth_texture(cam.size)
        made.append(depth)
        fbo = ctx.framebuffer(depth_attachment=depth)
        made.append(fbo)
        fbo.use()
        fbo.viewport = (0, 0, *cam.size)
        fbo.clear(depth=1.0)
        ctx.enable_only(moderngl.DEPTH_TEST | moderngl.CULL_FACE)
        ctx.cull_face, ctx.front_face = "back", "ccw"
        shadow_uniforms = self._uniforms(cam, light) | {
            "u_clip_opaque": False,
            "u_shadow_length": float(np.mean(self.rep.thickness))}
        self._draw("shadow", shadow_uniforms)
        depth.compare_func = ""
        depth.filter = (moderngl.NEAREST, moderngl.NEAREST)
        depth.use(_SHADOW_UNIT)
        from ...core.transforms import translation

        light_matrix = np.asarray(cam.proj) @ np.asarray(cam.view) @ translation(self.origin)
        return {"u_light_matrix": light_matrix, "u_shadow_bias": SHADOW_DEPTH_BIAS,
                "u_shadow_texel": 2.0 * cam.ortho_height / cam.size[0]}

    def _opaque_depth(self, outer, made) -> dict:
        """A copy of the opaque pass's depth to sample (the attached one cannot be)."""
        width, height = outer.size
        depth = read_depth(outer, top_row_first=False)  # GL rows: texelFetch(gl_FragCoord)
        tex = self.ctx.texture((width, height), 1, depth.tobytes(), dtype="f4")
        made.append(tex)
        import moderngl

        tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
        tex.use(_DEPTH_UNIT)
        return {"u_clip_opaque": bool((depth < 1.0).any())}

    def _half_opacity_point(self, outer, front, uniforms, made) -> None:
        """Find, per pixel, the rank of the tetrahedron where the opacity accumulated over
        the drawables in front and this shell first reaches 0.5, and draw that point's
        position and normal (AOV_FINAL) into the transparent pass."""
        import moderngl

        ctx = self.ctx
        width, height = outer.size
        count = len(self.shell.tets)
        need = _needed_optical_depth(front)
        bins = [ctx.texture((width, height), 4, dtype="f4") for _ in range(4)]
        made.extend(bins)
        fbo = ctx.framebuffer(color_attachments=bins, depth_attachment=outer.depth_attachment)
        made.append(fbo)
        search = ctx.texture((width, height), 2, dtype="f4")
        made.append(search)
        search.filter = (moderngl.NEAREST, moderngl.NEAREST)
        lo = np.zeros((height, width))
        hi = np.where(np.isfinite(need), float(count), 0.0)
        passes = 0
        while (hi - lo > 1).any():
            search.write(np.stack([lo, hi], axis=-1).astype(np.float32).tobytes())
            search.use(_SEARCH_UNIT)
            fbo.use()
            fbo.depth_mask = False
            fbo.viewport = (0, 0, width, height)
            for tex in bins:
                tex.write(np.zeros((height, width, 4), np.float32).tobytes())
            ctx.enable_only(moderngl.DEPTH_TEST | moderngl.BLEND | moderngl.CULL_FACE)
            ctx.blend_func = moderngl.ONE, moderngl.ONE
            self._draw("bins", uniforms)
            sums = np.concatenate([read_rgba(fbo, k, top_row_first=False)
                                   for k in range(4)], axis=-1)
            lo, hi, need = _narrow(lo, hi, need, sums.astype(np.float64))
            passes += 1
        self.stats["half_opacity_passes"] = passes + 1
        found = (hi - lo == 1) & np.isfinite(need)
        rank = np.where(found, lo, -1.0)
        search.write(np.stack([rank, np.where(found, need, 0.0)], axis=-1)
                     .astype(np.float32).tobytes())
        search.use(_SEARCH_UNIT)
        outer.use()
        use_transparent_blending(ctx, moderngl.CULL_FACE)
        self._draw("final", uniforms)

    def _draw_peeled(self, outer, uniforms, made) -> None:
        """Depth peeling: pass k draws every tetrahedron, keeps the nearest fragment behind
        layer k - 1 (depth test), and adds it under the layers in front; until a pass draws
        nothing (an occlusion query) or `MAX_PEELS` passes."""
        import moderngl

        ctx = self.ctx
        width, height = outer.size
        color = ctx.texture((width, height), 4, dtype="f4")
        made.append(color)
        # the depth test picks the nearest fragment; its exact z goes to a float attachment
        # (a 24-bit depth texture would round it, and the layer would be peeled again)
        peeled = [ctx.texture((width, height), 4, dtype="f4") for _ in range(2)]
        depth = ctx.depth_texture((width, height))
        made.extend([*peeled, depth])
        for tex in peeled:
            tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
        fbos = [ctx.framebuffer(color_attachments=[color, z], depth_attachment=depth)
                for z in peeled]
        made.extend(fbos)
        # a pixel no fragment reaches keeps "beyond everything", so nothing comes back
        beyond = np.full((height, width, 4), 2.0, np.float32).tobytes()
        peeled[1].write(np.full((height, width, 4), -1.0, np.float32).tobytes())  # none yet
        self.layer_program["u_layer"].value = _SEARCH_UNIT
        layers = 0
        for k in range(MAX_PEELS):
            fbo, before = fbos[k % 2], peeled[(k + 1) % 2]
            fbo.use()
            fbo.viewport = (0, 0, width, height)
            fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
            peeled[k % 2].write(beyond)
            ctx.enable_only(moderngl.DEPTH_TEST | moderngl.CULL_FACE)
            before.use(_SEARCH_UNIT + 1)
            query = ctx.query(samples=True)
            with query:
                self._draw("main", uniforms | {"u_peel_depth": _SEARCH_UNIT + 1})
            if query.samples == 0:
                break
            layers += 1
            outer.use()
            use_transparent_blending(ctx)
            ctx.disable(moderngl.DEPTH_TEST)
            color.use(_SEARCH_UNIT)
            self.layer_vao.render(moderngl.TRIANGLES, vertices=3)
        self.stats["peeled_layers"] = layers

    def finish(self, frame) -> None:
        frame.stats.update({"tetrahedra": len(self.shell.tets),
                            "samples": self.options.samples, "unlit": self.options.unlit,
                            "mip": self.options.mip, **self.stats})
        if self.stats.get("cycles"):
            frame.warnings.append(cycles_warning(self.stats["cycles"]))


def cycles_warning(cycles: int) -> str:
    """What a sort that broke ``cycles`` cycles tells the user: no order of the tetrahedra
    exists where they overlap (parts of the mesh pass through each other, or the shell is
    too thick there), so some pixels are composited out of order; peeling is exact."""
    return (f"the visibility order broke {cycles:,} cycles (tetrahedra that overlap, where "
            "parts of the mesh pass through each other or the shell is too thick): some "
            "pixels are composited out of order; --sort peel is exact (one pass per depth "
            "layer, slower)")


def _needed_optical_depth(front: np.ndarray) -> np.ndarray:
    """Per pixel, the optical depth a shell behind opacity ``front`` must accumulate to bring
    the total to 0.5: -ln(1 - a) with front + (1 - front) a = 0.5 (inf where front >= 0.5)."""
    safe = np.minimum(front, 0.5)
    target = (0.5 - safe) / (1.0 - safe)
    return np.where(front < 0.5, -np.log1p(-np.minimum(target, 1.0 - 1e-12)), np.inf)


def _narrow(lo, hi, need, sums):
    """One step of the base-16 rank search: ``sums[..., k]`` is the optical depth of the
    ranks in [lo, t_k), t_k = lo + ceil((hi - lo)(k + 1) / 16); keep the first bin whose
    sum reaches ``need`` (the optical depth still needed), or give up where none does."""
    k = np.arange(1, SEARCH_BINS + 1)
    thresholds = lo[..., None] + np.ceil((hi - lo)[..., None] * k / SEARCH_BINS)
    active = hi - lo > 1
    reached = sums >= need[..., None]
    first = np.argmax(reached, axis=-1)
    some = reached.any(axis=-1)
    below = np.take_along_axis(sums, np.maximum(first - 1, 0)[..., None], -1)[..., 0]
    prev = np.take_along_axis(thresholds, np.maximum(first - 1, 0)[..., None], -1)[..., 0]
    new_lo = np.where(first > 0, prev, lo)
    new_hi = np.take_along_axis(thresholds, first[..., None], -1)[..., 0]
    new_need = need - np.where(first > 0, below, 0.0)
    lo = np.where(active & some, new_lo, np.where(active, 0.0, lo))
    hi = np.where(active & some, new_hi, np.where(active, 0.0, hi))
    need = np.where(active & ~some, np.inf, np.where(active, new_need, need))
    return lo, hi, need


def _read_alpha(fbo) -> np.ndarray:
    """(H, W) float64 alpha of colour attachment 0 (GL row order, bottom row first)."""
    return read_rgba(fbo, 0, top_row_first=False)[..., 3].astype(np.float64)


def drawable_spec() -> DrawableSpec:
    """How the technique draws its shells (the package's `Technique` declares it)."""
    return DrawableSpec(TexturedShell, TexturedShellDrawable, ShellRenderOptions)
