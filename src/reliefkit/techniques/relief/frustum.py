"""Reverse-perspective relief textures (§4): one fitted frustum, or six splitting a cube.

A reverse frustum's centre of projection lies *beyond* the bottom of the object, so the
rays that build the heightfield converge away from the viewer and reach the object's sides
(Fig. 9). ``box_to_world`` is then the inverse of a perspective projection: lines stay
lines in box coordinates, so the relief shader is unchanged.
"""

from __future__ import annotations

import numpy as np

from ...bake.project import axis_frame, cube_face_frames, project_mesh
from ...core.transforms import translation
from ...errors import UsageError
from ...scene.mesh import RenderMesh
from .bake import (
    BORDER_TEXELS,
    DEFAULT_TOLERANCE,
    MIN_THICKNESS,
    bake_through,
    check_not_edge_on,
    flat_axis,
)
from .representation import ReliefObject, ReliefTexture

UNIT_FROM_NDC = np.array([[0.5, 0, 0, 0.5], [0, 0.5, 0, 0.5], [0, 0, 0.5, 0.5], [0, 0, 0, 1]])


def frustum_matrix(apex, frame, tan_u: float, tan_v: float, near: float,
                   far: float) -> np.ndarray:
    """box_to_world of a frustum with apex ``apex`` opening along ``frame[2]``.

    Box coordinate h = 0 is the near plane (distance ``near`` from the apex), h = 1 the
    far plane; u, v span ``±tan`` of the distance along ``frame[0]`` and ``frame[1]``.
    """
    if not 0 < near < far:
        raise UsageError(f"frustum needs 0 < near < far, got {near}, {far}")
    view = np.eye(4)
    axes = np.asarray(frame, dtype=np.float64) * np.array([[1.0], [1.0], [-1.0]])
    view[:3, :3] = axes  # looking from the world origin; moved to the apex afterwards, exactly
    proj = np.zeros((4, 4))  # OpenGL perspective: eye looks down -z, w = distance > 0
    proj[0, 0], proj[1, 1] = 1.0 / tan_u, 1.0 / tan_v
    proj[2, 2], proj[2, 3] = (far + near) / (near - far), 2.0 * far * near / (near - far)
    proj[3, 2] = -1.0
    return translation(apex) @ np.linalg.inv(UNIT_FROM_NDC @ proj @ view)


def fit_reverse_frustum(mesh: RenderMesh, axis: str = "y", spread_deg: float = 30.0,
                        depth_res: int = 256) -> tuple[np.ndarray, tuple[int, int]]:
    """A reverse frustum around ``mesh`` seen from ``axis``, sides tilted by ``spread_deg``.

    The apex lies below the mesh so that the frustum's side planes make ``spread_deg``
    with ``axis`` across the narrower side; returns (box_to_world, (W, H)).
    """
    if not 1.0 <= spread_deg <= 75.0:
        raise UsageError(f"frustum spread must be between 1 and 75 degrees, got {spread_deg}")
    check_not_edge_on(mesh, axis)
    frame = axis_frame(axis)
    local = mesh.world_positions @ frame.T
    lo, hi = local.min(axis=0), local.max(axis=0)
    centre = (lo + hi) / 2
    half = np.maximum((hi - lo) / 2, 1e-9 * float(np.max(hi - lo)))
    apex_distance = min(half[0], half[1]) / np.tan(np.radians(spread_deg))
    apex_local = np.array([centre[0], centre[1], lo[2] - apex_distance])
    rel = local - apex_local
    tans = np.abs(rel[:, :2]).max(axis=0) / rel[:, 2].min()
    # square texels on the base; a ring of empty texels around the footprint
    longest = int(np.argmax(tans))
    size = [depth_res, depth_res]
    size[1 - longest] = max(4, int(np.ceil(depth_res * tans[1 - longest] / tans[longest])))
    tans = tans * np.array([s / (s - 2 * BORDER_TEXELS) for s in size])
    depth = max(hi[2] - lo[2], MIN_THICKNESS * 2 * max(half[0], half[1]))  # flat: thin
    near, far = apex_distance - 0.01 * depth, apex_distance + 1.01 * depth
    box_to_world = frustum_matrix(frame.T @ apex_local, frame, tans[0], tans[1], near, far)
    return box_to_world, (size[0], size[1])


