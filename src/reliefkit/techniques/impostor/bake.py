"""Baking an octahedral impostor: the mesh drawn from every direction of the grid (one
upload, many orthographic views), each frame's colour, normal and depth dilated into its
padding and packed into one atlas per channel.

The views go through one `render.draw.Scene` rather than `render(mesh, cameras)`: the same
single upload, but each Frame is packed and dropped before the next is drawn, so memory
stays one frame plus the atlases (a list of 144 Frames of float64 positions would not).
"""

from __future__ import annotations

import numpy as np

from ...bake.project import FLAT_LIGHT, dilate
from ...colorspace import to_rgba8
from ...gl.context import get_context
from ...render.draw import Scene
from ...scene.camera import Camera
from ...scene.mesh import RenderMesh
from ...scene.views import bounds_radius
from . import octahedral
from .representation import OctahedralImpostor, check_grid, frame_size


def frame_camera(center, radius: float, frame_radius: float, direction, size: int) -> Camera:
    """The orthographic camera of one frame: looking along -``direction`` at the bounding
    sphere, its image the square of half side ``frame_radius`` in the frame's axes."""
    direction = np.asarray(direction, np.float64)
    right, up = octahedral.frame_basis(direction)
    eye = np.asarray(center, np.float64) + 2.0 * radius * direction
    return Camera(eye=tuple(eye), target=tuple(center), up=tuple(up), size=(size, size),
                  near=0.5 * radius, far=3.5 * radius, ortho_height=frame_radius)


def bake_impostor(mesh: RenderMesh, *, grid: int = 12, hemi: bool = False,
                  atlas_res: int = 1024, padding: int = 2, progress=None,
                  ctx=None) -> OctahedralImpostor:
    """Bake ``mesh`` into ``grid`` x ``grid`` frames on the full (or ``hemi``) octahedral map,
    in atlases of ``atlas_res`` texels rounded down to a multiple of ``grid``.
    ``progress(done, total)`` counts frames."""
    if not isinstance(mesh, RenderMesh):
        raise TypeError("bake_impostor needs a RenderMesh")
    grid = check_grid(grid, hemi)
    size = frame_size(atlas_res, grid, padding)
    bounds = np.asarray(mesh.bounds, np.float64)
    center, radius = bounds.mean(axis=0), bounds_radius(bounds)
    frame_radius = radius * size / (size - 2 * padding)
    side = grid * size
    color = np.zeros((side, side, 4), np.uint8)
    normal = np.zeros((side, side, 3), np.uint8)
    depth = np.zeros((side, side), np.uint8)
    directions = octahedral.frame_directions(grid, hemi)
    with Scene(mesh, ctx=ctx or get_context()) as scene:
        for j in range(grid):
            for i in range(grid):
                d = directions[j, i]
                frame = scene.frame(frame_camera(center, radius, frame_radius, d, size),
                                    FLAT_LIGHT)
                cell = (slice(j * size, (j + 1) * size), slice(i * size, (i + 1) * size))
                color[cell], normal[cell], depth[cell] = _frame_maps(frame, center, radius, d)
                if progress:
                    progress(j * grid + i + 1, grid * grid)
    return OctahedralImpostor(
        grid=grid, hemi=hemi, center=center, radius=radius, padding=padding, color=color,
        normal=normal, depth=depth, source_bounds=bounds,
        params={"source": mesh.name, "grid": grid, "hemi": hemi, "atlas_res": atlas_res,
                "padding": padding})


def _frame_maps(frame, center, radius: float, direction) -> tuple[np.ndarray, ...]:
    """One frame's colour (sRGB, coverage alpha), normal and depth texels, row 0 at the
    bottom, each empty texel holding its nearest covered texel's values."""
    rows = slice(None, None, -1)  # frames have row 0 at the top; textures at v = 0
    mask = frame.mask[rows]
    rgba = to_rgba8(np.where(mask[..., None], frame.color[rows], 0.0))
    height = np.where(mask, (frame.position[rows] - center) @ direction / radius, 0.0)
    depth = np.round(np.clip((height + 1.0) * 0.5, 0.0, 1.0) * 255.0).astype(np.uint8)
    normal = np.round((np.nan_to_num(frame.normal[rows]) + 1.0) * 127.5).astype(np.uint8)
    rgb, normal, depth = dilate(mask, rgba[..., :3], normal, depth)
    return np.concatenate([rgb, rgba[..., 3:]], axis=-1), normal, depth
