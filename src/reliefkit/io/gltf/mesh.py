"""A `RenderMesh` as core glTF 2.0: one node, its mesh, a primitive per material, materials,
textures and one sampler, added to a `GlbBuilder`. What any glTF viewer shows.

Conventions crossed on the way out:

- **UVs.** reliefkit's v runs up and a texture's row 0 lies at v = 0; glTF's v runs down
  from the image's top row. The PNG holds the texture upside down from reliefkit's array
  (so it reads upright in an image viewer, as the loader's images do) and TEXCOORD_0 is
  (u, 1 - v), after the material's `uv_transform` is applied: glTF has no transform in core.
- **Colour.** baseColorFactor and COLOR_0 are linear, as reliefkit's; textures stay sRGB
  bytes. Baked colours are diffuse: metallicFactor 0 and roughnessFactor 1 (glTF's default
  metallic 1 draws them black under ambient light).
- **Precision.** POSITION is float32 relative to `RenderMesh.origin`, and the node's
  translation is that origin, so a viewer composes far-away meshes in float64 where it can.
- **Filtering.** One sampler, trilinear and repeating, as reliefkit's mesh renderer samples
  (uvs that leave [0, 1] tile there too). Textures of MASK and BLEND materials have their
  colour dilated into fully transparent texels first, so mipmaps and bilinear lookups at a
  cut-out's edge do not mix in those texels' colour.

Each primitive carries only the vertices its triangles use (indices uint16 where they fit),
and only the attributes its material reads: TEXCOORD_0 where it is textured, COLOR_0 where
the vertex colours are not all white. Equal images, textures and materials are written once.
"""

from __future__ import annotations

import io
from collections.abc import Mapping

import numpy as np
from PIL import Image

from ...errors import FormatError
from ...scene.mesh import Material, RenderMesh
from .glb import ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER, GlbBuilder, append_item

__all__ = ["add_render_mesh", "SAMPLER"]

