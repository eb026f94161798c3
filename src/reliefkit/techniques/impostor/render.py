"""Drawing an `OctahedralImpostor`: one draw plan of one quad (four corners the vertex
shader turns to face the camera, so the plan instances as it is), its three atlases and the
grid's uniforms; with ``shadows``, the "shadow-map" multi-pass kind draws the same quad from
the light (coverage and depth only) first."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...compact.encodings import encoding_of
from ...core.params import param
from ...core.technique import DrawableSpec, ProgramVariant
from ...render.mesh import SHADOW_MAP_SIZE
from ...render.plan import Attribute, DrawPlan, Geometry, MultiPass, Program, Texture
from .representation import OctahedralImpostor

PROGRAM = "impostor:impostor.glsl"
PROGRAMS = tuple(ProgramVariant(PROGRAM, {"COUNT_ITERATIONS": counted, "SHADOWS": shadows})
                 for counted in (False, True) for shadows in (False, True)) \
    + (ProgramVariant(PROGRAM, {"SHADOW_MAP": True}),
       ProgramVariant(PROGRAM, {"INSTANCED": True}))  # the draw-path variants

_CORNERS = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], np.float32)
_TRIANGLES = np.array([0, 1, 2, 0, 2, 3], np.uint32)


@dataclass(frozen=True)
class ImpostorRenderOptions:
    """The render options of octahedral impostors."""

    parallax_steps: int = param(8, "samples of each frame's depth along the ray, front to "
                                "back, then a linear step to where the ray meets it, so the "
                                "blended frames agree on where the surface is (0: the lookup "
                                "where the ray crosses each frame's plane)", kind="int",
                                lo=0, hi=16)
    shadows: bool = param(False, "shadows from a shadow map of the directional light, the "
                                 "impostor drawn from the light into it")


def impostor_plan(rep: OctahedralImpostor, options: ImpostorRenderOptions,
                  instrument: bool = False) -> DrawPlan:
    """The impostor's one draw: a quad around its centre (the plan's origin)."""
    multipass = None
    if options.shadows:
        multipass = MultiPass("shadow-map", {"caster": Program(PROGRAM, {"SHADOW_MAP": True})},
                              {"bounds": rep.bounds, "size": SHADOW_MAP_SIZE,
                               "bias": shadow_bias(rep)})
    return DrawPlan(
        name=f"octahedral impostor of {rep.grid} x {rep.grid} frames",
        program=Program(PROGRAM, {"COUNT_ITERATIONS": instrument,
                                  "SHADOWS": options.shadows}),
        geometry=Geometry({"in_corner": Attribute(_CORNERS)}, indices=_TRIANGLES),
        textures={"u_color_atlas": Texture(rep.color, srgb=True, mipmaps=True,
                                           what="impostor colour atlas",
                                           encoded=encoding_of(rep.color)),
                  "u_normal_atlas": Texture(rep.normal, mipmaps=True,
                                            what="impostor normal atlas",
                                            encoded=encoding_of(rep.normal)),
                  "u_depth_atlas": Texture(rep.depth, what="impostor depth atlas")},
        uniforms={"u_radius": rep.radius, "u_grid": rep.grid, "u_hemi": rep.hemi,
                  "u_frame_radius": rep.frame_radius, "u_frame_texels": float(rep.frame),
                  "u_parallax_steps": options.parallax_steps},
        origin=tuple(float(x) for x in rep.center), multipass=multipass)


def shadow_bias(rep: OctahedralImpostor) -> float:
    """The shadow map's depth bias: what the impostor may put its surface off by (a frame
    texel and a step of its uint8 depth), in the light camera's window depth
    (`render.shadows.light_camera` spans 3 half diagonals of the box around the sphere)."""
    uncertain = 2.0 * rep.frame_radius / rep.frame + 2.0 * rep.radius / 255.0
    return float(uncertain / (3.0 * np.sqrt(3.0) * rep.radius))


class ImpostorDrawable:
    """An OctahedralImpostor as its draw plan (`impostor_plan`)."""

    def __init__(self, rep: OctahedralImpostor, options: ImpostorRenderOptions | None = None,
                 instrument: bool = False):
        self.rep = rep
        self.extra_attachments = 1 if instrument else 0
        self.plans = [impostor_plan(rep, options or ImpostorRenderOptions(), instrument)]

    def finish(self, frame, stats: dict) -> None:
        frame.stats["impostor_frames"] = frame.stats.get("impostor_frames", 0) \
            + self.rep.grid ** 2


def drawable_spec() -> DrawableSpec:
    """How the technique draws its impostors (the package's `Technique` declares it)."""
    return DrawableSpec(OctahedralImpostor, ImpostorDrawable, ImpostorRenderOptions)
