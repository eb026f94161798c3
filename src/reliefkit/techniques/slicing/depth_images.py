"""Six orthographic depth images of a mesh on its bounding cube (§4) and their visual hull (§5).

Conventions
-----------
The cube is the mesh's bounding box grown to its largest side and enlarged by `MARGIN` on
every side (so texels are square and nothing touches a face). Cube coordinates
q = (x, y, z) in [0, 1]^3 are world axes: ``world = cube_to_world @ (q, 1)``.

Face k (k indexes `reliefkit.bake.project.CUBE_FACES` = x, -x, y, -y, z, -z) has the frame
``axis_frame(face)`` whose h is the face's *outward* normal. Its box ``box_to_world[k]`` maps
(u, v, h) in [0, 1]^3 onto the whole cube with h = 1 on face k and h = 0 on the opposite
face, so `project_mesh` (which keeps the largest h) keeps the surface nearest to face k.

``depth[k][j, i]`` (float32) is the distance from face k to the first surface met by the
ray entering the cube through the texel centre u = (i + 0.5) / N, v = (j + 0.5) / N and
travelling along the inward normal (-h), as a fraction of the cube side: depth = 1 - h.
Where that ray meets nothing, ``mask[k][j, i]`` is False and depth is 1.

The volume of image k is the set of cube points p whose own distance from face k,
1 - h_k(p), is at least the depth stored at p's projection onto face k (see
`reference.py` for how the images are reconstructed between texels); the depth object is
the intersection of all six volumes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...bake.project import CUBE_FACES, axis_frame, project_mesh
from ...core.transforms import MAX_COORDINATE
from ...errors import UsageError
from ...gl import targets
from ...gl.textures import MAX_TEXTURE_ARRAY_BYTES
from ...io.rk import DEFAULT_MAX_BYTES
from ...units import format_bytes

#: Growth of the bounding cube on every side, as a fraction of the mesh's largest extent.
MARGIN = 0.02
#: Indices of the faces in `CUBE_FACES` order (outward normal +x, -x, +y, -y, +z, -z).
FACE_INDEX = {face: k for k, face in enumerate(CUBE_FACES)}
MAX_RESOLUTION = 8192
#: The smallest cube side: the GPU draws in float32, whose normal numbers end near 1e-38, so
#: a smaller cube's texels (side / N) and inverse boxes are no longer numbers it can hold.
MIN_SIDE = 1e-30
#: Bytes per texel of the six images: depth float32, mask, colour RGBA float32, normal.
TEXEL_BYTES = 4 + 1 + 16 + 12
#: Host memory per texel at the peak of a bake and of a render (the images' arrays, one
#: face's projection, or the draw plan's depth and premultiplied colour arrays, and on
#: Mesa the driver's copy of the textures); measured as the slope of the peak RSS from
#: res 512 to 1024 (bake 71 B, render 85 B), with margin.
PEAK_TEXEL_BYTES = {"bake": 76, "render": 88}
#: Texturing (§4.2): a point this many texels (plus one slice, or one grid cell) behind
#: image k's surface still counts as seen by image k (`visible_depth`).
VISIBLE_TEXELS = 1.5


@dataclass(frozen=True, eq=False)
class DepthImages:
    """Six orthographic depth images looking into a cube (see the module docstring).

    depth : (6, N, N) float32 in [0, 1], distance from face k to the first surface along the
        inward normal in cube-side units, 1 where ``mask`` is False.
    mask : (6, N, N) bool, texels whose inward ray meets the surface.
    color : (6, N, N, 4) float32 linear base colour with straight alpha.
    normal : (6, N, N, 3) float32 world-space normals as rasterized.
    box_to_world : (6, 4, 4) float64, face k's box (u, v, h) -> world, h = outward normal.
    cube_to_world : (4, 4) float64, cube coordinates (x, y, z) in [0, 1]^3 -> world.
    """

    depth: np.ndarray
    mask: np.ndarray
    color: np.ndarray
    normal: np.ndarray
    box_to_world: np.ndarray
    cube_to_world: np.ndarray

    def __post_init__(self) -> None:
        depth = np.asarray(self.depth)
        if depth.ndim != 3 or depth.shape[0] != 6 or depth.shape[1] != depth.shape[2] \
                or depth.shape[1] < 1:
            raise UsageError(f"depth images must have shape (6, N, N), got {depth.shape}")
        n = depth.shape[1]
        expected = {"mask": (6, n, n), "color": (6, n, n, 4), "normal": (6, n, n, 3),
                    "box_to_world": (6, 4, 4), "cube_to_world": (4, 4)}
        for name, shape in expected.items():
            got = np.shape(getattr(self, name))
            if got != shape:
                raise UsageError(f"depth images: {name} must have shape {shape}, got {got}")
        if not np.isfinite(depth).all() or depth.min() < 0 or depth.max() > 1:
            raise UsageError("depth images: depth must be finite and in [0, 1]")
        object.__setattr__(self, "depth", depth.astype(np.float32, copy=False))
        object.__setattr__(self, "mask", np.asarray(self.mask, dtype=bool))

    @property
    def resolution(self) -> int:
        return int(self.depth.shape[1])

    @property
    def side(self) -> float:
        """Length of the cube's side in world units."""
        return float(np.linalg.norm(self.cube_to_world[:3, 0]))

    @property
    def texel(self) -> float:
        """One texel in world units."""
        return self.side / self.resolution

    def column_bounds(self) -> np.ndarray:
        """(3, 2, N, N) float64: per cube axis a, the interval [lo, hi] of q_a allowed by
        the two images looking along a, per texel column (nearest-texel reconstruction).

        ``bounds[a, 0]`` comes from the face whose outward normal is -a (q_a >= depth),
        ``bounds[a, 1]`` from the face +a (q_a <= 1 - depth); both are indexed by the voxel
        indices of the two other cube axes in increasing order (x: [y, z], y: [x, z],
        z: [x, y]). An empty column has lo = 2, hi = -1.
        """
        n = self.resolution
        bounds = np.empty((3, 2, n, n))
        bounds[:, 0] = 2.0
        bounds[:, 1] = -1.0
        centres = (np.arange(n) + 0.5) / n
        uu, vv = np.meshgrid(centres, centres)  # [j, i]
        for face, k in FACE_INDEX.items():
            frame = axis_frame(face)  # rows u, v, h in world (= cube) axes
            corner = 0.5 - 0.5 * frame.sum(axis=0)
            q = corner + uu[..., None] * frame[0] + vv[..., None] * frame[1]
            axis = int(np.argmax(np.abs(frame[2])))
            others = [b for b in range(3) if b != axis]
            ib = np.floor(q[..., others[0]] * n).astype(int)
            ic = np.floor(q[..., others[1]] * n).astype(int)
            d = self.depth[k].astype(np.float64)
            outward_positive = frame[2, axis] > 0
            value = np.where(self.mask[k], 1.0 - d if outward_positive else d,
                             -1.0 if outward_positive else 2.0)
            bounds[axis, 1 if outward_positive else 0, ib, ic] = value
        return bounds


