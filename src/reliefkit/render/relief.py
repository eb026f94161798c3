"""Relief textures: draw the box (or frustum) and intersect each pixel's ray in the shader."""

from __future__ import annotations

import numpy as np

from ..errors import UsageError
from ..gl.context import check_gl_error
from ..gl.shaders import program
from ..gl.textures import texture2d
from ..represent.relief import ReliefObject, ReliefTexture
from .frame import window_depth
from .proxy import relief_proxy
from .registry import register_renderer
from .targets import camera_uniforms, set_uniforms

METHODS = ("binary", "exact", "robust")
DEPTH_MODES = ("conservative", "exact")
ZERO_RADIUS_MODES = ("exact", "clamp")
CELL_TESTS = ("quadratic", "linear")
OPTIONS = ("method", "depth_mode", "shadows", "count_iterations", "linear_steps",
           "binary_steps", "max_iterations", "zero_radius", "cell_test")

def validate_options(method: str, depth_mode: str, zero_radius: str, cell_test: str) -> None:
    for value, allowed, label in ((method, METHODS, "method"),
                                  (depth_mode, DEPTH_MODES, "depth mode"),
                                  (zero_radius, ZERO_RADIUS_MODES, "zero-radius mode"),
                                  (cell_test, CELL_TESTS, "cell test")):
        if value not in allowed:
            raise UsageError(f"unknown {label} {value!r} (choose from {', '.join(allowed)})")


class ReliefDrawable:
    """GPU textures and proxy of one ReliefTexture, drawn with one intersection method.

    ``cell_test="linear"`` is the paper's exact walk (heights linear between centreline
    crossings, §3.3); ``"quadratic"`` (default) also tests the exact quadratic inside each
    cell with one more fetch per step, so saddle grazes (Fig. 3) are found too.
    """

    def __init__(self, ctx, relief: ReliefTexture, *, method: str = "robust",
                 depth_mode: str = "conservative", shadows: bool = False,
                 count_iterations: bool = False, linear_steps: int = 16, binary_steps: int = 8,
                 max_iterations: int | None = None, zero_radius: str = "exact",
                 cell_test: str = "quadratic"):
        validate_options(method, depth_mode, zero_radius, cell_test)
        if method == "robust" and relief.safety is None:
            raise UsageError("this relief texture has no safety radii: bake it with them or "
                             "render with --method binary or exact")
        for name, value in (("linear_steps", linear_steps), ("binary_steps", binary_steps)):
            if not 1 <= int(value) <= 4096:
                raise UsageError(f"{name} must be between 1 and 4096, got {value}")
        self.ctx, self.relief, self.method = ctx, relief, method
        self.count_iterations = count_iterations
        self.extra_attachments = 1 if count_iterations else 0
        w, h = relief.depth_resolution
        self.prog = program(ctx, "relief.glsl", {
            f"METHOD_{method.upper()}": True, "WRITE_DEPTH": depth_mode == "exact",
            "SHADOWS": bool(shadows), "COUNT_ITERATIONS": bool(count_iterations)})
        self.textures = {
            "u_height": texture2d(ctx, relief.height, what="height", filter="nearest"),
            "u_color": texture2d(ctx, relief.color, what="color", srgb=True, mipmaps=True),
            "u_normal": texture2d(ctx, relief.normal, what="normal"),
        }
        if method == "robust":
            self.textures["u_safety"] = texture2d(ctx, relief.safety.astype(np.float32),
                                                  what="safety", filter="nearest")
        self.proxy = relief_proxy(relief.world_to_box, relief.params.get("clip_bounds"))
        self.vbo = ctx.buffer(self.proxy.positions.tobytes())
        self.ibo = ctx.buffer(self.proxy.triangles.tobytes())
        self.vao = ctx.vertex_array(self.prog, [(self.vbo, "3f", "in_position")], self.ibo,
                                    index_element_size=4)
        self.uniforms = {
            "u_box_to_world": relief.box_to_world, "u_world_to_box": relief.world_to_box,
            "u_hf_size": (w, h), "u_linear_steps": int(linear_steps),
            "u_binary_steps": int(binary_steps),
            "u_max_iterations": int(max_iterations or 4 * (w + h) + 64),
            "u_zero_exact": zero_radius == "exact",
            "u_quadratic_cells": cell_test == "quadratic",
        }
        check_gl_error(ctx, "uploading a relief texture")

    def reaches_near_plane(self, camera) -> bool:
        """Does the proxy extend in front of the near plane (camera inside or close)?

        Then its front faces would be clipped and the back faces are drawn instead; the
        shader builds the ray from the window position, not from the face it was drawn for.
        """
        eye_z = np.c_[self.proxy.positions, np.ones(len(self.proxy.positions))] @ camera.view[2]
        return bool(eye_z.max() > -camera.near * 1.001)

    def draw(self, camera, light) -> None:
        import moderngl

        view_proj = camera.proj @ camera.view
        set_uniforms(self.prog, self.uniforms | camera_uniforms(camera) | light.uniforms()
                     | {"u_inv_view_proj": np.linalg.inv(view_proj)})
        for unit, (name, tex) in enumerate(self.textures.items()):
            tex.use(unit)
            set_uniforms(self.prog, {name: unit})
        self.ctx.enable(moderngl.CULL_FACE)
        self.ctx.cull_face = "front" if self.reaches_near_plane(camera) else "back"
        self.vao.render()
        self.ctx.disable(moderngl.CULL_FACE)

    def finish(self, frame) -> None:
        """Depth AOV from the hit positions (in conservative mode the Z-buffer holds the box)."""
        frame.depth = window_depth(frame.position, frame.view, frame.proj, frame.depth)
        if self.count_iterations:
            counts = frame.extra["targets"][0]
            ran = counts[..., 2] > 0.5
            covered = counts[..., 3] > 0.5
            primary, shadow = counts[..., 0], counts[..., 1]
            frame.stats.update({
                "fragments": int(ran.sum()), "covered": int(covered.sum()),
                "iterations_mean": float(primary[ran].mean()) if ran.any() else 0.0,
                "iterations_max": int(primary[ran].max()) if ran.any() else 0,
                "iterations_mean_covered": float(primary[covered].mean()) if covered.any()
                else 0.0,
                "shadow_iterations_mean": float(shadow[covered].mean()) if covered.any()
                else 0.0,
            })
            frame.extra["iterations"] = np.where(ran, primary, np.nan).astype(np.float32)

    def release(self) -> None:
        for obj in (self.vao, self.vbo, self.ibo, *self.textures.values()):
            obj.release()


class ReliefObjectDrawable:
    """Every part of a ReliefObject (six frusta of a cube) with the same options.

    The parts always write their hit depth: a part whose proxy reaches the near plane is
    drawn by its back faces, and box depths of front and back faces would not order parts.
    """

    def __init__(self, ctx, obj: ReliefObject, **options):
        options = options | {"depth_mode": "exact"}
        self.parts = [ReliefDrawable(ctx, part, **options) for part in obj.parts]
        self.extra_attachments = self.parts[0].extra_attachments

    def draw(self, camera, light) -> None:
        for part in self.parts:
            part.draw(camera, light)

    def finish(self, frame) -> None:
        self.parts[0].finish(frame)

    def release(self) -> None:
        for part in self.parts:
            part.release()


register_renderer(ReliefTexture, ReliefDrawable, OPTIONS)
register_renderer(ReliefObject, ReliefObjectDrawable, OPTIONS)
