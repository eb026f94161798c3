"""Open3D's voxel carving as a peer of `reference.voxel_carve`, on the same six depth images.

`open3d_carve` feeds the six images of a `DepthImages` to Open3D's
``VoxelGrid.carve_depth_map`` (§4: the depth object) or ``VoxelGrid.carve_silhouette`` (§5:
the visual hull, from the masks) on a dense ``n^3`` grid over the cube, and returns the
occupancy in `voxel_carve`'s layout; `open3d_agreement` compares the two. Open3D is optional
(``pip install open3d``; see pyproject.toml for why it is or is not in the ``peers`` extra):
without it `open3d_status` says why and the other functions raise `UsageError` with that
reason instead of pretending.

The camera: an orthographic image emulated by a distant pinhole
-------------------------------------------------------------------
Open3D carves only through a ``PinholeCameraParameters``. Face k's image is orthographic, so
each face gets a pinhole camera on the face's outward normal at ``distance`` cube sides from
the face (default 1000), looking inward, with its x/y axes along the face's u/v axes and a
focal length chosen so that the magnification is exact on the cube's mid-plane
(``f = N (D + s/2) / s`` pixels, principal point ``(N - 1) / 2``: pixel centre (i, j) is
Open3D's integer pixel coordinate (i, j), as texel centre ``u = (i + 0.5) / N``). The depth
image becomes metric depth along the camera's axis, ``D + depth * s`` (float32), 0 where
``mask`` is False (Open3D's "no measurement": ``carve_depth_map`` keeps nothing on account of
a pixel whose depth is 0). The silhouette image is the mask as float32 0/1 (Open3D reads both
through ``Image.FloatValueAt``, which needs a one-channel float32 image).

The other choice, resampling each orthographic image into a nearby pinhole's image, was not
taken: a pinhole pixel's ray crosses many orthographic texel columns, so the resampled image
would have to be the depth of one image's *volume* along perspective rays (a ray cast per
pixel) and would add its own resampling error; the distant camera feeds Open3D the original
texels unchanged. Its error is the perspective left in it: a point at distance t in [0, s]
from the face and offset r <= s/sqrt(2) from the face's centre projects
``r |(D + s/2)/(D + t) - 1| <= r (s/2) / D`` away from where an orthographic camera puts it,
i.e. at most ``N / (2 sqrt(2) * distance)`` pixels (0.045 px for N = 128 at 1000 sides), and
the float32 depth loses ``~6e-8 * (D + s)`` (6e-5 sides at 1000 sides; a 128^3 voxel is
7.8e-3 sides). The camera sits outside the cube, in front of every voxel: Open3D projects
points behind a pinhole as if in front (it divides by z without checking its sign), the open
bug https://github.com/isl-org/Open3D/issues/4359 ("Voxel Depth-Map Carving removes
everything behind the camera"), which a camera inside the grid would hit.

What Open3D carves (so what agreement to expect)
------------------------------------------------
Open3D keeps a voxel when *any* of its 8 corners projects inside an image to a pixel whose
bilinearly interpolated value passes (depth: ``d > 0`` and the corner's depth ``z >= d``;
silhouette: value > 0), and carves corners that fall outside the image (we pass
``keep_voxels_outside_image=False``; the cube's boundary corners project half a pixel beyond
the outermost pixel centres, so the shell of voxels touching the cube is carved unless an
inner corner keeps it, which the margin of `depth_images.MARGIN` makes harmless). `voxel_carve`
instead tests each voxel's *centre* against nearest-texel columns. So Open3D's occupancy is
the conservative one: every voxel whose cell touches an image's volume is kept (about one
voxel layer more on every side of the object), plus up to a pixel more where bilinear
filtering mixes a surface depth with a 0 ("no surface") neighbour (a smaller depth, so more
is kept); on every test scene it contains `voxel_carve`'s occupancy.

The tests evaluate that rule in numpy with exact orthographic projection: Open3D's output
equals it voxel for voxel on the test scenes (IoU 1.0 for the box, sphere and cup at n = 32
with 64^2 images; >= 0.999 at n = 64, 128 with 128^2 images), which is what shows the camera
emulation right. Against `voxel_carve` the extra voxels form
a shell one voxel thick (IoU 0.72-0.85 at n = 32, 0.94-0.99 at n = 128), except where a
depth image's edge pixels are mixed with an empty (0) neighbour: there that image keeps its
whole column, so a few voxels (1-3 % of the disagreement on the sphere) lie farther off
the surface (up to 3 voxels at n = 32, 9 at n = 128). `open3d_agreement` reports both
(``band_fraction``, ``max_offset``).

Speed: Open3D's carve is a serial C++ loop over a hash map of voxels (8 projections per voxel
per image) and is timed alone (``create_dense`` and the six carves); reading the surviving
voxels back into a numpy array is not timed.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ...errors import UsageError
from .depth_images import DepthImages, visual_hull
from .reference import voxel_carve

#: Default camera distance from its face, in cube sides (see the module docstring).
DISTANCE = 1000.0
#: Largest grid: Open3D holds every voxel in a hash map (256^3 = 16.7M voxels is ~1-2 GB).
MAX_GRID = 256


def _open3d():
    """(the open3d module, "") or (None, a one-line reason it cannot be imported)."""
    try:
        import open3d
    except Exception as error:  # ImportError, or a broken wheel (missing shared libraries)
        text = " ".join(str(error).split())[:300]
        hint = "pip install open3d"
        if "libusb" in text:
            hint = "the wheel links libusb-1.0: apt-get install libusb-1.0-0"
        elif "libGL" in text or "libX11" in text or "libEGL" in text:
            hint = "the wheel links GL/X11 libraries: apt-get install libgl1 libx11-6"
        return None, f"open3d unavailable ({type(error).__name__}: {text}); {hint}"
    version = getattr(open3d, "__version__", "?")
    geometry = getattr(open3d, "geometry", None)
    voxel_grid = getattr(geometry, "VoxelGrid", None)
    missing = [name for name in ("create_dense", "carve_depth_map", "carve_silhouette")
               if not hasattr(voxel_grid, name)]
    if missing:
        return None, (f"open3d {version} has no VoxelGrid.{', '.join(missing)} (built without "
                      "the legacy geometry module?)")
    return open3d, ""


def open3d_status() -> tuple[bool, str]:
    """(whether Open3D's carving can run, one line naming its version or why not)."""
    o3d, reason = _open3d()
    if o3d is None:
        return False, reason
    return True, f"open3d {o3d.__version__} (VoxelGrid.carve_depth_map / carve_silhouette)"


def _require():
    o3d, reason = _open3d()
    if o3d is None:
        raise UsageError(f"the Open3D peer cannot run here: {reason}")
    return o3d


def _check(images, n) -> None:
    if not isinstance(images, DepthImages):
        raise UsageError(f"expected DepthImages, got {type(images).__name__}")
    if isinstance(n, bool) or not isinstance(n, int | np.integer) or not 1 <= n <= MAX_GRID:
        raise UsageError(f"the Open3D carve needs an integer grid size in [1, {MAX_GRID}], "
                         f"got {n!r}")
    if images.resolution < 2:  # Image::FloatValueAt reads pixel u + 1 of a 1-pixel image
        raise UsageError("the Open3D carve needs images of at least 2 x 2 texels")
    linear = np.asarray(images.cube_to_world, dtype=np.float64)[:3, :3]
    if not np.allclose(linear, np.eye(3) * images.side, rtol=0, atol=1e-9 * images.side):
        raise UsageError("the Open3D carve needs an axis-aligned cube (cube_to_world a scale "
                         "and a translation), as `bake_depth_images` makes")


def face_cameras(images: DepthImages, distance: float = DISTANCE):
    """Per face k: (extrinsic 4x4 world -> camera, intrinsic 3x3 in pixels, D) of the distant
    pinhole camera standing in for face k's orthographic image (module docstring)."""
    if not np.isfinite(distance) or distance < 1:
        raise UsageError(f"camera distance must be >= 1 cube side, got {distance}")
    side = images.side
    n = images.resolution
    far = distance * side
    focal = n * (far + 0.5 * side) / side
    centre_px = 0.5 * (n - 1)
    intrinsic = np.array([[focal, 0.0, centre_px], [0.0, focal, centre_px], [0.0, 0.0, 1.0]])
    cameras = []
    for k in range(6):
        box = np.asarray(images.box_to_world[k], dtype=np.float64)
        u_axis, v_axis, h_axis = (box[:3, a] / np.linalg.norm(box[:3, a]) for a in range(3))
        face_centre = box[:3, :3] @ np.array([0.5, 0.5, 1.0]) + box[:3, 3]
        eye = face_centre + far * h_axis
        rotation = np.stack([u_axis, v_axis, -h_axis])  # rows: camera x, y, z in world
        extrinsic = np.eye(4)
        extrinsic[:3, :3] = rotation
        extrinsic[:3, 3] = -rotation @ eye
        cameras.append((extrinsic, intrinsic.copy(), far))
    return cameras


def _camera_parameters(o3d, extrinsic, intrinsic, n):
    params = o3d.camera.PinholeCameraParameters()
    params.intrinsic = o3d.camera.PinholeCameraIntrinsic(
        n, n, intrinsic[0, 0], intrinsic[1, 1], intrinsic[0, 2], intrinsic[1, 2])
    params.extrinsic = extrinsic
    return params


def _occupancy(grid, n: int) -> np.ndarray:
    """The surviving voxels of an Open3D grid as (n, n, n) bool [z, y, x]."""
    occupancy = np.zeros((n, n, n), bool)
    voxels = grid.get_voxels()
    if voxels:
        index = np.array([v.grid_index for v in voxels], dtype=np.int64).reshape(-1, 3)
        occupancy[index[:, 2], index[:, 1], index[:, 0]] = True
    return occupancy


def open3d_carve(images: DepthImages, n: int, silhouettes: bool = False, *,
                 distance: float = DISTANCE) -> tuple[np.ndarray, float]:
    """Carve a dense ``n^3`` Open3D ``VoxelGrid`` on the cube with the six images.

    ``silhouettes=False``: ``carve_depth_map`` with each image's metric depth (the depth
    object, §4); ``True``: ``carve_silhouette`` with the masks (the visual hull, §5).
    Returns ``(occupancy, seconds)``: (n, n, n) bool indexed [z, y, x] over the cube's voxels
    as `reference.voxel_carve`, and the wall time of Open3D's ``create_dense`` plus the six
    carves. Raises `UsageError` when Open3D is unavailable (see `open3d_status`).
    """
    _check(images, n)
    o3d = _require()
    n = int(n)
    side = images.side
    res = images.resolution
    origin = np.asarray(images.cube_to_world, dtype=np.float64)[:3, 3]
    inputs = []
    for k, (extrinsic, intrinsic, far) in enumerate(face_cameras(images, distance)):
        if silhouettes:
            values = images.mask[k].astype(np.float32)
        else:
            metric = far + images.depth[k].astype(np.float64) * side
            values = np.where(images.mask[k], metric, 0.0).astype(np.float32)
        inputs.append((o3d.geometry.Image(np.ascontiguousarray(values)),
                       _camera_parameters(o3d, extrinsic, intrinsic, res)))
    start = time.perf_counter()
    grid = o3d.geometry.VoxelGrid.create_dense(origin, np.zeros(3), side / n, side, side, side)
    for image, params in inputs:
        if silhouettes:
            grid.carve_silhouette(image, params, keep_voxels_outside_image=False)
        else:
            grid.carve_depth_map(image, params, keep_voxels_outside_image=False)
    seconds = time.perf_counter() - start
    return _occupancy(grid, n), seconds


@dataclass(frozen=True)
class Agreement:
    """Open3D's carve against `voxel_carve` on one grid.

    iou : |both| / |either| of the two occupancies.
    voxels_open3d, voxels_reference : occupied voxel counts.
    only_open3d, only_reference : voxels occupied in one and not the other.
    band_fraction : share of the disagreeing voxels that lie within one voxel (26-neighbour)
        of the reference's surface (1 when they agree everywhere).
    max_offset : the farthest a disagreeing voxel lies from that surface, in voxels
        (chessboard distance; 0 when they agree).
    seconds_open3d, seconds_reference : wall time of each carve (Open3D: `open3d_carve`'s).
    """

    n: int
    silhouettes: bool
    iou: float
    voxels_open3d: int
    voxels_reference: int
    only_open3d: int
    only_reference: int
    band_fraction: float
    max_offset: int
    seconds_open3d: float
    seconds_reference: float


def compare_occupancy(peer: np.ndarray, reference: np.ndarray) -> dict:
    """IoU, counts and how far from the reference's surface two occupancies disagree.

    ``band_fraction``: share of the disagreeing voxels within one voxel (26-neighbour) of the
    reference's surface, i.e. outside voxels touching it or inside voxels touching its
    outside; ``max_offset``: the largest such chessboard distance in voxels (0 when they
    agree)."""
    from scipy.ndimage import distance_transform_cdt

    peer = np.asarray(peer, bool)
    reference = np.asarray(reference, bool)
    if peer.shape != reference.shape:
        raise UsageError(f"occupancies differ in shape: {peer.shape} vs {reference.shape}")
    union = int((peer | reference).sum())
    both = int((peer & reference).sum())
    differ = peer ^ reference
    n_differ = int(differ.sum())
    if n_differ == 0:
        band_fraction, max_offset = 1.0, 0
    elif not reference.any() or reference.all():
        band_fraction, max_offset = 0.0, int(max(reference.shape))
    else:
        # pad with empty space so the grid's border counts as outside
        padded = np.pad(reference, 1)
        outside = distance_transform_cdt(~padded, metric="chessboard")[1:-1, 1:-1, 1:-1]
        inside = distance_transform_cdt(padded, metric="chessboard")[1:-1, 1:-1, 1:-1]
        offset = np.where(reference, inside, outside)[differ]
        band_fraction, max_offset = float((offset <= 1).mean()), int(offset.max())
    return {"iou": both / union if union else 1.0,
            "voxels_open3d": int(peer.sum()), "voxels_reference": int(reference.sum()),
            "only_open3d": int((peer & ~reference).sum()),
            "only_reference": int((reference & ~peer).sum()),
            "band_fraction": band_fraction, "max_offset": max_offset}


def open3d_agreement(images: DepthImages, n: int, silhouettes: bool = False, *,
                     distance: float = DISTANCE) -> Agreement:
    """Run `open3d_carve` and `reference.voxel_carve` (of `visual_hull(images)` when
    ``silhouettes``) on the same n^3 grid and compare them."""
    peer, seconds = open3d_carve(images, n, silhouettes, distance=distance)
    source = visual_hull(images) if silhouettes else images
    start = time.perf_counter()
    reference = voxel_carve(source, int(n))
    seconds_reference = time.perf_counter() - start
    return Agreement(int(n), bool(silhouettes), seconds_open3d=seconds,
                     seconds_reference=seconds_reference,
                     **compare_occupancy(peer, reference))
