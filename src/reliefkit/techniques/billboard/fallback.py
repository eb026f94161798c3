"""A billboard cloud as plain textured quads: what a glTF viewer that knows nothing of
reliefkit shows of a cloud or of a DMBBC (its cloud's quads).

The quads are the renderer's (`quads.quad_attributes`: the same corners, the same atlas
coordinates, no inset), one material per atlas page, alpha-tested at the renderer's 0.5 and
double-sided. The renderer tests coverage on the atlas's base level; a viewer filters the
atlas with mipmaps it builds itself, so every texel a quad does not cover takes the colour of
its nearest covered texel (`bake.project.dilate`): a bake dilates each rectangle only into its
`GUTTER`, and the texels between the rectangles are black, which a viewer's mip levels of
two texels and more would mix into the quads' borders.

The stored world normals become a tangent-space normal map per page
(`fallback_normal_texture`), in glTF's convention: a texel's (x, y, z) are the normal's
components along the quad's tangent T = normalize(u_axis) (increasing u), its bitangent
B = N x T and its plane normal N = normalize(u_axis x v_axis). B points along v_axis
(increasing v in reliefkit's uvs) when the rectangle's sides are perpendicular, as baked
ones are: up in the picture, as glTF's normal maps expect, once the image is written
upright (reliefkit's row 0 is v = 0, the bottom; glTF's row 0 is the top, v = 0 there).
The glTF writer derives each vertex's TANGENT from the uvs (`io.gltf.mesh.vertex_tangents`):
T with w = +1 on every quad, so a viewer need not derive the frame itself.
"""

from __future__ import annotations

import numpy as np

from ...bake.project import dilate
from ...errors import UsageError
from ...scene.mesh import Material, RenderMesh
from .quads import quad_attributes, quad_indices

#: The renderer's alpha test (shaders/billboard.glsl): coverage below it is discarded.
ALPHA_CUTOFF = 0.5


def cloud_of(rep):
    """The `BillboardCloud` a representation falls back to: a DMBBC's ``cloud`` (the one its
    switch by distance draws), or the cloud itself."""
    return getattr(rep, "cloud", rep)


def fallback_mesh(rep) -> RenderMesh:
    """One quad (two triangles) per rectangle of ``rep``'s cloud, a fixed count; material k
    is atlas page k, its colour dilated into the texels no quad covers."""
    cloud = cloud_of(rep)
    attributes = quad_attributes(cloud, cloud.center)
    materials = tuple(Material(name=f"billboard atlas page {page}", texture=texture,
                               alpha_mode="MASK", alpha_cutoff=ALPHA_CUTOFF,
                               double_sided=True)
                      for page, texture in enumerate(_dilated_pages(cloud)))
    white = np.broadcast_to(np.ones(4, np.float32), (4 * cloud.count, 4))
    source = cloud.params.get("source") or "billboard cloud"
    return RenderMesh(attributes["in_position"], quad_indices(cloud.count).reshape(-1, 3),
                      attributes["in_plane_normal"], white, uvs=attributes["in_atlas"][:, :2],
                      name=f"{source} quads", materials=materials,
                      material=np.repeat(cloud.rects[:, 0], 2), origin=cloud.center)


def fallback_normal_maps(rep) -> dict[int, np.ndarray]:
    """Material (atlas page) -> its `fallback_normal_texture`: what the glTF export writes as
    each material's normalTexture."""
    return {page: fallback_normal_texture(rep, page)
            for page in range(cloud_of(rep).normal.shape[0])}


def fallback_normal_texture(rep, page: int = 0) -> np.ndarray:
    """(h, w, 4) uint8 tangent-space normal map of material ``page`` of `fallback_mesh`
    (linear, (n + 1) / 2 * 255, alpha 255), in each quad's frame (T, N x T, N); dilated
    as the colour is."""
    cloud = cloud_of(rep)
    pages = cloud.normal.shape[0]
    if isinstance(page, bool) or not isinstance(page, int | np.integer) \
            or not 0 <= page < pages:
        raise UsageError(f"page must be an atlas page of the cloud, 0..{pages - 1}, "
                         f"got {page!r}")
    tangent, bitangent, normal = _tangent_frames(cloud)
    encoded = np.empty(cloud.normal.shape[1:], np.uint8)
    encoded[...] = (128, 128, 255)  # flat, where nothing is shown
    for p in np.flatnonzero(cloud.rects[:, 0] == page):
        _, x, y, w, h = cloud.rects[p]
        world = cloud.normal[page, y:y + h, x:x + w] * (2.0 / 255.0) - 1.0
        local = world @ np.stack([tangent[p], bitangent[p], normal[p]]).T
        length = np.linalg.norm(local, axis=-1, keepdims=True)  # ~0: the shader's plane normal
        local = np.where(length > 1e-3, local / np.maximum(length, 1e-12), [0.0, 0.0, 1.0])
        encoded[y:y + h, x:x + w] = np.round((local + 1.0) * 127.5)
    (encoded,) = dilate(_shown(cloud, page), encoded)
    return np.concatenate([encoded, np.full(encoded.shape[:2] + (1,), 255, np.uint8)], axis=-1)


def _dilated_pages(cloud) -> list[np.ndarray]:
    """Every atlas page with its colour dilated from the texels the quads show (alpha kept)."""
    pages = []
    for page in range(cloud.color.shape[0]):
        rgba = cloud.color[page]
        (rgb,) = dilate(_shown(cloud, page), rgba[..., :3])
        pages.append(np.concatenate([rgb, rgba[..., 3:]], axis=-1))
    return pages


def _shown(cloud, page: int) -> np.ndarray:
    """(H, W) texels of ``page`` a quad shows: inside a rectangle, with some coverage."""
    inside = np.zeros(cloud.color.shape[1:3], bool)
    for on, x, y, w, h in cloud.rects:
        if on == page:
            inside[y:y + h, x:x + w] = True
    return inside & (cloud.color[page, ..., 3] > 0)


def _tangent_frames(cloud) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(P, 3) T, B, N of every rectangle: orthonormal, right-handed, N its plane normal."""
    normal = cloud.normals
    tangent = cloud.u_axes / np.linalg.norm(cloud.u_axes, axis=1, keepdims=True)
    return tangent, np.cross(normal, tangent), normal

