"""Baking relief textures: project a mesh onto the bottom face of a box or reverse frustum.

The projection runs on the GPU through the core's `reliefkit.bake.project`: the depth
buffer keeps the highest surface and height = 1 - window depth (§3).
"""

from __future__ import annotations

import numpy as np

from ...bake.project import axis_frame, dilate, project_mesh
from ...colorspace import srgb_decode, to_rgba8
from ...core.transforms import transform_points
from ...errors import UsageError
from ...scene.mesh import RenderMesh
from .render import ReliefRenderOptions, robust_jumps
from .representation import ReliefTexture

BORDER_TEXELS = 1.5      # empty margin around the footprint (the border ring must be 0)
HEIGHT_MARGIN = 0.01     # the box bottom lies this fraction of the height below the mesh
# A box at least this fraction of its footprint deep: a flat mesh (a decal, a sheet) seen
# from above had a box 1e-9 deep, whose projection lost its heights to float precision
# (refused as empty) or drew nothing.
MIN_THICKNESS = 1e-3
# Safety-radius tolerance of bakes (height units, Fig. 12): with 0 most texels of a bilinear
# terrain get radius 0 (every non-planar patch bends down along some direction); 1% of the
# box height keeps radii growing with resolution at a bounded silhouette error.
DEFAULT_TOLERANCE = 0.01
HEIGHTMAP_BOX = (2.0, 0.5, 2.0)  # world size (x, height, z) of a heightmap's box by default


def flat_axis(mesh: RenderMesh) -> str | None:
    """The world axis ('x', 'y' or 'z') a flat mesh (a decal, a sheet) is flat across; None
    for a mesh with depth in every direction."""
    ext = np.ptp(mesh.world_positions, axis=0)
    flat = int(np.argmin(ext))
    return "xyz"[flat] if ext[flat] <= 1e-6 * float(ext.max()) else None


def check_not_edge_on(mesh: RenderMesh, axis: str) -> None:
    """Refuse, naming the axis to bake along, a flat mesh seen edge-on along ``axis``: it
    covers no texel, and the bake ended in "the heightfield is empty" without saying why."""
    flat = flat_axis(mesh)
    if flat is not None and axis.lstrip("+-") != flat:
        raise UsageError(f"the mesh is flat across {flat}: seen along --axis {axis} it is "
                         f"edge-on and covers nothing; bake it along --axis {flat}")


def ortho_box(mesh: RenderMesh, axis: str, depth_res: int) -> tuple[np.ndarray, tuple[int, int]]:
    """box_to_world of the bounding box seen along ``axis`` and the (W, H) of its heightfield.

    The longer side gets ``depth_res`` square texels; a ring of empty texels surrounds the
    footprint and the bottom sits slightly below the mesh so that every covered texel has
    a positive height.
    """
    if depth_res < 8:
        raise UsageError(f"depth resolution must be at least 8, got {depth_res}")
    frame = axis_frame(axis)
    local = mesh.world_positions @ frame.T
    lo, hi = local.min(axis=0), local.max(axis=0)
    ext = np.maximum(hi - lo, 1e-9 * max(float(np.max(hi - lo)), 1e-30))
    ext[2] = max(ext[2], MIN_THICKNESS * max(ext[0], ext[1]))  # a flat mesh: a thin box
    texel = max(ext[0], ext[1]) / (depth_res - 2 * BORDER_TEXELS)
    size = [depth_res if ext[k] >= ext[1 - k] else
            int(min(depth_res, np.ceil(ext[k] / texel + 2 * BORDER_TEXELS))) for k in (0, 1)]
    size = [max(s, 4) for s in size]
    centre = (lo + hi) / 2
    span = np.array([size[0] * texel, size[1] * texel, ext[2] * (1 + 2 * HEIGHT_MARGIN)])
    origin_local = np.array([centre[0] - span[0] / 2, centre[1] - span[1] / 2,
                             lo[2] - ext[2] * HEIGHT_MARGIN])
    box_to_world = np.eye(4)
    box_to_world[:3, :3] = frame.T * span
    box_to_world[:3, 3] = frame.T @ origin_local
    return box_to_world, (size[0], size[1])


def _orient_normals(normal: np.ndarray, box_to_world: np.ndarray) -> np.ndarray:
    """Unit normals turned to face the viewer of the bake (up the box's h lines)."""
    h, w = normal.shape[:2]
    u, v = np.meshgrid((np.arange(w) + 0.5) / w, (np.arange(h) + 0.5) / h)
    top = transform_points(box_to_world, np.stack([u, v, np.full_like(u, 0.9)], -1))
    bottom = transform_points(box_to_world, np.stack([u, v, np.full_like(u, 0.1)], -1))
    up = top - bottom
    n = normal.astype(np.float64)
    flip = (n * up).sum(-1) < 0
    n[flip] *= -1
    length = np.linalg.norm(n, axis=-1, keepdims=True)
    up_unit = up / np.linalg.norm(up, axis=-1, keepdims=True)
    return np.where(length > 1e-6, n / np.maximum(length, 1e-12), up_unit).astype(np.float32)


