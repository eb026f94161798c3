"""Drawing a `DisplacementMap` by slicing (§3): per frame the slice polygons are computed on
the CPU (`displacement_slices`), uploaded as one triangle list and drawn in one call with the
depth test; shaders/displacement.glsl keeps a fragment by the alpha test against its h.

The slices are alpha-tested opaque fragments, so their order does not matter (the depth test
keeps the nearest). The number of h slices K is the ``slices`` option, or automatic: a
spacing scale / K of at most one pixel's world footprint at the object (so the eye cannot see
between slices seen face-on), but no finer than one height texel's world size (finer slices
show nothing new), K clamped to [2, 512] (`auto_slices`), and halved while the frame would
need more than `displacement_slices.MAX_POLYGONS` polygons; the slices across the volume
(orthogonal u and v, screen planes) are then never closer than that spacing either, so a
displacement thinner than a pixel costs the base and a few slices, not 1 / scale of them.

The drawable is one draw plan (`render.plan`): the textures, the base as its geometry, and a
view hook that returns each camera's slice polygons as new vertex arrays. The hook's data
is the map as plain arrays (its base mesh, textures and tetrahedra), rebuilt per call.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from ...bake.uv_atlas import atlas_uniforms
from ...compact.encodings import encoding_of
from ...core.params import param
from ...core.technique import DrawableSpec, ProgramVariant
from ...render.instancing import per_object
from ...render.plan import Attribute, DrawPlan, Geometry, Program, Texture, ViewHook, ViewUpdate
from ...scene.mesh import RenderMesh
from .displacement import DisplacementMap, DisplacementVolume
from .displacement_slices import MODES, TooManyPolygons, base_triangles, slice_triangles
from .slices import auto_slice_count, pixel_world_size, projected_area

PROGRAM = "slicing:displacement.glsl"
PROGRAMS = (ProgramVariant(PROGRAM, {}), ProgramVariant(PROGRAM, {"UNLIT": True}))
ALPHA_TESTS = ("fill", "bound")
AUTO_MIN, AUTO_MAX = 2, 512


@dataclass(frozen=True)
class DisplacementRenderOptions:
    """The render options of displacement maps."""

    slicing: str = param("orthogonal", "slice planes: offset surfaces h = const (§3.1), the "
                         "per-triangle direction most perpendicular to the view (§3.2), or "
                         "planes facing the screen cut exactly through the volume (§3.3)",
                         choices=MODES)
    slices: int | None = param(None, "h slices K (none: automatic from the size on screen, "
                               f"clamped to [{AUTO_MIN}, {AUTO_MAX}])", kind="int", lo=1,
                               hi=4096)
    alpha_test: str = param("fill", "surface slicing: draw where height >= h (fill, "
                            "Dietrich) or only within one slice of it (bound, Schaufler)",
                            choices=ALPHA_TESTS)
    unlit: bool = param(False, "the colour texture without lighting")


def texel_world_size(rep: DisplacementMap) -> float:
    """World size of one height texel on the base (the finest of its two directions)."""
    base = rep.base
    tris = np.asarray(base.indices, np.int64)
    p = base.world_positions[tris]
    uv = np.asarray(base.uvs, np.float64)[tris]
    area = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1).sum()
    d1, d2 = uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0]
    uv_area = 0.5 * np.abs(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]).sum()
    per_uv = math.sqrt(area / uv_area) if uv_area > 0 else math.sqrt(area)
    h, w = rep.height.shape
    return per_uv / max(w * rep.tile[0], h * rep.tile[1])


def finest_spacing(rep: DisplacementMap, camera) -> float:
    """The closest useful slice spacing: one pixel's world size at the object's centre, but
    no finer than one height texel's world size."""
    lo, hi = rep.bounds
    return max(pixel_world_size(camera, 0.5 * (lo + hi)), texel_world_size(rep))


def auto_slices(rep: DisplacementMap, camera) -> int:
    """K = ceil(scale / spacing), spacing = `finest_spacing`, clamped to [AUTO_MIN,
    AUTO_MAX] (`slices.auto_slice_count`)."""
    lo, hi = rep.bounds
    return auto_slice_count(rep.scale, camera, 0.5 * (lo + hi), texel_world_size(rep),
                            maximum=AUTO_MAX)


def vertex_arrays(tris, origin, layers) -> dict:
    """The shader's vertex arrays (float32) of slice triangles ``tris``: position relative
    to ``origin``, (u, v, h), d/du, d/dv, d/dh, the surface layer (``layers`` (F,) per base
    triangle: `DisplacementMap.surface_layers`)."""
    j = tris.jacobian
    arrays = {"in_position": tris.positions - origin, "in_uvh": tris.box,
              "in_ju": j[:, :, 0], "in_jv": j[:, :, 1], "in_jh": j[:, :, 2],
              "in_layer": layers[tris.triangle]}
    return {name: np.ascontiguousarray(a, np.float32) for name, a in arrays.items()}


