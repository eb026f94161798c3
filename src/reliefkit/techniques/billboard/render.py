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

from ...compact.encodings import encoding_of
from ...core.technique import DrawableSpec, ProgramVariant
from ...render.plan import Attribute, DrawPlan, Geometry, Program, Texture
from .quads import quad_attributes, quad_indices
from .representation import BillboardCloud

PROGRAM = "billboard:billboard.glsl"
PROGRAMS = tuple(ProgramVariant(PROGRAM, {"COUNT_ITERATIONS": counted, "INSTANCED": placed})
                 for counted in (False, True)
                 for placed in (False, True))  # the draw-path variants (GLSL ES test)


@dataclass(frozen=True)
class BillboardRenderOptions:
    """The render options of billboard clouds (none yet: the baseline has no variants)."""


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

    #: its instrumented variant counts fragments only: its shader has no loop
    counts_iterations = False

    def __init__(self, cloud: BillboardCloud, options=None, instrument: bool = False):
        self.cloud = cloud
        self.extra_attachments = 1 if instrument else 0
        self.plans = [cloud_plan(cloud, instrument)]

    def finish(self, frame, stats: dict) -> None:
        frame.stats["rectangles"] = frame.stats.get("rectangles", 0) + self.cloud.count


def drawable_spec() -> DrawableSpec:
    """How the technique draws its clouds (the package's `Technique` declares it)."""
    return DrawableSpec(BillboardCloud, BillboardCloudDrawable, BillboardRenderOptions)