def _zero_border(height: np.ndarray) -> np.ndarray:
    height = height.copy()
    height[0, :] = height[-1, :] = 0.0
    height[:, 0] = height[:, -1] = 0.0
    return height


def _color_size(depth_size, depth_res: int, color_res: int | None) -> tuple[int, int]:
    if color_res is None:
        return tuple(depth_size)
    scale = color_res / depth_res
    return tuple(max(2, int(round(s * scale))) for s in depth_size)


def wants_radii(safety: bool | None, size, octants: bool = False) -> bool:
    """``safety`` as given, or by default (None) whether robust's default render jumps by
    safety radii on a field of ``size`` (W, H), or ``octants`` asks for them. Smaller fields
    are drawn with the exact walk, which never reads them: the radii of a cube's six 128²
    faces took minutes for the same pixels."""
    if safety is None:
        return octants or robust_jumps(*size, ReliefRenderOptions())
    return bool(safety)


def far_tolerance(box_to_world: np.ndarray, tolerance: float) -> float:
    """The safety tolerance in h units that bounds, at a frustum's far end, the world depth
    that ``tolerance`` bounds in an orthographic box as deep (its fraction of the depth).

    A frustum's h is perspective depth, most compressed at the far end: there one unit of h
    spans far / near times the box's mean depth per unit, so the tolerance shrinks by
    near / far (1 for a box; 1/4 for a pyramid of the cube cut at a quarter of its height).
    """
    if not np.any(box_to_world[3, :3]):  # affine: h is uniform, the tolerance as given
        return float(tolerance)

    m = np.asarray(box_to_world, dtype=np.float64)
    p0, p1 = m @ [0.5, 0.5, 0.0, 1.0], m @ [0.5, 0.5, 1.0, 1.0]  # the box's centre line
    depth = np.linalg.norm(p1[:3] / p1[3] - p0[:3] / p0[3])
    dp = m[:, 2]  # d p / d h; the world point is p[:3] / p[3], differentiated exactly at h = 1
    far_rate = np.linalg.norm((dp[:3] * p1[3] - p1[:3] * dp[3]) / p1[3] ** 2)
    return float(tolerance) * min(1.0, float(depth / far_rate))


def bake_through(mesh: RenderMesh, box_to_world: np.ndarray, depth_size, color_size, *,
                 safety: bool | None = None, tolerance: float = DEFAULT_TOLERANCE,
                 progress=None, params: dict | None = None, zero_border: bool = True,
                 clip_bounds=None, ctx=None, octants: bool = False) -> ReliefTexture:
    """Bake ``mesh`` through any box/frustum matrix at the given resolutions.

    ``zero_border`` empties the outer ring of texels so every ray enters above the surface
    (§3, footnote 1); the six frusta of a cube share their sides and keep it. ``safety``:
    bake safety radii, or by default (None) where robust would jump (`wants_radii`).
    """
    for label, (w, h) in (("depth", depth_size), ("color", color_size)):
        if w > 8192 or h > 8192:
            raise UsageError(f"{label} resolution {w}x{h} is above 8192")
    height = np.clip(project_mesh(mesh, box_to_world, depth_size, ctx).height, 0.0, 1.0)
    colors = project_mesh(mesh, box_to_world, color_size, ctx)
    # pad colour and normals into the empty texels: lookups near a footprint's edge stay opaque
    color, normal = dilate(colors.mask, colors.color, colors.normal)
    if zero_border:
        height = _zero_border(height)
    relief = ReliefTexture(height=height, color=to_rgba8(color),
                           normal=_orient_normals(normal, box_to_world),
                           box_to_world=box_to_world, clip_bounds=clip_bounds,
                           source_bounds=mesh.bounds, params=dict(params or {}))
    if wants_radii(safety, depth_size, octants):
        from .safety import safety_radii  # numba: slow to import

        tolerance = far_tolerance(box_to_world, tolerance)  # a frustum's h is not uniform
        relief.safety = safety_radii(height, tolerance=tolerance, progress=progress,
                                     octants=octants)
        relief.params["safety_tolerance"] = float(tolerance)
    return relief