#: The one sampler: trilinear, repeating (as reliefkit's mesh renderer samples textures).
SAMPLER = {"magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 10497}

_MOST_UINT16_VERTICES = 65535  # indices 0..65534: 65535 is the restart value glTF forbids


def add_render_mesh(builder: GlbBuilder, mesh: RenderMesh, *, name: str,
                    normal_textures: Mapping[int, np.ndarray] | None = None) -> dict:
    """Add ``mesh`` to ``builder.document`` (its mesh, materials, textures, images) and
    return its glTF node, for the caller to append to ``nodes`` and place in a scene.

    ``normal_textures`` maps a material index to a tangent-space normal map for that
    material (``normalTexture``): (h, w, 3 or 4) uint8, row 0 at v = 0 like the colour
    textures, x along +u and y along +v (glTF's convention: +y up in the written image).
    """
    normal_textures = _checked_normal_textures(mesh, normal_textures or {})
    textures = _Textures(builder)
    primitives = []
    used = np.flatnonzero(np.bincount(mesh.material, minlength=len(mesh.materials)))
    for k, (material, corners) in zip(used, mesh.material_groups(), strict=True):
        normal = normal_textures.get(int(k))
        color = None if material.texture is None else textures.color(material)
        normal_index = None if normal is None else textures.image(normal, dilate=False)
        glmaterial = _material(material, color, normal_index)
        primitive = _primitive(builder, mesh, corners, material,
                               uvs=color is not None or normal is not None,
                               tangents=normal is not None)
        primitive["material"] = _index_of(builder.document, "materials", glmaterial)
        primitives.append(primitive)
    mesh_index = append_item(builder.document, "meshes", {"name": name, "primitives": primitives})
    node = {"name": name, "mesh": mesh_index}
    if mesh.origin.any():
        node["translation"] = [float(x) for x in mesh.origin]
    return node


# ------------------------------------------------------------------------ geometry


def _primitive(builder: GlbBuilder, mesh: RenderMesh, corners: np.ndarray,
               material: Material, *, uvs: bool, tangents: bool) -> dict:
    """The attributes and indices of one material's triangles, over the vertices they use."""
    vertices, local = np.unique(corners, return_inverse=True)
    local = local.reshape(-1, 3)
    index_type = np.uint16 if len(vertices) <= _MOST_UINT16_VERTICES else np.uint32
    normals = _unit(mesh.normals[vertices])
    attributes = {
        "POSITION": builder.add_array(mesh.positions[vertices], target=ARRAY_BUFFER,
                                      bounds=True),
        "NORMAL": builder.add_array(normals, target=ARRAY_BUFFER),
    }
    surface_uvs = transformed_uvs(mesh.uvs[vertices], material.uv_transform) if uvs else None
    if uvs:
        attributes["TEXCOORD_0"] = builder.add_array(gltf_uvs(surface_uvs),
                                                     target=ARRAY_BUFFER)
    if tangents:
        attributes["TANGENT"] = builder.add_array(
            vertex_tangents(mesh.positions[vertices], normals, surface_uvs, local),
            target=ARRAY_BUFFER)
    colors = mesh.colors[vertices]
    if not (colors == 1.0).all():
        attributes["COLOR_0"] = builder.add_array(np.clip(colors, 0.0, 1.0).astype(np.float32),
                                                  target=ARRAY_BUFFER)
    indices = builder.add_array(local.reshape(-1).astype(index_type),
                                target=ELEMENT_ARRAY_BUFFER)
    return {"attributes": attributes, "indices": indices}


def transformed_uvs(uvs: np.ndarray, uv_transform: np.ndarray | None) -> np.ndarray:
    """(N, 2) float64 uvs (reliefkit's, v up) through a material's transform."""
    uv = np.asarray(uvs, np.float64)
    if uv_transform is None:
        return uv
    matrix = np.asarray(uv_transform, np.float64)
    return uv @ matrix[:2, :2].T + matrix[:2, 2]


def gltf_uvs(uvs: np.ndarray) -> np.ndarray:
    """(N, 2) float32 TEXCOORD_0 of reliefkit's uvs: v flipped to glTF's (v down from the
    image's top row)."""
    return np.column_stack([uvs[:, 0], 1.0 - uvs[:, 1]]).astype(np.float32)


def vertex_tangents(positions: np.ndarray, normals: np.ndarray, uvs: np.ndarray,
                    triangles: np.ndarray) -> np.ndarray:
    """(N, 4) float32 glTF TANGENTs: xyz the unit direction of increasing u in each vertex's
    tangent plane, w the sign that makes cross(normal, xyz) * w point along increasing v
    (reliefkit's v: up in the written image, a normal map's +y). Summed over the triangles
    about a vertex, each weighted by its uv area; a vertex whose uvs span nothing gets any
    tangent."""
    p = np.asarray(positions, np.float64)[triangles]
    t = np.asarray(uvs, np.float64)[triangles]
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    d1, d2 = t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]
    det = d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]
    sign = np.sign(det)[:, None]  # (e1 dv2 - e2 dv1) / det, times |det|: no division by 0
    along_u = (e1 * d2[:, 1:] - e2 * d1[:, 1:]) * sign
    along_v = (e2 * d1[:, :1] - e1 * d2[:, :1]) * sign
    tangent = np.zeros((len(positions), 3))
    bitangent = np.zeros((len(positions), 3))
    for corner in range(3):
        np.add.at(tangent, triangles[:, corner], along_u)
        np.add.at(bitangent, triangles[:, corner], along_v)
    n = np.asarray(normals, np.float64)
    summed = np.linalg.norm(tangent, axis=1, keepdims=True)
    tangent -= n * (n * tangent).sum(axis=1, keepdims=True)  # into the tangent plane
    length = np.linalg.norm(tangent, axis=1, keepdims=True)
    spare = np.cross(n, np.where(np.abs(n[:, :1]) < 0.9, [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]))
    usable = length > 1e-6 * summed  # not (nearly) along the normal, whatever the mesh's scale
    tangent = np.where(usable, tangent / np.maximum(length, 1e-300), spare)
    tangent /= np.linalg.norm(tangent, axis=1, keepdims=True)
    w = np.where((np.cross(n, tangent) * bitangent).sum(axis=1) < 0, -1.0, 1.0)
    return np.column_stack([tangent, w]).astype(np.float32)


