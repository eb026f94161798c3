"""Mesh projection through any box: what relief textures, billboard boxes and depth images bake.

A box is given by ``box_to_world``, a 4x4 map from box coordinates (u, v, h) in [0, 1]^3 to
world space (affine for a box, projective for a reverse-perspective frustum). The mesh is
rasterized through the matrix that maps box coordinates to clip space (x = 2u - 1,
y = 2v - 1, z = 1 - 2h), so the depth buffer keeps the surface with the largest h: its
height is 1 - window depth. Images come back with row 0 at v = 0 (texture convention).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.transforms import box_center, invert_box
from ..errors import UsageError
from ..render import render
from ..scene.camera import MatrixCamera
from ..scene.light import DirectionalLight

AXES = {"x": 0, "y": 1, "z": 2}
CUBE_FACES = ("x", "-x", "y", "-y", "z", "-z")
FLAT_LIGHT = DirectionalLight(intensity=0.0, ambient=1.0, specular=0.0)  # colour = base colour

# box (u, v, h) -> clip: x = 2u - 1, y = 2v - 1, z = 1 - 2h (the top is nearest)
BOX_TO_CLIP = np.array([[2.0, 0, 0, -1], [0, 2.0, 0, -1], [0, 0, -2.0, 1], [0, 0, 0, 1]])


def axis_frame(axis: str) -> np.ndarray:
    """Rows u, v, h: a right-handed frame whose h points along ``axis`` ('y', '-z', ...)."""
    sign = -1.0 if axis.startswith("-") else 1.0
    name = axis.lstrip("+-")
    if name not in AXES:
        raise UsageError(f"axis must be one of x, y, z, -x, -y, -z; got {axis!r}")
    h = np.zeros(3)
    h[AXES[name]] = sign
    u = np.zeros(3)
    u[0 if name != "x" else 2] = 1.0
    return np.stack([u, np.cross(h, u), h])


def cube_face_frames() -> dict[str, np.ndarray]:
    """The six faces of a cube, each with its `axis_frame` (h pointing out of the face)."""
    return {face: axis_frame(face) for face in CUBE_FACES}


@dataclass(frozen=True)
class Projection:
    """What a mesh looks like through a box, at one resolution (row 0 at v = 0).

    height : (H, W) float32 in [0, 1], 0 where nothing was drawn.
    color : (H, W, 4) float32 linear base colour with straight alpha.
    normal : (H, W, 3) float32 world-space normals as rasterized (not re-oriented).
    mask : (H, W) bool, covered texels.
    """

    height: np.ndarray
    color: np.ndarray
    normal: np.ndarray
    mask: np.ndarray


def box_camera(box_to_world: np.ndarray, size) -> MatrixCamera:
    """The camera that rasterizes world space through ``box_to_world`` at ``size`` (W, H)."""
    world_to_box = invert_box(box_to_world)
    up = box_to_world[:3, 2] - box_to_world[3, 2] * box_to_world[:3, 3] / box_to_world[3, 3]
    return MatrixCamera(view=world_to_box, proj=BOX_TO_CLIP, size=tuple(size),
                        view_dir=tuple(up / np.linalg.norm(up)),
                        origin=tuple(box_center(box_to_world)))


def project_mesh(mesh, box_to_world: np.ndarray, size, ctx=None) -> Projection:
    """Rasterize ``mesh`` through the box at ``size`` (W, H) texels."""
    box_to_world = np.asarray(box_to_world, dtype=np.float64)
    if box_to_world.shape != (4, 4) or not np.isfinite(box_to_world).all():
        raise UsageError("box_to_world must be a finite 4x4 matrix")
    frame = render(mesh, box_camera(box_to_world, size), light=FLAT_LIGHT, ctx=ctx)
    rows = slice(None, None, -1)  # frames have row 0 at the top (v = 1); textures at v = 0
    mask = frame.mask[rows]
    height = np.where(mask, 1.0 - frame.depth[rows], 0.0).astype(np.float32)
    return Projection(height, frame.color[rows], frame.normal[rows], mask)


def dilate(mask: np.ndarray, *images: np.ndarray) -> tuple[np.ndarray, ...]:
    """Each image with its empty texels (``~mask``) filled from the nearest covered texel.

    Impostor bakers pad their maps this way so bilinear and mipmapped lookups at the edge of
    a footprint never mix in the empty texels' zeros (dark, semi-transparent fringes).
    Images come back unchanged when nothing is covered.
    """
    from scipy.ndimage import distance_transform_edt

    mask = np.asarray(mask, dtype=bool)
    if mask.all() or not mask.any():
        return tuple(np.array(image, copy=True) for image in images)
    _, (rows, cols) = distance_transform_edt(~mask, return_indices=True)
    return tuple(np.asarray(image)[rows, cols] for image in images)
