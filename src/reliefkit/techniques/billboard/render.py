"""Drawing a `BillboardCloud`: one textured quad per rectangle, alpha-tested, normal-mapped.

All rectangles go into one vertex buffer and one draw call; the atlas pages are the layers
of two texture arrays (colour and normal), so a cloud costs two texture bindings whatever
its page count. The quads are stored relative to the cloud's centre and placed with
``u_model_offset`` (camera-relative rendering), so a cloud far from the world origin draws
as it does at the origin. The shader (shaders/billboard.glsl) tests coverage at 0.5 on the
atlas's base level and shades two-sided like the ground-truth mesh.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...core.technique import DrawableSpec, ProgramVariant
from ...gl.context import check_gl_error
from ...gl.objects import GLObjects
from ...gl.shaders import program
from ...gl.textures import texture_array
from ...gl.uniforms import camera_uniforms, model_offset, set_uniforms
from .representation import BillboardCloud

PROGRAM = "billboard:billboard.glsl"
PROGRAMS = tuple(ProgramVariant(PROGRAM, {"COUNT_ITERATIONS": counted})
                 for counted in (False, True))  # the draw-path variants (GLSL ES test)

#: (s, t) of a quad's four corners, counter-clockwise seen from the side u x v faces, so
#: gl_FrontFacing is true there; and its two triangles.
_QUAD_ST = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float64)
_QUAD_TRIANGLES = np.array([0, 1, 2, 0, 2, 3], np.uint32)
_COLOR_UNIT, _NORMAL_UNIT = 0, 1


@dataclass(frozen=True)
class BillboardRenderOptions:
    """The render options of billboard clouds (none yet: the baseline has no variants)."""


def quad_vertices(cloud: BillboardCloud, origin) -> np.ndarray:
    """(4P, 9) float32 vertices: corner relative to ``origin``, atlas (u, v, page), plane
    normal; corner k of rectangle p is row 4p + k.

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
    return np.concatenate([relative, atlas, normals], axis=-1).reshape(-1, 9).astype(np.float32)


def quad_indices(count: int) -> np.ndarray:
    """Two triangles per quad, indexing `quad_vertices`."""
    return (_QUAD_TRIANGLES[None] + 4 * np.arange(count, dtype=np.uint32)[:, None]).ravel()


class BillboardCloudDrawable(GLObjects):
    """GPU buffers and atlases of one BillboardCloud, drawable many times."""

    def __init__(self, ctx, cloud: BillboardCloud, options=None, instrument: bool = False):
        self.ctx, self.cloud = ctx, cloud
        self.origin = cloud.center  # float64: the quads are stored relative to it
        self.extra_attachments = 1 if instrument else 0
        self._upload_owned(lambda: self._upload(instrument))

    def _upload(self, instrument: bool) -> None:
        ctx, cloud = self.ctx, self.cloud
        # the atlases first: their sizes are checked against the GPU's limits before anything
        self.color = self.keep(texture_array(ctx, cloud.color, what="billboard colour atlas",
                                              srgb=True, mipmaps=True))
        self.normal = self.keep(texture_array(ctx, cloud.normal,
                                               what="billboard normal atlas", mipmaps=True))
        self.prog = program(ctx, PROGRAM, {"COUNT_ITERATIONS": instrument})
        vbo = self.keep(ctx.buffer(quad_vertices(cloud, self.origin).tobytes()))
        ibo = self.keep(ctx.buffer(quad_indices(cloud.count).tobytes()))
        self.vao = self.keep(ctx.vertex_array(
            self.prog, [(vbo, "3f 3f 3f", "in_position", "in_atlas", "in_plane_normal")],
            ibo, index_element_size=4))
        check_gl_error(ctx, f"uploading a billboard cloud of {cloud.count} rectangles")

    def draw(self, camera, light) -> None:
        set_uniforms(self.prog, camera_uniforms(camera) | model_offset(camera, self.origin)
                     | light.uniforms()
                     | {"u_color_atlas": _COLOR_UNIT, "u_normal_atlas": _NORMAL_UNIT})
        self.color.use(_COLOR_UNIT)
        self.normal.use(_NORMAL_UNIT)
        self.vao.render()

    def finish(self, frame) -> None:
        frame.stats["rectangles"] = frame.stats.get("rectangles", 0) + self.cloud.count


def drawable_spec() -> DrawableSpec:
    """How the technique draws its clouds (the package's `Technique` declares it)."""
    return DrawableSpec(BillboardCloud, BillboardCloudDrawable, BillboardRenderOptions)