def _unit(normals: np.ndarray) -> np.ndarray:
    """Normals rescaled to unit length in float64 (glTF requires it; float32 sums and file
    normals drift), +y where one has no length, as `vertex_normals` gives."""
    n = np.asarray(normals, np.float64)
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return np.where(length > 0, n / np.maximum(length, 1e-300), [0.0, 1.0, 0.0]) \
        .astype(np.float32)


# ------------------------------------------------------------------------ materials


def _material(material: Material, color: int | None, normal: int | None) -> dict:
    pbr = {"baseColorFactor": [float(c) for c in material.color],
           "metallicFactor": 0.0, "roughnessFactor": 1.0}
    if color is not None:
        pbr["baseColorTexture"] = {"index": color}
    out = {"pbrMetallicRoughness": pbr}
    if material.name:
        out["name"] = material.name
    if material.alpha_mode != "OPAQUE":
        out["alphaMode"] = material.alpha_mode
    if material.alpha_mode == "MASK":  # the validator warns of a cutoff in other modes
        out["alphaCutoff"] = material.alpha_cutoff
    if material.double_sided:
        out["doubleSided"] = True
    if normal is not None:
        out["normalTexture"] = {"index": normal}
    return out


class _Textures:
    """glTF textures of arrays, each array (by identity: materials share theirs) encoded once;
    `GlbBuilder.add_png` writes equal images once across calls."""

    def __init__(self, builder: GlbBuilder):
        self.builder = builder
        self.pngs: dict[tuple[int, bool], int] = {}  # (id of an array, dilated) -> texture

    def color(self, material: Material) -> int:
        return self.image(material.texture, dilate=material.alpha_mode != "OPAQUE")

    def image(self, array: np.ndarray, *, dilate: bool) -> int:
        key = (id(array), dilate)
        if key not in self.pngs:
            pixels = dilated_texture(array) if dilate else array
            image = self.builder.add_png(png_bytes(pixels))
            sampler = _index_of(self.builder.document, "samplers", dict(SAMPLER))
            self.pngs[key] = _index_of(self.builder.document, "textures",
                                       {"sampler": sampler, "source": image})
        return self.pngs[key]


def dilated_texture(texture: np.ndarray) -> np.ndarray:
    """An RGBA texture with the colour of each fully transparent texel taken from the
    nearest texel that is not; alpha and every other texel unchanged."""
    from ...bake.project import dilate  # deferred: bake.project imports the GL renderer

    texture = np.asarray(texture)
    (rgb,) = dilate(texture[..., 3] > 0, texture[..., :3])
    return np.ascontiguousarray(np.dstack([rgb, texture[..., 3]]))


def png_bytes(texture: np.ndarray) -> bytes:
    """A (h, w, 3|4) uint8 texture (row 0 at v = 0) as PNG bytes, row 0 at the bottom of the
    image where glTF puts v = 1; RGB when every texel is opaque."""
    texture = np.asarray(texture)
    if texture.dtype != np.uint8 or texture.ndim != 3 or texture.shape[2] not in (3, 4):
        raise FormatError(f"a glTF image takes an (h, w, 3|4) uint8 array; got "
                          f"{texture.dtype} {texture.shape}")
    if texture.shape[2] == 4 and (texture[..., 3] == 255).all():
        texture = texture[..., :3]
    out = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(texture[::-1])).save(out, format="PNG")
    return out.getvalue()


def _checked_normal_textures(mesh: RenderMesh, maps: Mapping[int, np.ndarray]) -> dict:
    for k in maps:
        if not 0 <= int(k) < len(mesh.materials):
            raise FormatError(f"{mesh.name}: a normal texture for material {k}; the mesh has "
                              f"{len(mesh.materials)}")
    if maps and mesh.uvs is None:
        raise FormatError(f"{mesh.name}: a normal texture needs texture coordinates (uvs)")
    return {int(k): v for k, v in maps.items()}


# ------------------------------------------------------------------------ the document


def _index_of(document: dict, key: str, item: dict) -> int:
    """The index of an item equal to ``item`` in ``document[key]``, appended if none is."""
    items = document.setdefault(key, [])
    if item in items:
        return items.index(item)
    return append_item(document, key, item)

