"""Drawing a `BillboardCloud`: one textured quad per rectangle, alpha-tested, normal-mapped.

The cloud is one draw plan (`render.plan`), drawn by the executor: all rectangles in one
vertex and index array, one draw call; the atlas pages are the layers of two texture arrays
(colour and normal), so a cloud costs two texture bindings whatever its page count. The
quads are stored relative to the cloud's centre, the plan's ``origin`` (camera-relative
rendering), so a cloud far from the world origin draws as it does at the origin. The shader
(shaders/billboard.glsl) tests coverage at 0.5 on the atlas's base level and shades
two-sided like the ground-truth mesh.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...compact.encodings import encoding_of
from ...core.technique import DrawableSpec, ProgramVariant
from ...render.plan import Attribute, DrawPlan, Geometry, Program, Texture
from .representation import BillboardCloud

PROGRAM = "billboard:billboard.glsl"
PROGRAMS = tuple(ProgramVariant(PROGRAM, {"COUNT_ITERATIONS": counted, "INSTANCED": placed})
                 for counted in (False, True)
                 for placed in (False, True))  # the draw-path variants (GLSL ES test)

#: (s, t) of a quad's four corners, counter-clockwise seen from the side u x v faces, so
#: gl_FrontFacing is true there; and its two triangles.
_QUAD_ST = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float64)
_QUAD_TRIANGLES = np.array([0, 1, 2, 0, 2, 3], np.uint32)


@dataclass(frozen=True)
class BillboardRenderOptions:
    """The render options of billboard clouds (none yet: the baseline has no variants)."""


def quad_attributes(cloud: BillboardCloud, origin) -> dict[str, np.ndarray]:
    """The quads' vertex arrays, (4P, 3) float32 each: ``in_position`` the corner relative
    to ``origin``, ``in_atlas`` (u, v, page), ``in_plane_normal``; corner k of rectangle p
    is row 4p + k.

    The atlas coordinate of (s, t) is ((x + s w) / W, (y + t h) / H): texel (x + i, y + j)
    then holds s = (i + 0.5) / w, t = (j + 0.5) / h, as the representation defines it.
    """
    s, t = _QUAD_ST[:, 0][None, :, None], _QUAD_ST[:, 1][None, :, None]
    corners = cloud.corners[:, None] + s * cloud.u_axes[:, None] + t * cloud.v_axes[:, None]
    relative = corners - np.asarray(origin, dtype=np.float64)
    page, x, y, w, h = (cloud.rects[:, k, None].astype(np.float64) for k in range(5))
    height, width = cloud.color.shape[1:3]
    atlas = np.stack([(x + s[..., 0] * w) / width, (y + t[..., 0] * h) / height,
                      np.broadcast_to(page, (cloud.count, 4))], axis=-1)
    normals = np.broadcast_to(cloud.normals[:, None], (cloud.count, 4, 3))
    return {name: a.reshape(-1, 3).astype(np.float32) for name, a in
            (("in_position", relative), ("in_atlas", atlas), ("in_plane_normal", normals))}


def quad_indices(count: int) -> np.ndarray:
    """Two triangles per quad, indexing `quad_attributes`."""
    return (_QUAD_TRIANGLES[None] + 4 * np.arange(count, dtype=np.uint32)[:, None]).ravel()


def cloud_plan(cloud: BillboardCloud, instrument: bool = False) -> DrawPlan:
    """The cloud's one draw: its quads relative to its centre, its atlases as mip-mapped
    texture arrays (colour sRGB-decoded), the counting variant when ``instrument``."""
    attributes = quad_attributes(cloud, cloud.center)
    return DrawPlan(
        name=f"billboard cloud of {cloud.count} rectangles",
        program=Program(PROGRAM, {"COUNT_ITERATIONS": instrument}),
        geometry=Geometry({name: Attribute(a) for name, a in attributes.items()},
                          indices=quad_indices(cloud.count)),
        textures={"u_color_atlas": Texture(cloud.color, target="2d_array", srgb=True,
                                           mipmaps=True, what="billboard colour atlas",
                                           encoded=encoding_of(cloud.color)),
                  "u_normal_atlas": Texture(cloud.normal, target="2d_array", mipmaps=True,
                                            what="billboard normal atlas",
                                            encoded=encoding_of(cloud.normal))},
        origin=tuple(float(x) for x in cloud.center))


class BillboardCloudDrawable:
    """A BillboardCloud as its draw plan (`cloud_plan`)."""

    def __init__(self, cloud: BillboardCloud, options=None, instrument: bool = False):
        self.cloud = cloud
        self.extra_attachments = 1 if instrument else 0
        self.plans = [cloud_plan(cloud, instrument)]

    def finish(self, frame, stats: dict) -> None:
        frame.stats["rectangles"] = frame.stats.get("rectangles", 0) + self.cloud.count


def drawable_spec() -> DrawableSpec:
    """How the technique draws its clouds (the package's `Technique` declares it)."""
    return DrawableSpec(BillboardCloud, BillboardCloudDrawable, BillboardRenderOptions)
