"""Open3D's voxel carving as a peer of `reference.voxel_carve` (the Open3D runs skip without
open3d; the status, the camera emulation and the numpy model of Open3D's rule, `open3d_rule`
here, always run)."""

from __future__ import annotations

import sys

import numpy as np
import pytest
from slicing_scenes import BOX_HI, BOX_LO, box_mesh, sphere_mesh

from reliefkit.core.transforms import transform_points
from reliefkit.errors import UsageError
from reliefkit.techniques.slicing.depth_images import (
    DepthImages,
    bake_depth_images,
    face_boxes,
    visual_hull,
)
from reliefkit.techniques.slicing.peers import (
    DISTANCE,
    Agreement,
    compare_occupancy,
    face_cameras,
    open3d_agreement,
    open3d_carve,
    open3d_status,
)
from reliefkit.techniques.slicing.reference import voxel_carve

AVAILABLE, REASON = open3d_status()
needs_open3d = pytest.mark.skipif(not AVAILABLE, reason=REASON or "open3d unavailable")

RES = 64  # image resolution: two texels per voxel at N = 32
N = 32
# IoU of Open3D's carve against voxel_carve at N = 32. Open3D keeps every voxel one of whose
# 8 corners passes (bilinear), voxel_carve tests voxel centres (nearest texel), so Open3D's
# occupancy is voxel_carve's plus a one-voxel shell. For the box that is exact arithmetic:
# centres inside give 30 x 18 x 24 = 12960 voxels, cells touching give 32 x 20 x 26 = 16640,
# IoU 0.779; the sphere (radius ~15 voxels) measured 0.822 (depth) and 0.793 (silhouettes).
# 0.75 leaves 0.03 of margin below the lowest, and fails if the shell grows to two voxels
# (box: 12960 / (34 x 22 x 28) = 0.62) or the camera is wrong (a misplaced or mirrored
# face carves away whole slabs).
MIN_IOU = 0.75


def open3d_rule(images: DepthImages, n: int, silhouettes: bool = False, *,
                distance: float = DISTANCE) -> np.ndarray:
    """Open3D's carving rule evaluated here in numpy with *exact orthographic* projection:
    (n, n, n) bool [z, y, x], no Open3D needed.

    A voxel survives image k when any of its 8 corners falls within the pixel centres'
    rectangle and the bilinear value there (of the same float32 image `open3d_carve` passes:
    metric depth ``distance + depth`` in cube sides, 0 off the mask; or the 0/1 mask) passes
    (``d > 0`` and the corner's depth ``>= d``; or ``value > 0``): Open3D's
    ``VoxelGrid::CarveDepthMap`` / ``CarveSilhouette`` with ``Image::FloatValueAt``. Its
    difference from `open3d_carve` is only the distant pinhole's perspective (and float
    rounding), which makes it the check that the camera emulation is right; its difference
    from `voxel_carve` is the rule itself (any corner and bilinear, versus voxel centre and
    nearest texel).
    """
    res = images.resolution
    lattice = np.arange(n + 1) / n
    z, y, x = np.meshgrid(lattice, lattice, lattice, indexing="ij")
    corners = np.stack([x, y, z], axis=-1).reshape(-1, 3)
    world = corners @ images.cube_to_world[:3, :3].T + images.cube_to_world[:3, 3]
    keep = np.ones((n, n, n), bool)
    for k in range(6):
        to_box = np.linalg.inv(images.box_to_world[k])
        uvh = world @ to_box[:3, :3].T + to_box[:3, 3]
        px, py = uvh[:, 0] * res - 0.5, uvh[:, 1] * res - 0.5
        within = (px >= 0) & (px <= res - 1) & (py >= 0) & (py <= res - 1)
        if silhouettes:
            values = images.mask[k].astype(np.float32)
        else:
            values = np.where(images.mask[k], distance + images.depth[k].astype(np.float64),
                              0.0).astype(np.float32)
        ui = np.clip(np.floor(np.clip(px, 0, res - 1)).astype(int), 0, res - 2)
        vi = np.clip(np.floor(np.clip(py, 0, res - 1)).astype(int), 0, res - 2)
        pu, pv = px - ui, py - vi
        d = ((values[vi, ui] * (1 - pv) + values[vi + 1, ui] * pv) * (1 - pu)
             + (values[vi, ui + 1] * (1 - pv) + values[vi + 1, ui + 1] * pv) * pu)
        if silhouettes:
            passes = within & (d > 0)
        else:
            passes = within & (d > 0) & (distance + 1.0 - uvh[:, 2] >= d)
        passes = passes.reshape(n + 1, n + 1, n + 1)
        voxel = np.zeros((n, n, n), bool)
        for dz in (0, 1):
            for dy in (0, 1):
                for dx in (0, 1):
                    voxel |= passes[dz:dz + n, dy:dy + n, dx:dx + n]
        keep &= voxel
    return keep


def empty_images(res=4):
    cube = np.eye(4)
    return DepthImages(np.ones((6, res, res), np.float32), np.zeros((6, res, res), bool),
                       np.zeros((6, res, res, 4), np.float32), np.zeros((6, res, res, 3),
                                                                         np.float32),
                       face_boxes(cube), cube)


@pytest.fixture(scope="module")
def box_images(gl):
    return bake_depth_images(box_mesh(), RES)


@pytest.fixture(scope="module")
def sphere_images(gl):
    return bake_depth_images(sphere_mesh(), RES)