class DisplacementDrawable:
    """The displacement texture as one draw plan; its slices recomputed for every camera by
    the plan's view hook."""

    def __init__(self, rep: DisplacementMap, options: DisplacementRenderOptions | None = None,
                 instrument: bool = False):
        self.rep = rep
        self.options = opts = options or DisplacementRenderOptions()
        self.extra_attachments = 1 if instrument else 0
        lo, hi = rep.bounds
        origin = 0.5 * (lo + hi)
        test = opts.alpha_test if opts.slicing == "surface" else "fill"
        textures = {"u_height": Texture(rep.height, filter="nearest",
                                        what="displacement height",
                                        encoded=encoding_of(rep.height)),
                    "u_color": Texture(rep.color, wrap=("repeat",) * 3 if rep.wrap
                                       else ("clamp",) * 3, what="displacement colour",
                                       encoded=encoding_of(rep.color))}
        if rep.surface is not None:
            textures["u_surface"] = Texture(rep.surface.rgba8, "2d_array", srgb=True,
                                            what="displacement surface materials",
                                            encoded=encoding_of(rep.surface.rgba8))
        h, w = rep.height.shape
        layers = rep.surface_layers()
        volume = None if opts.slicing == "surface" else rep.volume()
        base = vertex_arrays(base_triangles(rep), origin, layers)
        self.plans = [DrawPlan(
            "displacement slices",
            Program(PROGRAM, {"UNLIT": opts.unlit, "COUNT_ITERATIONS": instrument}),
            Geometry({name: Attribute(a) for name, a in base.items()}), textures,
            # without a surface its sampler names a unit no texture of the plan uses
            {"u_hf_size": (w, h), "u_wrap": rep.wrap, "u_tile": tuple(rep.tile),
             "u_test": ALPHA_TESTS.index(test)} | atlas_uniforms(rep.surface, len(textures)),
            origin=tuple(float(x) for x in origin),
            per_view=ViewHook(f"{__name__}:slices_view", {
                "displacement": _map_data(rep), "layers": layers,
                "volume": None if volume is None else {
                    f.name: getattr(volume, f.name) for f in fields(volume)},
                "slicing": opts.slicing, "slices": opts.slices, "alpha_test": test}))]

    def finish(self, frame, stats: dict) -> None:
        frame.stats.update(stats)


def _map_data(rep: DisplacementMap) -> dict:
    """What slicing reads of ``rep``, as plain data (`_map` rebuilds it)."""
    base = rep.base
    return {"positions": base.positions, "origin": tuple(float(x) for x in base.origin),
            "indices": base.indices, "normals": base.normals, "uvs": base.uvs,
            "color": rep.color, "height": rep.height, "scale": rep.scale,
            "tile": tuple(rep.tile), "wrap": rep.wrap}


def _map(data: dict) -> DisplacementMap:
    """The map of `_map_data` (its surface left out: the hook is given the layers)."""
    positions = data["positions"]
    base = RenderMesh(positions, data["indices"], data["normals"],
                      np.broadcast_to(np.float32(1.0), (len(positions), 4)), data["uvs"],
                      origin=data["origin"])
    return DisplacementMap(base, data["color"], data["height"], data["scale"], data["tile"],
                           data["wrap"])


@per_object("it cuts new slice polygons through the object's own shell for "
            "each camera")
def slices_view(plan, camera, light, *, displacement, layers, volume, slicing, slices,
                alpha_test) -> ViewUpdate:
    """View hook: this camera's slice polygons (`displacement_slices`) as the vertex
    arrays; their count K is ``slices`` or automatic (see the module docstring)."""
    rep = _map(displacement)
    volume = None if volume is None else DisplacementVolume(**volume)
    count = slices if slices is not None else auto_slices(rep, camera)
    finest = finest_spacing(rep, camera) if slices is None else 0.0
    while True:
        try:
            tris = slice_triangles(rep, camera, slicing, count, volume, finest)
            break
        except TooManyPolygons:
            if slices is not None or count <= AUTO_MIN:
                raise
            count = max(AUTO_MIN, count // 2)  # automatic: halve until the slices fit
    bound = 1.0 / (count - 1) if count > 1 else 1.0
    stats = {"slices": int(count), "slicing": slicing, "alpha_test": alpha_test,
             "slice_planes": int(tris.slices), "slice_polygons": int(tris.polygons),
             "slice_triangles": int(tris.triangle_count),
             "slice_spacing": float(tris.spacing),
             "fill_pixels": projected_area(tris.positions, camera),
             **{f"direction_{k}": v for k, v in tris.directions.items()}}
    return ViewUpdate(uniforms={"u_bound": float(bound)},
                      attributes=vertex_arrays(tris, np.asarray(plan.origin, np.float64),
                                               layers),
                      stats=stats)


def drawable_spec() -> DrawableSpec:
    return DrawableSpec(DisplacementMap, DisplacementDrawable, DisplacementRenderOptions)
