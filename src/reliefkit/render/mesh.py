"""Ground truth: rasterize the original mesh into a Frame with every AOV.

The mesh is drawn one material at a time (its triangles are contiguous in the index buffer),
each with its colour factor, its alpha mode (OPAQUE: alpha 1; MASK: fragments below the
cutoff discarded, the rest alpha 1; BLEND: alpha kept as the Frame's coverage) and, when it has
one, its texture and UV transform. With ``shadows`` a shadow map of the directional light
(`render.shadows`) darkens what the mesh hides from it, as the techniques' own --shadows do.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.params import param
from ..core.technique import DrawableSpec, ProgramVariant
from ..gl.context import check_gl_error
from ..gl.objects import GLObjects
from ..gl.shaders import program
from ..gl.textures import texture2d
from ..gl.uniforms import camera_uniforms, model_offset, set_uniforms
from ..scene.light import DirectionalLight
from ..scene.mesh import Material, RenderMesh
from .shadows import SHADOW_UNIT, render_shadow_map

PROGRAM = "core:mesh.glsl"
MESH_PROGRAMS = tuple(  # the draw-path variants (compiled as GLSL ES by the tests too)
    ProgramVariant(PROGRAM, {"HAS_TEXTURE": textured, "COUNT_ITERATIONS": counted,
                             "SHADOWS": shadows})
    for textured in (False, True) for counted in (False, True) for shadows in (False, True)
) + tuple(ProgramVariant(PROGRAM, {"HAS_TEXTURE": textured, "SHADOW_MAP": True})
          for textured in (False, True))
SHADOW_MAP_SIZE = 2048  # texels on a side over the mesh's bounding sphere

#: u_alpha_mode of shaders/mesh.glsl for each `Material.alpha_mode`.
ALPHA_MODE_CODES = {"OPAQUE": 0, "MASK": 1, "BLEND": 2}

_LAYOUT = (("in_position", 3), ("in_normal", 3), ("in_color", 4), ("in_uv", 2))


@dataclass(frozen=True)
class MeshRenderOptions:
    """The ground truth's render options."""

    shadows: bool = param(False, "shadows from a shadow map of the directional light "
                                 "(2048² over the bounding sphere, filtered 3 x 3)")


@dataclass(frozen=True)
class _Draw:
    """One material's triangles: indices [first, first + count) of the index buffer."""

    textured: bool
    texture: object | None
    uniforms: dict
    first: int
    count: int


class MeshDrawable(GLObjects):
    """GPU buffers of a RenderMesh, drawable many times (turntables, benchmarks)."""

    def __init__(self, ctx, mesh: RenderMesh, options: MeshRenderOptions | None = None,
                 instrument: bool = False):
        self.ctx, self.mesh = ctx, mesh
        self.options = options or MeshRenderOptions()
        self.extra_attachments = 1 if instrument else 0
        self._shadow_maps: dict[tuple, dict] = {}  # light direction -> its uniforms
        self._upload_owned(lambda: self._upload(instrument))

    def _upload(self, instrument: bool) -> None:
        ctx, mesh = self.ctx, self.mesh
        groups = mesh.material_groups()
        uvs = mesh.uvs if mesh.uvs is not None else np.zeros((len(mesh.positions), 2))
        interleaved = np.hstack([mesh.positions, mesh.normals, mesh.colors, uvs])
        vbo = self.keep(ctx.buffer(interleaved.astype(np.float32).tobytes()))
        ibo = self.keep(ctx.buffer(np.concatenate([c.ravel() for _, c in groups]).tobytes()))
        # (pass, textured) -> (program, vertex array); pass "main", or "shadow_map" (depth
        # from the light) with shadows
        self.passes: dict[tuple[str, bool], tuple] = {}
        textures: dict[int, object] = {}  # one upload per distinct image
        self.draws: list[_Draw] = []
        first = 0
        for material, corners in groups:
            textured = material.texture is not None
            if ("main", textured) not in self.passes:
                self._add_passes(textured, instrument, vbo, ibo)
            texture = None
            if textured:
                key = id(material.texture)
                if key not in textures:
                    textures[key] = self.keep(texture2d(
                        ctx, material.texture, what=f"{mesh.name} texture", srgb=True,
                        mipmaps=True, repeat=True))
                texture = textures[key]
            self.draws.append(_Draw(textured, texture, material_uniforms(material), first,
                                    corners.size))
            first += corners.size
        check_gl_error(ctx, f"uploading mesh {mesh.name}")

    def _add_passes(self, textured: bool, instrument: bool, vbo, ibo) -> None:
        shadows = self.options.shadows
        defines = {"main": {"HAS_TEXTURE": textured, "COUNT_ITERATIONS": instrument,
                            "SHADOWS": shadows}}
        if shadows:
            defines["shadow_map"] = {"HAS_TEXTURE": textured, "SHADOW_MAP": True}
        for name, chosen in defines.items():
            prog = program(self.ctx, PROGRAM, chosen)
            self.passes[name, textured] = (prog, self._vertex_array(prog, vbo, ibo))

    def _vertex_array(self, prog, vbo, ibo):
        attributes = [name for name, _ in _LAYOUT if name in prog]
        fmt = " ".join(f"{n}f" if name in prog else f"{n}x4" for name, n in _LAYOUT)
        return self.keep(self.ctx.vertex_array(prog, [(vbo, fmt, *attributes)], ibo,
                                               index_element_size=4))

    def draw(self, camera, light: DirectionalLight) -> None:
        shared = light.uniforms()
        if self.options.shadows:
            shared |= self._shadow_map(light)
        self._draw_pass("main", camera, shared)

    def _draw_pass(self, name: str, camera, shared: dict) -> None:
        shared = camera_uniforms(camera) | model_offset(camera, self.mesh.origin) | shared
        for (kind, _), (prog, _) in self.passes.items():
            if kind == name:
                set_uniforms(prog, shared)
        for draw in self.draws:
            prog, vao = self.passes[name, draw.textured]
            set_uniforms(prog, draw.uniforms)
            if draw.texture is not None:
                draw.texture.use(0)
            vao.render(first=draw.first, vertices=draw.count)

    def _shadow_map(self, light: DirectionalLight) -> dict:
        """The shadow map's uniforms for ``light``, drawn on first use (then bound)."""
        key = tuple(light.unit_direction)
        if key not in self._shadow_maps:
            outer = self.ctx.fbo
            try:
                depth, uniforms = render_shadow_map(
                    self.ctx, self.mesh.bounds, light, self.mesh.origin,
                    lambda cam: self._draw_pass("shadow_map", cam, {}), SHADOW_MAP_SIZE)
            finally:
                outer.use()
            self.keep(depth)
            self._shadow_maps[key] = uniforms | {"texture": depth}
        uniforms = dict(self._shadow_maps[key])
        uniforms.pop("texture").use(SHADOW_UNIT)
        return uniforms

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


#: The core's ground-truth drawable; the composition root (`reliefkit.builtins`) registers it.
MESH_DRAWABLE = DrawableSpec(RenderMesh, MeshDrawable, MeshRenderOptions)
