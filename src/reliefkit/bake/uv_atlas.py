"""A mesh's own materials in its uv space: what a layer baked over the mesh (a shell
volume) keeps of the surface it covers.

One layer per material (each material has its own texture over uvs that other materials'
triangles may reuse): the material's triangles are drawn by the core renderer (textures, uv
transforms and alpha modes as they are drawn everywhere) with their uvs as positions,
through `project.project_mesh`, so layer k's texel (row, col) holds material k's colour
(factor times texture; vertex colours are no material) at that uv. Empty texels between uv
islands are filled from the nearest island (`project.dilate`), so bilinear lookups at an
island's edge keep its colour.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..colorspace import srgb_decode, to_rgba8
from ..scene.mesh import RenderMesh
from .project import dilate, project_mesh

#: Texels along each side of a layer.
ATLAS_SIZE = 256
#: Meshes with more materials keep none (a texture array of this many layers is small).
MAX_MATERIALS = 64


@dataclass(frozen=True)
class MaterialAtlas:
    """``rgba8`` (M, H, W, 4) uint8 sRGB colour (alpha 255) per material over the uv
    rectangle ``box`` (u0, v0, u1, v1); row 0 of a layer is v0."""

    rgba8: np.ndarray
    box: tuple


def has_material(mesh) -> bool:
    """Whether any material of ``mesh`` has a texture or a colour other than white."""
    return any(m.texture is not None or not np.allclose(m.color, 1.0) for m in mesh.materials)


def material_atlas(mesh, size: int = ATLAS_SIZE, ctx=None) -> MaterialAtlas:
    """The colour of each of ``mesh``'s materials (at most `MAX_MATERIALS`) over the
    rectangle its uvs span (it needs uvs)."""
    uvs = np.asarray(mesh.uvs, np.float64)
    lo, hi = uvs.min(axis=0), uvs.max(axis=0)
    extent = np.maximum(hi - lo, 1e-9)
    box = np.eye(4)
    box[0, 0], box[1, 1], box[2, 2] = extent[0], extent[1], 2.0
    box[:3, 3] = (lo[0], lo[1], -1.0)
    count = len(uvs)
    flat = np.column_stack([uvs, np.zeros(count)])
    up, white = np.tile([0.0, 0.0, 1.0], (count, 1)), np.ones((count, 4), np.float32)
    material = np.asarray(mesh.material)
    layers = np.full((len(mesh.materials), size, size, 4), 255, np.uint8)
    for k, m in enumerate(mesh.materials):
        faces = np.asarray(mesh.indices)[material == k]
        if not len(faces):
            continue
        part = RenderMesh(flat, faces, up, white, mesh.uvs, name=f"{mesh.name} uv atlas",
                          materials=[m])
        projection = project_mesh(part, box, (size, size), ctx=ctx)
        (rgba,) = dilate(projection.mask, projection.color)
        rgba = np.asarray(rgba, np.float32).copy()
        rgba[..., 3] = 1.0
        layers[k] = to_rgba8(rgba)
    return MaterialAtlas(layers, (float(lo[0]), float(lo[1]), float(lo[0] + extent[0]),
                                  float(lo[1] + extent[1])))


def kept_atlas(mesh) -> tuple[MaterialAtlas | None, int]:
    """The atlas of ``mesh``'s materials when they are anything but plain white (None
    otherwise), and how many materials were left out: all of them past `MAX_MATERIALS`."""
    if not has_material(mesh):
        return None, 0
    if len(mesh.materials) > MAX_MATERIALS:
        return None, len(mesh.materials)
    return material_atlas(mesh), 0


def atlas_uniforms(atlas: MaterialAtlas | None, unit: int) -> dict:
    """The uniforms of core:include/surface_tint.glsl, its texture array bound to ``unit``."""
    box = atlas.box if atlas is not None else (0.0, 0.0, 1.0, 1.0)
    return {"u_surface": unit, "u_tinted": atlas is not None,
            "u_surface_box": (box[0], box[1], 1.0 / (box[2] - box[0]),
                              1.0 / (box[3] - box[1]))}


def linear_tint(atlas: MaterialAtlas, uv, layer) -> np.ndarray:
    """(..., 3) linear colour of ``atlas`` at base uvs ``uv`` (..., 2) in layers ``layer``
    (...): bilinear between texel centres, clamped at the border, as surface_tint.glsl
    samples it."""
    uv = np.asarray(uv, np.float64)
    layer = np.asarray(layer, np.int64)
    _, height, width, _ = atlas.rgba8.shape
    u0, v0, u1, v1 = atlas.box
    x = np.clip((uv[..., 0] - u0) / (u1 - u0) * width - 0.5, 0.0, width - 1.0)
    y = np.clip((uv[..., 1] - v0) / (v1 - v0) * height - 0.5, 0.0, height - 1.0)
    x0, y0 = np.floor(x).astype(np.int64), np.floor(y).astype(np.int64)
    x1, y1 = np.minimum(x0 + 1, width - 1), np.minimum(y0 + 1, height - 1)
    fx, fy = (x - x0)[..., None], (y - y0)[..., None]

    def rgb(rows, cols):
        return srgb_decode(atlas.rgba8[layer, rows, cols, :3] / 255.0)

    top = rgb(y0, x0) * (1 - fx) + rgb(y0, x1) * fx
    bottom = rgb(y1, x0) * (1 - fx) + rgb(y1, x1) * fx
    return top * (1 - fy) + bottom * fy
