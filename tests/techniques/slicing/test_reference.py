"""The exact depth-object reference against analytic scenes and the crude voxel carve."""

import numpy as np
import pytest
from slicing_scenes import (
    BOX_HI,
    BOX_LO,
    CUP_FLOOR,
    CUP_TOP,
    SPHERE_CENTRE,
    SPHERE_RADIUS,
    box_distance,
    box_mesh,
    cup_mesh,
    iou,
    ray_box,
    ray_sphere,
    rays,
    sphere_mesh,
    views,
)

from reliefkit.bake.project import CUBE_FACES
from reliefkit.core.transforms import transform_points
from reliefkit.errors import UsageError
from reliefkit.scene.camera import Camera
from reliefkit.techniques.slicing.depth_images import bake_depth_images, visual_hull
from reliefkit.techniques.slicing.reference import (
    exact_intersection,
    inside,
    occupied_columns,
    voxel_carve,
)

N = 64


@pytest.fixture(scope="module")
def box_images(gl):
    return bake_depth_images(box_mesh(), N)


@pytest.fixture(scope="module")
def sphere_images(gl):
    return bake_depth_images(sphere_mesh(), N)


@pytest.fixture(scope="module")
def cup_images(gl):
    return bake_depth_images(cup_mesh(), N)


def cube_centre(images):
    return transform_points(images.cube_to_world, np.full(3, 0.5))


def test_box_mask_positions_and_faces(box_images):
    im = box_images
    for camera in views(cube_centre(im)):
        mask, position, face = exact_intersection(im, camera)
        truth, truth_position = ray_box(camera, BOX_LO, BOX_HI)
        assert iou(mask, truth) >= 0.98
        assert np.isnan(position[~mask]).all() and (face[~mask] == -1).all()
        # every hit lies within half a texel of the box (nearest-texel columns)
        assert box_distance(position[mask], BOX_LO, BOX_HI).max() <= 0.5 * im.texel
        both = mask & truth
        error = np.linalg.norm(position[both] - truth_position[both], axis=-1)
        # along the ray the error grows as 1 / sin(grazing angle): the side images'
        # columns end on texel boundaries, up to half a texel short of the box's faces
        assert np.median(error) <= im.texel
        assert np.percentile(error, 99) <= 2.5 * im.texel
        # the face of the hit is the image looking at the box face that was hit
        p = truth_position[both]
        slack = np.stack([BOX_HI[0] - p[:, 0], p[:, 0] - BOX_LO[0], BOX_HI[1] - p[:, 1],
                          p[:, 1] - BOX_LO[1], BOX_HI[2] - p[:, 2], p[:, 2] - BOX_LO[2]], -1)
        assert (face[both] == np.argmin(np.abs(slack), axis=-1)).mean() >= 0.95


def test_box_visual_hull_is_the_box(box_images):
    camera = views(cube_centre(box_images))[0]
    depth_object = exact_intersection(box_images, camera)
    hull = exact_intersection(visual_hull(box_images), camera)
    assert iou(depth_object[0], hull[0]) >= 0.98  # the hull's faces lie on texel boundaries
    both = depth_object[0] & hull[0]
    error = np.linalg.norm(depth_object[1][both] - hull[1][both], axis=-1)
    assert np.median(error) <= box_images.texel


def test_sphere_positions_and_mask(sphere_images):
    im = sphere_images
    for camera in views(SPHERE_CENTRE):
        mask, position, _ = exact_intersection(im, camera)
        truth, _ = ray_sphere(camera, SPHERE_CENTRE, SPHERE_RADIUS)
        assert iou(mask, truth) >= 0.98
        radial = np.abs(np.linalg.norm(position[mask] - SPHERE_CENTRE, axis=-1) - SPHERE_RADIUS)
        assert radial.max() <= im.texel
        assert np.percentile(radial, 95) <= 0.6 * im.texel


def test_first_hit_is_exact_along_the_ray(sphere_images, rng):
    """Dense samples before the hit are outside (pointwise test), just after it inside."""
    im = sphere_images
    camera = views(SPHERE_CENTRE)[1]
    mask, position, _ = exact_intersection(im, camera)
    origin, direction = rays(camera)
    pick = rng.choice(mask.size, 300, replace=False)
    rows, cols = np.unravel_index(pick, mask.shape)
    after_inside = []
    for r, c in zip(rows, cols, strict=True):
        o, d = origin[r, c], direction[r, c]
        t_hit = (np.dot(position[r, c] - o, d) / np.dot(d, d)) if mask[r, c] else 1.0
        t = np.linspace(0.0, t_hit, 4000, endpoint=False)
        assert not inside(im, o + t[:, None] * d).any()
        if mask[r, c]:
            after_inside.append(bool(inside(im, o + (t_hit + 1e-7) * d)))
    assert np.mean(after_inside) >= 0.98


def cup_camera():
    return Camera(eye=(0.0, 5.0, 0.0), target=(0.0, 0.0, 0.0), up=(0.0, 0.0, -1.0),
                  size=(64, 64), ortho_height=1.2, near=0.1, far=10.0)