def test_status_is_a_bool_and_one_line():
    available, reason = open3d_status()
    assert isinstance(available, bool) and isinstance(reason, str)
    assert reason and "\n" not in reason and "open3d" in reason
    if available:
        import open3d

        assert open3d.__version__ in reason


def test_missing_open3d_is_reported_not_raised(monkeypatch):
    for name in [m for m in sys.modules if m == "open3d" or m.startswith("open3d.")]:
        monkeypatch.setitem(sys.modules, name, None)
    monkeypatch.setitem(sys.modules, "open3d", None)  # None: "import halted"
    available, reason = open3d_status()
    assert not available and "open3d unavailable" in reason and "\n" not in reason
    with pytest.raises(UsageError, match="Open3D peer cannot run here"):
        open3d_carve(empty_images(), 4)


def test_bad_arguments_are_usage_errors():
    with pytest.raises(UsageError):
        open3d_carve("not images", 4)
    for n in (0, True, 2.5, 10_000):  # refused before Open3D is needed
        with pytest.raises(UsageError, match="grid size"):
            open3d_carve(empty_images(), n)
    with pytest.raises(UsageError, match="2 x 2"):
        open3d_carve(empty_images(res=1), 4)
    with pytest.raises(UsageError):
        face_cameras(empty_images(), distance=0.5)


def test_distant_pinhole_puts_texel_centres_on_pixel_centres():
    images = empty_images(res=128)
    res = images.resolution
    ii, jj = np.meshgrid(np.arange(res), np.arange(res))
    bound = res / (2 * np.sqrt(2) * DISTANCE)  # the docstring's perspective error
    for k, (extrinsic, intrinsic, far) in enumerate(face_cameras(images)):
        assert np.allclose(extrinsic[:3, :3] @ extrinsic[:3, :3].T, np.eye(3))
        for h in (0.0, 0.5, 1.0):  # the far face, the mid-plane, the face itself
            uvh = np.stack([(ii + 0.5) / res, (jj + 0.5) / res, np.full(ii.shape, h)], -1)
            world = transform_points(images.box_to_world[k], uvh)
            cam = transform_points(extrinsic, world)
            # in front of the camera, at the metric depth open3d_carve encodes
            assert np.allclose(cam[..., 2], far + (1 - h) * images.side)
            pix = cam @ intrinsic.T
            col, row = pix[..., 0] / pix[..., 2], pix[..., 1] / pix[..., 2]
            assert np.abs(col - ii).max() <= bound + 1e-9
            assert np.abs(row - jj).max() <= bound + 1e-9
            if h == 0.5:
                assert np.abs(col - ii).max() < 1e-6 and np.abs(row - jj).max() < 1e-6


def test_compare_occupancy_counts_and_band():
    ref = np.zeros((8, 8, 8), bool)
    ref[2:6, 2:6, 2:6] = True
    shell = np.zeros_like(ref)
    shell[1:7, 1:7, 1:7] = True
    got = compare_occupancy(shell, ref)
    assert got["iou"] == pytest.approx(64 / 216)
    assert (got["voxels_open3d"], got["voxels_reference"]) == (216, 64)
    assert (got["only_open3d"], got["only_reference"], got["max_offset"]) == (152, 0, 1)
    assert got["band_fraction"] == 1.0
    far = ref.copy()
    far[0, 0, 0] = True  # 2 voxels (chessboard) from the cube
    got = compare_occupancy(far, ref)
    assert got["max_offset"] == 2 and got["band_fraction"] == 0.0
    assert compare_occupancy(ref, ref)["iou"] == 1.0


@pytest.mark.parametrize("silhouettes", [False, True])
def test_open3d_rule_contains_voxel_carve_with_one_voxel_shell_on_the_box(box_images,
                                                                          silhouettes):
    rule = open3d_rule(box_images, N, silhouettes)
    source = visual_hull(box_images) if silhouettes else box_images
    ref = voxel_carve(source, N)
    assert not (ref & ~rule).any()
    # analytic: the cells that touch the box (open intervals) along every axis
    lo, hi = (transform_points(np.linalg.inv(box_images.cube_to_world), p) for p in
              (BOX_LO, BOX_HI))
    cells = np.arange(N)
    touch = [((cells + 1) / N > lo[a]) & (cells / N < hi[a]) for a in range(3)]
    truth = touch[2][:, None, None] & touch[1][None, :, None] & touch[0][None, None, :]
    assert compare_occupancy(rule, truth)["iou"] >= 0.98


@needs_open3d
@pytest.mark.parametrize("scene", ["box", "sphere"])
@pytest.mark.parametrize("silhouettes", [False, True])
def test_open3d_carve_agrees_with_voxel_carve(scene, silhouettes, request):
    images = request.getfixturevalue(f"{scene}_images")
    occupancy, seconds = open3d_carve(images, N, silhouettes)
    assert occupancy.shape == (N, N, N) and occupancy.dtype == bool and seconds >= 0
    # the camera emulation: Open3D's output is its own rule evaluated orthographically here
    assert compare_occupancy(occupancy, open3d_rule(images, N, silhouettes))["iou"] >= 0.995
    agreement = open3d_agreement(images, N, silhouettes)
    assert isinstance(agreement, Agreement)
    print(f"{scene} silhouettes={silhouettes}: {agreement}")
    assert agreement.iou >= MIN_IOU
    # conservative: Open3D keeps (almost) everything voxel_carve keeps, and the extra lies
    # along the surface
    assert agreement.only_reference <= 0.002 * agreement.voxels_reference
    assert agreement.voxels_open3d > agreement.voxels_reference
    assert agreement.band_fraction >= 0.9
