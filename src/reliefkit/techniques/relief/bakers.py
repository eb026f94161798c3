"""The relief bakers and their typed parameters (the CLI's ``bake --as relief...`` options)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...core.params import param
from ...core.technique import Sizing
from ...errors import UsageError
from .bake import DEFAULT_TOLERANCE, HEIGHTMAP_BOX, bake_relief, relief_from_heights
from .frustum import bake_relief_cube, bake_relief_frustum
from .render import ReliefRenderOptions

AXES = ("x", "y", "z", "-x", "-y", "-z")
# Safety radii cost about SAFETY_SECONDS_512 for a 512² field on a 2-core machine and grow
# with the texel count (docs/benchmarks.md); above these sides a bake would run for many
# minutes, so it is refused with a hint instead of leaving the user with a progress bar.
SAFETY_SECONDS_512 = 20.0  # 11 s measured on 2026-12-03, twice that on slower days
SAFETY_MAX_TEXELS = 1024 * 1024


def check_safety_work(width: int, height: int, parts: int = 1) -> None:
    """Refuse safety radii whose computation would take too long (estimate in the message)."""
    texels = width * height * parts
    if texels <= SAFETY_MAX_TEXELS:
        return
    minutes = SAFETY_SECONDS_512 * texels / 512**2 / 60
    raise UsageError(f"safety radii for {parts} x {width}x{height} texels would take about "
                     f"{minutes:.0f} minutes here (the limit is {SAFETY_MAX_TEXELS} texels); "
                     "bake with --no-safety and render with --method maxmip (exact, needs no "
                     "radii), or use a smaller --depth-res")


def wanted_safety(p) -> bool | None:
    """Whether to bake safety radii: ``--safety`` / ``--no-safety``, else (None) where robust
    would jump (`bake.wants_radii`); ``--safety-octants`` or ``--safety-tolerance`` ask for
    them. Refuses those two with ``--no-safety``: they would be silently ignored."""
    given = [flag for flag, on in (("--safety-octants", p.safety_octants),
                                   ("--safety-tolerance", p.safety_tolerance != DEFAULT_TOLERANCE))
             if on]
    if given and p.safety is False:
        raise UsageError(f"{' and '.join(given)} shape safety radii, which --no-safety leaves "
                         "out: drop one or the other")
    return True if given else p.safety


def _depth_res(default: int):
    return param(default, "heightfield resolution (longest side, texels)", lo=8, hi=8192)


def _color_res():
    return param(None, "colour/normal resolution, longest side (none: the depth resolution)",
                 kind="int", lo=2, hi=8192)


def _safety():
    return param(None, "bake safety radii, which robust jumps by on fields with W + H > "
                 f"{ReliefRenderOptions().exact_field} (smaller ones it draws with the exact "
                 "walk) (none: only where it jumps)", kind="bool")


def _octants():
    return param(False, "safety radii per direction octant (8 per texel): larger radii on "
                 "rough fields, 8x the radii's memory")


def _tolerance():
    return param(DEFAULT_TOLERANCE, "safety radii: ignored dip depth (height units, Fig. 12); "
                 "larger radii and fewer iterations for a bounded silhouette error (frusta and "
                 "cubes scale it by near/far)",
                 lo=0.0, hi=1.0)


def _axis():
    return param("y", "projection axis (the heightfield's up direction)", choices=AXES)


MESH_DEPTH_RES, MESH_AXIS = 256, "y"  # a mesh's orthographic relief when none are given


@dataclass(frozen=True)
class ReliefParams:
    depth_res: int | None = param(None, "heightfield resolution (longest side, texels) (none: "
                                  f"{MESH_DEPTH_RES}; a heightmap keeps its own size)",
                                  kind="int", lo=8, hi=8192)
    color_res: int | None = _color_res()
    safety: bool | None = _safety()
    safety_tolerance: float = _tolerance()
    safety_octants: bool = _octants()
    axis: str | None = param(None, "projection axis (the heightfield's up direction) (none: "
                             f"{MESH_AXIS}; a heightmap's is y)", kind="str", choices=AXES)
    box: tuple | None = param(None, "heightmaps only: world size SX,SY,SZ of the box (none: "
                              f"{','.join(f'{s:g}' for s in HEIGHTMAP_BOX)}); a mesh keeps "
                              "its own size",
                              kind="floats", count=3, lo=1e-9)


@dataclass(frozen=True)
class ReliefFrustumParams:
    depth_res: int = _depth_res(256)
    color_res: int | None = _color_res()
    safety: bool | None = _safety()
    safety_tolerance: float = _tolerance()
    safety_octants: bool = _octants()
    axis: str = _axis()
    spread: float = param(30.0, "reverse frustum: side tilt in degrees", lo=1.0, hi=75.0)
    clip: bool = param(True, "cut the drawn frustum to the mesh's bounds (§4.1)")


@dataclass(frozen=True)
class ReliefCubeParams:
    depth_res: int = _depth_res(128)
    color_res: int | None = _color_res()
    safety: bool | None = _safety()
    safety_tolerance: float = _tolerance()
    safety_octants: bool = _octants()


def bake_orthographic(source, p: ReliefParams, progress=None):
    safety = wanted_safety(p)
    heightmap = isinstance(source, np.ndarray)
    if not heightmap and p.box is not None:
        raise UsageError("--box sets a heightmap's world size; a mesh's relief keeps the "
                         "mesh's own size: drop --box (or scale the mesh)")
    given = [flag for flag, value in (("--depth-res", p.depth_res), ("--color-res", p.color_res),
                                      ("--axis", p.axis)) if value is not None]
    if heightmap and given:
        one = len(given) == 1
        raise UsageError(f"{' and '.join(given)} {'shapes' if one else 'shape'} a mesh's "
                         "relief; a heightmap keeps its own size and its y axis: drop "
                         f"{'it' if one else 'them'} (or resample the heightmap)")
    depth_res, axis = p.depth_res or MESH_DEPTH_RES, p.axis or MESH_AXIS
    if safety is not False:
        side = max(source.shape) if heightmap else depth_res
        check_safety_work(side, side)
    if heightmap:
        return relief_from_heights(source, size=p.box or HEIGHTMAP_BOX, safety=safety,
                                   tolerance=p.safety_tolerance, progress=progress,
                                   octants=p.safety_octants)
    return bake_relief(source, depth_res, p.color_res, axis, safety=safety,
                       tolerance=p.safety_tolerance, progress=progress,
                       octants=p.safety_octants)


def bake_frustum(source, p: ReliefFrustumParams, progress=None):
    safety = wanted_safety(p)
    if safety is not False:
        check_safety_work(p.depth_res, p.depth_res)
    return bake_relief_frustum(source, depth_res=p.depth_res, color_res=p.color_res,
                               axis=p.axis, spread_deg=p.spread, clip=p.clip, safety=safety,
                               tolerance=p.safety_tolerance, progress=progress,
                               octants=p.safety_octants)


def bake_cube(source, p: ReliefCubeParams, progress=None):
    safety = wanted_safety(p)
    if safety is not False:
        check_safety_work(p.depth_res, p.depth_res, parts=6)
    return bake_relief_cube(source, depth_res=p.depth_res, color_res=p.color_res,
                            safety=safety, tolerance=p.safety_tolerance, progress=progress,
                            octants=p.safety_octants)


#: The shootout sizes a relief cube by its heightfields' resolution (colour follows it),
#: without safety radii (a bake of minutes from 150 texels on two cores), drawn with the
#: exact maximum mipmap, which needs nothing baked (docs/relief.md: "Which method").
CUBE_SIZING = Sizing("depth_res: texels per side of each of the six heightfields", 8, 2048,
                     lambda n, mesh: {"depth_res": n, "safety": False},
                     render={"method": "maxmip"})