def test_depth_object_sees_into_the_cup_the_visual_hull_fills_it(cup_images):
    im = cup_images
    camera = cup_camera()
    in_hole = None
    results = {}
    for name, images in (("depth", im), ("hull", visual_hull(im))):
        mask, position, face = exact_intersection(images, camera)
        if in_hole is None:
            in_hole = mask & (np.abs(position[..., 0]) < 0.4) & (np.abs(position[..., 2]) < 0.4)
            assert in_hole.sum() > 300
        assert mask[in_hole].all()
        results[name] = position[in_hole, 1], face[in_hole]
    depth_y, depth_face = results["depth"]
    hull_y, _ = results["hull"]
    np.testing.assert_allclose(depth_y, CUP_FLOOR, atol=im.texel)  # the floor of the hole
    assert (depth_face == CUBE_FACES.index("y")).all()
    np.testing.assert_allclose(hull_y, CUP_TOP, atol=im.texel)  # the hull fills the hole
    # and the carve agrees: the hole is empty in the depth object, full in the visual hull
    centres = (np.arange(N) + 0.5) / N
    world = transform_points(im.cube_to_world, np.stack(
        np.meshgrid(centres, centres, centres, indexing="ij")[::-1], -1))
    hole = (np.abs(world[..., 0]) < 0.45) & (np.abs(world[..., 2]) < 0.45) \
        & (world[..., 1] > CUP_FLOOR + 0.05) & (world[..., 1] < CUP_TOP - 0.05)
    assert not voxel_carve(im, N)[hole].any()
    assert voxel_carve(visual_hull(im), N)[hole].all()


def carve_hits(carve, images, camera, step=0.25):
    """First occupied carve voxel along each pixel's ray (marching in 1/4 voxels)."""
    n = carve.shape[0]
    origin, direction = rays(camera)
    world_to_cube = np.linalg.inv(images.cube_to_world)
    q0 = transform_points(world_to_cube, origin)
    q1 = transform_points(world_to_cube, origin + direction)
    dq = q1 - q0
    with np.errstate(divide="ignore", invalid="ignore"):
        s1, s2 = -q0 / dq, (1 - q0) / dq
    t_in = np.clip(np.nanmax(np.minimum(s1, s2), -1), 0, 1)
    t_out = np.clip(np.nanmin(np.maximum(s1, s2), -1), 0, 1)
    length = np.linalg.norm(dq, axis=-1)
    samples = int(np.ceil(np.sqrt(3) * n / step)) + 1
    ts = t_in[..., None] + (np.arange(samples) * step / n) / length[..., None]
    q = q0[..., None, :] + ts[..., None] * dq[..., None, :]
    valid = ts <= t_out[..., None]
    idx = np.clip(np.floor(q * n).astype(int), 0, n - 1)
    occupied = carve[idx[..., 2], idx[..., 1], idx[..., 0]] & valid
    hit = occupied.any(-1)
    first = np.argmax(occupied, -1)
    t = np.take_along_axis(ts, first[..., None], -1)[..., 0]
    return hit, np.where(hit[..., None], origin + t[..., None] * direction, np.nan)


@pytest.mark.parametrize("scene", ["sphere", "cup"])
def test_voxel_carve_agrees_with_the_exact_reference(scene, sphere_images, cup_images):
    im = {"sphere": sphere_images, "cup": cup_images}[scene]
    carve = voxel_carve(im, N)
    for camera in views(cube_centre(im), distance=4.0)[:3]:
        mask, position, _ = exact_intersection(im, camera)
        hit, carve_position = carve_hits(carve, im, camera)
        assert iou(mask, hit) >= 0.97
        both = mask & hit
        error = np.linalg.norm(position[both] - carve_position[both], axis=-1) / im.texel
        assert np.percentile(error, 95) <= 2.0
        assert np.percentile(error, 50) <= 1.0


def test_reference_refuses_other_inputs(box_images):
    with pytest.raises(UsageError, match="DepthImages"):
        exact_intersection(object(), views(np.zeros(3))[0])
    with pytest.raises(UsageError, match="grid size"):
        voxel_carve(box_images, 0)


def occupied_voxels(images) -> np.ndarray:
    """(N, N, N) bool [x, y, z]: the cube voxels where the nearest-texel object is not
    empty (its box there meets the voxel with a positive or zero extent on every axis), all
    N^3 at once from the column tables."""
    n = images.resolution
    b = images.column_bounds()  # (axis, lo/hi, i, j): x: [y, z], y: [x, z], z: [x, y]
    edges = np.arange(n + 1) / n

    def fits(lo, hi, cell_axis_shape):
        lo_c = edges[:-1].reshape(cell_axis_shape)
        hi_c = edges[1:].reshape(cell_axis_shape)
        return np.maximum(lo, lo_c) <= np.minimum(hi, hi_c)

    x = fits(b[0, 0][None, :, :], b[0, 1][None, :, :], (n, 1, 1))   # [x, y, z]
    y = fits(b[1, 0][:, None, :], b[1, 1][:, None, :], (1, n, 1))
    z = fits(b[2, 0][:, :, None], b[2, 1][:, :, None], (1, 1, n))
    return x & y & z


def test_occupied_voxels_hold_every_carved_voxel_centre(sphere_images):
    """A voxel whose centre is inside (the crude carve) meets the object's box there."""
    occupied = occupied_voxels(sphere_images).transpose(2, 1, 0)  # [z, y, x] like the carve
    carved = voxel_carve(sphere_images, N)
    assert carved.sum() > 1000
    assert not (carved & ~occupied).any()
    # and only the boundary layer differs: a box meeting a voxel without its centre
    assert occupied.sum() - carved.sum() < 0.1 * carved.sum()


def test_occupied_columns_are_the_voxels_any_along_each_axis(sphere_images, cup_images):
    """The bake report's per-column occupancy (N^2 memory) is the N^3 occupancy reduced."""
    for images in (sphere_images, cup_images, visual_hull(cup_images)):
        voxels = occupied_voxels(images)
        columns = occupied_columns(images)
        for axis in range(3):
            np.testing.assert_array_equal(columns[axis], voxels.any(axis=axis))
