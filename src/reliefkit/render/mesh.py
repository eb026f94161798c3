"""Ground truth: rasterize the original mesh into a Frame with every AOV.

The mesh is drawn one material at a time (its triangles are contiguous in the index buffer),
each with its colour factor, its alpha mode (OPAQUE: alpha 1; MASK: fragments below the
cutoff discarded, the rest alpha 1; BLEND: alpha kept as the Frame's coverage) and, when it has
one, its texture and UV transform.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.technique import DrawableSpec, ProgramVariant
from ..gl.context import check_gl_error
from ..gl.objects import GLObjects
from ..gl.shaders import program
from ..gl.textures import texture2d
from ..gl.uniforms import camera_uniforms, model_offset, set_uniforms
from ..scene.light import DirectionalLight
from ..scene.mesh import Material, RenderMesh
from .registry import register_core_drawable

PROGRAM = "core:mesh.glsl"
MESH_PROGRAMS = tuple(  # the draw-path variants (compiled as GLSL ES by the tests too)
    ProgramVariant(PROGRAM, {"HAS_TEXTURE": textured, "COUNT_ITERATIONS": counted})
    for textured in (False, True) for counted in (False, True))

#: u_alpha_mode of shaders/mesh.glsl for each `Material.alpha_mode`.
ALPHA_MODE_CODES = {"OPAQUE": 0, "MASK": 1, "BLEND": 2}

_LAYOUT = (("in_position", 3), ("in_normal", 3), ("in_color", 4), ("in_uv", 2))


@dataclass(frozen=True)
class _Draw:
    """One material's triangles: indices [first, first + count) of the index buffer."""

    prog: object
    vao: object
    texture: object | None
    uniforms: dict
    first: int
    count: int


class MeshDrawable(GLObjects):
    """GPU buffers of a RenderMesh, drawable many times (turntables, benchmarks)."""

    def __init__(self, ctx, mesh: RenderMesh, options=None, instrument: bool = False):
        self.ctx, self.mesh = ctx, mesh
        self.extra_attachments = 1 if instrument else 0
        self._upload_owned(lambda: self._upload(instrument))

    def _upload(self, instrument: bool) -> None:
        ctx, mesh = self.ctx, self.mesh
        groups = mesh.material_groups()
        uvs = mesh.uvs if mesh.uvs is not None else np.zeros((len(mesh.positions), 2))
        interleaved = np.hstack([mesh.positions, mesh.normals, mesh.colors, uvs])
        vbo = self.keep(ctx.buffer(interleaved.astype(np.float32).tobytes()))
        ibo = self.keep(ctx.buffer(np.concatenate([c.ravel() for _, c in groups]).tobytes()))
        vertex_arrays: dict[bool, tuple] = {}  # textured or not -> (program, vertex array)
        textures: dict[int, object] = {}  # one upload per distinct image
        self.draws: list[_Draw] = []
        first = 0
        for material, corners in groups:
            textured = material.texture is not None
            if textured not in vertex_arrays:
                prog = program(ctx, PROGRAM, {"HAS_TEXTURE": textured,
                                              "COUNT_ITERATIONS": instrument})
                vertex_arrays[textured] = (prog, self._vertex_array(prog, vbo, ibo))
            texture = None
            if textured:
                key = id(material.texture)
                if key not in textures:
                    textures[key] = self.keep(texture2d(
                        ctx, material.texture, what=f"{mesh.name} texture", srgb=True,
                        mipmaps=True, repeat=True))
                texture = textures[key]
            self.draws.append(_Draw(*vertex_arrays[textured], texture,
                                    material_uniforms(material), first, corners.size))
            first += corners.size
        self.programs = [prog for prog, _ in vertex_arrays.values()]
        check_gl_error(ctx, f"uploading mesh {mesh.name}")

    def _vertex_array(self, prog, vbo, ibo):
        attributes = [name for name, _ in _LAYOUT if name in prog]
        fmt = " ".join(f"{n}f" if name in prog else f"{n}x4" for name, n in _LAYOUT)
        return self.keep(self.ctx.vertex_array(prog, [(vbo, fmt, *attributes)], ibo,
                                               index_element_size=4))

    def draw(self, camera, light: DirectionalLight) -> None:
        shared = camera_uniforms(camera) | model_offset(camera, self.mesh.origin) | light.uniforms()
        for prog in self.programs:
            set_uniforms(prog, shared)
        for draw in self.draws:
            set_uniforms(draw.prog, draw.uniforms)
            if draw.texture is not None:
                draw.texture.use(0)
            draw.vao.render(first=draw.first, vertices=draw.count)

    def finish(self, frame) -> None:
        frame.stats["triangles"] = frame.stats.get("triangles", 0) + self.mesh.triangle_count



def material_uniforms(material: Material) -> dict:
    """u_base_color, u_uv_transform, u_texture (unit 0), u_alpha_mode and u_alpha_cutoff of
    shaders that draw a material (a program that lacks one ignores it)."""
    uv_transform = np.eye(3) if material.uv_transform is None else material.uv_transform
    return {"u_base_color": tuple(float(c) for c in material.color),
            "u_uv_transform": tuple(float(x) for x in uv_transform.T.ravel()),  # column-major
            "u_texture": 0,
            "u_alpha_mode": ALPHA_MODE_CODES[material.alpha_mode],
            "u_alpha_cutoff": float(material.alpha_cutoff)}


def _register() -> None:
    register_core_drawable(DrawableSpec(RenderMesh, MeshDrawable))


_register()
