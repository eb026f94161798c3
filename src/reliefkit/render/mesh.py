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

from ..compact.encodings import encoding_of
from ..core.params import param
from ..core.technique import DrawableSpec, ProgramVariant
from ..scene.mesh import Material, RenderMesh
from .plan import Attribute, DrawPlan, Geometry, MultiPass, Program, Texture

PROGRAM = "core:mesh.glsl"
MESH_PROGRAMS = tuple(  # the draw-path variants (compiled as GLSL ES by the tests too)
    ProgramVariant(PROGRAM, {"HAS_TEXTURE": textured, "COUNT_ITERATIONS": counted,
                             "SHADOWS": shadows})
    for textured in (False, True) for counted in (False, True) for shadows in (False, True)
) + tuple(ProgramVariant(PROGRAM, {"HAS_TEXTURE": textured, "COUNT_ITERATIONS": counted,
                                   "INSTANCED": True})
          for textured in (False, True) for counted in (False, True)
) + tuple(ProgramVariant(PROGRAM, {"HAS_TEXTURE": textured, "SHADOW_MAP": True})
          for textured in (False, True))
SHADOW_MAP_SIZE = 2048  # texels on a side over the mesh's bounding sphere

#: u_alpha_mode of shaders/mesh.glsl for each `Material.alpha_mode`.
ALPHA_MODE_CODES = {"OPAQUE": 0, "MASK": 1, "BLEND": 2}

_ATTRIBUTES = ("in_position", "in_normal", "in_color", "in_uv")


@dataclass(frozen=True)
class MeshRenderOptions:
    """The ground truth's render options."""

    shadows: bool = param(False, "shadows from a shadow map of the directional light "
                                 "(2048² over the bounding sphere, filtered 3 x 3)")


class MeshDrawable:
    """A RenderMesh as draw plans: one vertex and index array, one plan per material (its
    triangles are a contiguous range of the indices), one texture per distinct image."""

    #: its instrumented variant counts fragments only: its shader has no loop
    counts_iterations = False

    def __init__(self, mesh: RenderMesh, options: MeshRenderOptions | None = None,
                 instrument: bool = False):
        self.mesh = mesh
        self.options = options or MeshRenderOptions()
        self.extra_attachments = 1 if instrument else 0
        self.plans = mesh_plans(mesh, self.options.shadows, instrument)

    def finish(self, frame, stats: dict) -> None:
        frame.stats["triangles"] = frame.stats.get("triangles", 0) + self.mesh.triangle_count


def mesh_plans(mesh: RenderMesh, shadows: bool = False, instrument: bool = False) -> list:
    """The draw plans of ``mesh``: per material its range of the shared index array, its
    program variant, texture and uniforms; with ``shadows`` each also casts into the light's
    shadow map (the "shadow-map" multi-pass kind)."""
    groups = mesh.material_groups()
    uvs = mesh.uvs if mesh.uvs is not None else np.zeros((len(mesh.positions), 2))
    arrays = (mesh.positions, mesh.normals, mesh.colors, uvs)
    geometry = Geometry(
        attributes={name: Attribute(np.ascontiguousarray(a, np.float32))
                    for name, a in zip(_ATTRIBUTES, arrays, strict=True)},
        indices=np.concatenate([c.ravel() for _, c in groups]).astype(np.uint32))
    textures: dict[int, Texture] = {}  # one texture per distinct image
    plans, first = [], 0
    for material, corners in groups:
        textured = material.texture is not None
        sampled = {}
        if textured:
            key = id(material.texture)
            if key not in textures:
                textures[key] = Texture(material.texture, srgb=True, mipmaps=True,
                                        wrap=("repeat", "repeat", "repeat"),
                                        what=f"{mesh.name} texture",
                                        encoded=encoding_of(material.texture))
            sampled = {"u_texture": textures[key]}
        multipass = None
        if shadows:
            multipass = MultiPass("shadow-map", {"caster": Program(
                PROGRAM, {"HAS_TEXTURE": textured, "SHADOW_MAP": True})},
                {"bounds": np.asarray(mesh.bounds, np.float64), "size": SHADOW_MAP_SIZE})
        plans.append(DrawPlan(
            name=f"{mesh.name} material {len(plans)}",
            program=Program(PROGRAM, {"HAS_TEXTURE": textured,
                                      "COUNT_ITERATIONS": instrument, "SHADOWS": shadows}),
            geometry=geometry, textures=sampled, uniforms=material_uniforms(material),
            origin=tuple(float(x) for x in mesh.origin), first=first, count=corners.size,
            multipass=multipass))
        first += corners.size
    return plans


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