def bake_relief(mesh: RenderMesh, depth_res: int = 256, color_res: int | None = None,
                axis: str = "y", *, safety: bool | None = None,
                tolerance: float = DEFAULT_TOLERANCE, progress=None, ctx=None,
                octants: bool = False) -> ReliefTexture:
    """Orthographic relief texture of ``mesh`` seen from above along ``axis`` (§3)."""
    check_not_edge_on(mesh, axis)
    box_to_world, depth_size = ortho_box(mesh, axis, depth_res)
    color_size = _color_size(depth_size, depth_res, color_res)
    params = {"projection": "orthographic", "axis": axis, "depth_res": depth_res,
              "color_res": color_res or depth_res, "source": mesh.name}
    return bake_through(mesh, box_to_world, depth_size, color_size, safety=safety,
                        tolerance=tolerance, progress=progress, params=params, ctx=ctx,
                        octants=octants)


def relief_from_heights(heights, color=None, size=HEIGHTMAP_BOX, *,
                        safety: bool | None = None, tolerance: float = DEFAULT_TOLERANCE,
                        progress=None, octants: bool = False) -> ReliefTexture:
    """A relief texture straight from a height array (values scaled to [0, 1]).

    Orientation is that of a map seen from above: row 0 (an image's top row) is the far
    edge, -z, and columns run along +x, so with north up (-z) and east right (+x) the picture
    reads as the image does. ``size`` is the world extent (x, y, z) of the box: u along +x,
    v along +z, h along +y, centred on the origin with the bottom at y = 0. ``color`` is an
    (H', W', 3|4) uint8 sRGB or float linear image in the same orientation; by default the
    heights are shaded with a terrain colour ramp.
    """
    h = np.asarray(heights, dtype=np.float64)
    if h.ndim != 2 or min(h.shape) < 4:
        raise UsageError(f"a heightmap must be a 2D array of at least 4x4, got {h.shape}")
    if not np.isfinite(h).all():
        raise UsageError("the heightmap contains NaN or Inf values")
    span = h.max() - h.min()
    h = (h - h.min()) / span if span > 0 else np.zeros_like(h)
    h = np.clip(h * (1 - HEIGHT_MARGIN) + HEIGHT_MARGIN, 0, 1).astype(np.float32)
    sx, sy, sz = (float(s) for s in size)
    box_to_world = np.array([[sx, 0, 0, -sx / 2], [0, 0, sy, 0], [0, sz, 0, -sz / 2],
                             [0, 0, 0, 1.0]])
    color8 = _heightmap_color(h, color)
    normal = heightfield_normals(h, box_to_world)
    relief = ReliefTexture(height=h, color=color8, normal=normal, box_to_world=box_to_world,
                           params={"projection": "orthographic", "source": "heightmap"})
    if wants_radii(safety, relief.depth_resolution, octants):
        from .safety import safety_radii  # numba: slow to import

        relief.safety = safety_radii(h, tolerance=tolerance, progress=progress,
                                     octants=octants)
        relief.params["safety_tolerance"] = float(tolerance)
    return relief


def heightfield_normals(height: np.ndarray, box_to_world: np.ndarray) -> np.ndarray:
    """World-space normals of an affine-box heightfield by central differences."""
    rows, cols = height.shape
    dh_dv, dh_du = np.gradient(height.astype(np.float64), 1.0 / rows, 1.0 / cols)
    axes = box_to_world[:3, :3]
    tangent_u = axes[:, 0][None, None] + dh_du[..., None] * axes[:, 2]
    tangent_v = axes[:, 1][None, None] + dh_dv[..., None] * axes[:, 2]
    n = np.cross(tangent_u, tangent_v)
    if np.linalg.det(axes) < 0:
        n = -n
    return (n / np.linalg.norm(n, axis=-1, keepdims=True)).astype(np.float32)


# sRGB colour stops for heightmaps without a colour image: water, grass, rock, snow
_RAMP_STOPS = np.array([0.0, 0.25, 0.55, 0.8, 1.0])
_RAMP_SRGB = np.array([[40, 90, 110], [90, 140, 60], [140, 120, 80], [150, 150, 150],
                       [245, 245, 250]]) / 255.0


def height_ramp(h: np.ndarray) -> np.ndarray:
    """(H, W, 3) linear colours for heights in [0, 1]."""
    rgb = np.stack([np.interp(h, _RAMP_STOPS, _RAMP_SRGB[:, k]) for k in range(3)], -1)
    return srgb_decode(rgb).astype(np.float32)


def _heightmap_color(h: np.ndarray, color) -> np.ndarray:
    if color is None:
        return to_rgba8(np.concatenate([height_ramp(h), np.ones(h.shape + (1,))], -1))
    c = np.asarray(color)
    if c.ndim != 3 or c.shape[2] not in (3, 4):
        raise UsageError(f"color must be an (H, W, 3|4) image, got {c.shape}")
    if c.shape[2] == 3:
        alpha = np.full(c.shape[:2] + (1,), 255 if c.dtype == np.uint8 else 1.0, c.dtype)
        c = np.concatenate([c, alpha], -1)
    return c.astype(np.uint8) if c.dtype == np.uint8 else to_rgba8(c.astype(np.float32))