def visible_depth(resolution: int, slack: float = 0.0) -> float:
    """How far behind image k's surface a drawn point may be and still count as seen by it
    (cube-side units): `VISIBLE_TEXELS`, plus ``slack`` (a slice spacing for the point
    test, or a fallback mesh's grid cell: how far such points lie from the surface)."""
    return VISIBLE_TEXELS / resolution + slack


def check_side(side: float) -> None:
    """Refuse a cube side outside [`MIN_SIDE`, `MAX_COORDINATE`] (no float32 draw, and no
    float64 inverse, holds it)."""
    if not (np.isfinite(side) and MIN_SIDE <= side <= MAX_COORDINATE):
        raise UsageError(f"the depth images' cube side must be within [{MIN_SIDE:g}, "
                         f"{MAX_COORDINATE:g}] world units, got {side:g}; scale the mesh")


def cube_of(mesh, margin: float = MARGIN) -> np.ndarray:
    """cube_to_world of the mesh's bounding cube (largest side, grown by ``margin``)."""
    bounds = np.asarray(mesh.bounds, dtype=np.float64)
    extent = float((bounds[1] - bounds[0]).max())
    if not np.isfinite(extent) or extent <= 0:
        raise UsageError(f"mesh '{mesh.name}' has no extent (a point?); depth images need a "
                         "mesh with a non-zero bounding box")
    side = extent * (1.0 + 2.0 * margin)
    check_side(side)
    centre = bounds.mean(axis=0)
    cube = np.eye(4) * side
    cube[3, 3] = 1.0
    cube[:3, 3] = centre - 0.5 * side
    return cube