def bake_relief_frustum(mesh: RenderMesh, frustum: np.ndarray | None = None, *,
                        depth_res: int = 256, color_res: int | None = None, axis: str = "y",
                        spread_deg: float = 30.0, clip: bool = True,
                        safety: bool | None = None, tolerance: float = DEFAULT_TOLERANCE,
                        progress=None,
                        ctx=None, octants: bool = False) -> ReliefTexture:
    """Relief texture through a reverse frustum (a user's box_to_world, or a fitted one).

    With ``clip`` the proxy drawn at render time is the frustum intersected with the
    mesh's bounding box (§4.1), which rasterizes fewer fragments for the same picture.
    """
    if frustum is None:
        frustum, size = fit_reverse_frustum(mesh, axis, spread_deg, depth_res)
    else:
        frustum = np.asarray(frustum, dtype=np.float64)
        if frustum.shape != (4, 4) or not np.isfinite(frustum).all():
            raise UsageError("frustum must be a finite 4x4 box_to_world matrix")
        size = (depth_res, depth_res)
    color_size = size if color_res is None else tuple(
        max(2, round(s * color_res / depth_res)) for s in size)
    lo, hi = mesh.bounds
    pad = 2.0 * (hi - lo).max() / depth_res  # bilinear ramps reach half a texel outside
    params = {"projection": "reverse-frustum", "axis": axis, "spread_deg": spread_deg,
              "depth_res": depth_res, "color_res": color_res or depth_res, "source": mesh.name}
    clip_bounds = np.stack([lo - pad, hi + pad]) if clip else None
    return bake_through(mesh, frustum, size, color_size, safety=safety, tolerance=tolerance,
                        progress=progress, params=params, clip_bounds=clip_bounds, ctx=ctx,
                        octants=octants)


def cube_frusta(mesh: RenderMesh, margin: float = 0.02, near_fraction: float = 0.02,
                depth_res: int = 128, ctx=None) -> dict[str, np.ndarray]:
    """Six box_to_world matrices: pyramids from the bounding cube's centre to its faces.

    A pyramid's h is perspective depth: linear in 1 / distance from the centre, so with the
    near plane close to the centre the outer half of the pyramid, where the surface is,
    gets a sliver of h (2% near: the vehicle's heights all in [0.95, 1]). The safety radii's
    tolerance is in h units, and there 0.01 spans a third of the object: robust missed up
    to 24% of the vehicle's pixels. So each pyramid is first rasterized with the near plane
    at ``near_fraction`` of the half cube, then cut at 90% of the distance of its innermost
    covered texel, floored to 1/32 of the half cube (the outermost surface of every texel
    lies beyond the cut: nothing is lost). `bake.far_tolerance` then scales the tolerance.
    """
    lo, hi = mesh.bounds
    centre = (lo + hi) / 2
    half = float((hi - lo).max()) / 2 * (1 + margin)
    frusta = {}
    for face, frame in cube_face_frames().items():
        near = near_fraction * half
        probe = frustum_matrix(centre, frame, 1.0, 1.0, near, half)
        height = project_mesh(mesh, probe, (depth_res, depth_res), ctx).height
        covered = height > 0.0
        if covered.any():
            inner = probe @ np.array([0.5, 0.5, float(height[covered].min()), 1.0])
            distance = float(np.dot(inner[:3] / inner[3] - centre, frame[2]))
            # floored to 1/32 of the half cube: the same cut for the same mesh anywhere
            near = max(near, np.floor(32 * 0.9 * distance / half) / 32 * half)
        frusta[face] = frustum_matrix(centre, frame, 1.0, 1.0, near, half)
    return frusta


def bake_relief_cube(mesh: RenderMesh, *, depth_res: int = 128, color_res: int | None = None,
                     safety: bool | None = None, tolerance: float = DEFAULT_TOLERANCE,
                     progress=None, ctx=None, octants: bool = False) -> ReliefObject:
    """Six reverse-perspective heightfields splitting the bounding cube (§4.2, Fig. 10)."""
    flat = flat_axis(mesh)
    if flat is not None:  # its six pyramids meet where a flat mesh lies
        raise UsageError(f"the mesh is flat across {flat}: a relief cube's six frusta meet at "
                         f"its bounding cube's centre, in its plane, and none sees it; bake it "
                         f"as relief --axis {flat}")
    size = (depth_res, depth_res)
    color_size = size if color_res is None else (color_res, color_res)
    parts = []
    for k, (face, box_to_world) in enumerate(cube_frusta(mesh, depth_res=depth_res,
                                                             ctx=ctx).items()):
        params = {"projection": "cube-frustum", "face": face, "depth_res": depth_res,
                  "color_res": color_res or depth_res, "source": mesh.name}
        part_progress = None if progress is None else (
            lambda done, total, k=k: progress(k * total + done, 6 * total))
        parts.append(bake_through(mesh, box_to_world, size, color_size, safety=safety,
                                  tolerance=tolerance, progress=part_progress, params=params,
                                  zero_border=False, ctx=ctx, octants=octants))
    return ReliefObject(parts=parts, params={"projection": "cube", "source": mesh.name},
                        source_bounds=mesh.bounds)
