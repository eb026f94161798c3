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
    from ..colorspace import to_rgba8
    from ..scene.mesh import RenderMesh
    from .project import dilate, project_mesh

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
