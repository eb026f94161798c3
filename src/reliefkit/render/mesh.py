"""Ground truth: rasterize the original mesh into a Frame with every AOV."""

from __future__ import annotations

import numpy as np

from ..core.technique import DrawableSpec, ProgramVariant
from ..gl.context import check_gl_error
from ..gl.shaders import program
from ..gl.textures import texture2d
from ..gl.uniforms import camera_uniforms, set_uniforms
from ..scene.light import DirectionalLight
from ..scene.mesh import RenderMesh
from .registry import register_core_drawable

PROGRAM = "core:mesh.glsl"
MESH_PROGRAMS = tuple(  # the draw-path variants (compiled as GLSL ES by the tests too)
    ProgramVariant(PROGRAM, {"HAS_TEXTURE": textured, "COUNT_ITERATIONS": counted})
    for textured in (False, True) for counted in (False, True))


class MeshDrawable:
    """GPU buffers of a RenderMesh, drawable many times (turntables, benchmarks)."""

    def __init__(self, ctx, mesh: RenderMesh, options=None, instrument: bool = False):
        self.ctx, self.mesh = ctx, mesh
        textured = mesh.texture is not None
        self.extra_attachments = 1 if instrument else 0
        self.prog = program(ctx, PROGRAM, {"HAS_TEXTURE": textured,
                                           "COUNT_ITERATIONS": instrument})
        uvs = mesh.uvs if mesh.uvs is not None else np.zeros((len(mesh.positions), 2), np.float32)
        interleaved = np.hstack([mesh.positions, mesh.normals, mesh.colors, uvs]).astype(np.float32)
        self.vbo = ctx.buffer(interleaved.tobytes())
        self.ibo = ctx.buffer(mesh.indices.tobytes())
        layout = (("in_position", 3), ("in_normal", 3), ("in_color", 4), ("in_uv", 2))
        attributes = [name for name, _ in layout if name in self.prog]
        fmt = " ".join(f"{n}f" if name in self.prog else f"{n}x4" for name, n in layout)
        self.vao = ctx.vertex_array(self.prog, [(self.vbo, fmt, *attributes)], self.ibo,
                                    index_element_size=4)
        self.texture = texture2d(ctx, mesh.texture, what=f"{mesh.name} texture", srgb=True,
                                 mipmaps=True, repeat=True) if textured else None
        check_gl_error(ctx, f"uploading mesh {mesh.name}")

    def draw(self, camera, light: DirectionalLight) -> None:
        set_uniforms(self.prog, camera_uniforms(camera) | light.uniforms())
        if self.texture is not None:
            self.texture.use(0)
            set_uniforms(self.prog, {"u_texture": 0})
        self.vao.render()

    def finish(self, frame) -> None:
        frame.stats["triangles"] = frame.stats.get("triangles", 0) + self.mesh.triangle_count

    def release(self) -> None:
        for obj in (self.vao, self.vbo, self.ibo, self.texture):
            if obj is not None:
                obj.release()


def _register() -> None:
    register_core_drawable(DrawableSpec(RenderMesh, MeshDrawable))


_register()