def face_boxes(cube_to_world: np.ndarray) -> np.ndarray:
    """(6, 4, 4): face k's box (u, v, h) -> world, h pointing out of face k."""
    side = np.linalg.norm(cube_to_world[:3, 0])
    centre = cube_to_world[:3, 3] + 0.5 * side
    boxes = np.zeros((6, 4, 4))
    for face, k in FACE_INDEX.items():
        frame = axis_frame(face)
        boxes[k, :3, :3] = side * frame.T
        boxes[k, :3, 3] = centre - 0.5 * side * frame.sum(axis=0)
        boxes[k, 3, 3] = 1.0
    return boxes


def check_size(n: int) -> None:
    """Refuse, before anything is allocated, six N x N images that no .rk file could hold
    (`io.rk.DEFAULT_MAX_BYTES`) or whose colours no GPU texture array could (they are
    uploaded as one when drawn), with the estimate and the largest N that fits."""
    arrays, colours = 6 * n * n * TEXEL_BYTES, 6 * n * n * 16
    if arrays <= DEFAULT_MAX_BYTES and colours <= MAX_TEXTURE_ARRAY_BYTES:
        return
    largest = int(min(DEFAULT_MAX_BYTES / (6 * TEXEL_BYTES),
                      MAX_TEXTURE_ARRAY_BYTES / (6 * 16)) ** 0.5)
    raise UsageError(f"res {n}: six {n}x{n} depth images need {format_bytes(arrays)} of "
                     f"arrays (a .rk file holds at most {format_bytes(DEFAULT_MAX_BYTES)}) "
                     f"and {format_bytes(colours)} of colour texture when drawn (at most "
                     f"{format_bytes(MAX_TEXTURE_ARRAY_BYTES)}); use a res of at most "
                     f"{largest}")


def check_memory(n: int, stage: str) -> None:
    """Refuse, before anything is allocated, a ``stage`` ("bake" or "render") of six N x N
    images whose host-memory peak (`PEAK_TEXEL_BYTES`) exceeds `gl.targets.host_limit`,
    with the estimate and the largest N that fits."""
    per_texel, limit = PEAK_TEXEL_BYTES[stage], targets.host_limit()
    needed = 6 * n * n * per_texel
    if needed > limit:
        largest = int((limit / (6 * per_texel)) ** 0.5)
        raise UsageError(f"res {n}: to {stage} six {n}x{n} depth images needs about "
                         f"{format_bytes(needed)} of host memory (limit "
                         f"{format_bytes(limit)}); use a res of at most {largest}")


def bake_depth_images(mesh, resolution: int = 256, *, margin: float = MARGIN,
                      ctx=None) -> DepthImages:
    """Rasterize ``mesh`` through the six faces of its bounding cube (one GL draw each),
    after `check_size` and `check_memory`."""
    if isinstance(resolution, bool) or not isinstance(resolution, int | np.integer) \
            or not 2 <= resolution <= MAX_RESOLUTION:
        raise UsageError(f"resolution must be an integer in [2, {MAX_RESOLUTION}], "
                         f"got {resolution!r}")
    check_size(int(resolution))
    check_memory(int(resolution), "bake")
    if not 0 <= margin < 1:
        raise UsageError(f"margin must be in [0, 1), got {margin}")
    n = int(resolution)
    cube = cube_of(mesh, margin)
    boxes = face_boxes(cube)
    depth = np.ones((6, n, n), np.float32)
    mask = np.zeros((6, n, n), bool)
    color = np.zeros((6, n, n, 4), np.float32)
    normal = np.zeros((6, n, n, 3), np.float32)
    for k in range(6):
        proj = project_mesh(mesh, boxes[k], (n, n), ctx=ctx)
        mask[k] = proj.mask
        depth[k] = np.where(proj.mask, np.clip(1.0 - proj.height, 0.0, 1.0), 1.0)
        color[k] = proj.color
        normal[k] = proj.normal
    return DepthImages(depth, mask, color, normal, boxes, cube)


def visual_hull(images: DepthImages) -> DepthImages:
    """The silhouette version (§5): depth 0 inside every mask (the whole column is inside),
    1 and empty outside; colours, normals and boxes are kept."""
    depth = np.where(images.mask, 0.0, 1.0).astype(np.float32)
    return DepthImages(depth, images.mask.copy(), images.color, images.normal,
                       images.box_to_world, images.cube_to_world)
