"""Baking the six depth images of the cube: conventions against an analytic box."""

import numpy as np
import pytest
from slicing_scenes import BOX_HI, BOX_LO, box_mesh, cup_mesh

from reliefkit.bake.project import CUBE_FACES, axis_frame
from reliefkit.core.transforms import transform_points
from reliefkit.errors import UsageError
from reliefkit.techniques.slicing.depth_images import (
    MARGIN,
    DepthImages,
    bake_depth_images,
    visual_hull,
)

N = 64


@pytest.fixture(scope="module")
def box_images(gl):
    return bake_depth_images(box_mesh(), N)


def test_cube_is_the_enlarged_bounding_cube(box_images):
    side = (BOX_HI - BOX_LO).max() * (1 + 2 * MARGIN)
    assert box_images.side == pytest.approx(side)
    corners = transform_points(box_images.cube_to_world, np.array([[0, 0, 0], [1, 1, 1.0]]))
    np.testing.assert_allclose(corners.mean(axis=0), (BOX_LO + BOX_HI) / 2)
    np.testing.assert_allclose(corners[1] - corners[0], side)


def test_face_boxes_point_out_of_their_faces(box_images):
    centre = transform_points(box_images.cube_to_world, np.full(3, 0.5))
    for k, face in enumerate(CUBE_FACES):
        box = box_images.box_to_world[k]
        h_dir = axis_frame(face)[2]
        top = transform_points(box, np.array([0.5, 0.5, 1.0]))  # centre of face k
        np.testing.assert_allclose(top - centre, 0.5 * box_images.side * h_dir, atol=1e-12)
        corners = transform_points(box, np.array([[0, 0, 0], [1, 1, 1.0]]))
        np.testing.assert_allclose(np.sort(corners, axis=0),
                                   transform_points(box_images.cube_to_world,
                                                    np.array([[0, 0, 0], [1, 1, 1.0]])),
                                   atol=1e-12)


def test_box_depths_are_constant_and_analytic(box_images):
    im = box_images
    n = im.resolution
    lo_cube = transform_points(np.linalg.inv(im.cube_to_world), BOX_LO)
    hi_cube = transform_points(np.linalg.inv(im.cube_to_world), BOX_HI)
    centres = (np.arange(n) + 0.5) / n
    uu, vv = np.meshgrid(centres, centres)
    for k, face in enumerate(CUBE_FACES):
        frame = axis_frame(face)
        corner = 0.5 - 0.5 * frame.sum(axis=0)
        q = corner + uu[..., None] * frame[0] + vv[..., None] * frame[1]
        axis = int(np.argmax(np.abs(frame[2])))
        others = [a for a in range(3) if a != axis]
        expected_mask = np.ones((n, n), bool)
        for a in others:
            expected_mask &= (q[..., a] > lo_cube[a]) & (q[..., a] < hi_cube[a])
        assert np.array_equal(im.mask[k], expected_mask), face
        expected = 1 - hi_cube[axis] if frame[2, axis] > 0 else lo_cube[axis]
        np.testing.assert_allclose(im.depth[k][im.mask[k]], expected, atol=2e-4)
        assert (im.depth[k][~im.mask[k]] == 1).all()
        assert np.abs(im.color[k][im.mask[k]] - [0.8, 0.5, 0.2, 1.0]).max() < 1e-3


def test_visual_hull_fills_every_covered_column(box_images):
    hull = visual_hull(box_images)
    assert np.array_equal(hull.mask, box_images.mask)
    assert (hull.depth[hull.mask] == 0).all() and (hull.depth[~hull.mask] == 1).all()


def test_cup_seen_from_above_shows_its_floor(gl):
    im = bake_depth_images(cup_mesh(), N)
    k = CUBE_FACES.index("y")
    n = im.resolution
    centre = im.depth[k][n // 2 - 2:n // 2 + 2, n // 2 - 2:n // 2 + 2]
    # the cube spans y in [0.5 - side/2, 0.5 + side/2]; the floor is at y = 0.4
    expected = (0.5 + im.side / 2 - 0.4) / im.side
    np.testing.assert_allclose(centre, expected, atol=2e-4)


@pytest.mark.parametrize("resolution", [0, 1, 2.5, True, "64", 10 ** 6])
def test_bad_resolution_is_a_usage_error(resolution):
    with pytest.raises(UsageError, match="resolution"):
        bake_depth_images(box_mesh(), resolution)


def test_bad_arrays_are_usage_errors(box_images):
    im = box_images
    with pytest.raises(UsageError, match="shape"):
        DepthImages(im.depth[:5], im.mask, im.color, im.normal, im.box_to_world,
                    im.cube_to_world)
    with pytest.raises(UsageError, match="mask"):
        DepthImages(im.depth, im.mask[:, :2], im.color, im.normal, im.box_to_world,
                    im.cube_to_world)
    with pytest.raises(UsageError, match=r"\[0, 1\]"):
        DepthImages(im.depth * 2, im.mask, im.color, im.normal, im.box_to_world,
                    im.cube_to_world)


@pytest.mark.parametrize("side", [1e-200, 1e300])
def test_a_cube_no_float_can_hold_is_refused(box_images, side):
    """A forged .rk cube whose side squares to 0 or overflows is a one-line error, not a
    singular matrix when it is drawn."""
    from reliefkit.errors import FormatError
    from reliefkit.techniques.slicing.codec import CODECS

    im = box_images
    cube = np.eye(4) * side
    cube[3, 3] = 1.0
    arrays = {"depth": im.depth, "mask": im.mask.astype(np.uint8), "color": im.color,
              "normal": im.normal, "cube_to_world": cube}
    with pytest.raises(FormatError, match="cube side must be within"):
        CODECS[0].from_arrays(arrays, {})


def test_a_mesh_too_small_for_float32_draws_is_refused(gl):
    from reliefkit.scene.mesh import RenderMesh

    mesh = box_mesh()
    tiny = RenderMesh(mesh.world_positions * 1e-32, mesh.indices, mesh.normals, mesh.colors,
                      name="tiny box")
    with pytest.raises(UsageError, match="cube side must be within"):
        bake_depth_images(tiny, 8)


def test_a_bake_over_the_host_memory_limit_is_refused_before_drawing(gl, monkeypatch):
    """Res 32 needs 6 x 32² texels x 76 B = 456 KiB at its peak: with the host-memory limit
    one byte below, it is refused with that estimate before any face is drawn; res 31 fits."""
    import reliefkit.gl.targets as targets
    import reliefkit.techniques.slicing.depth_images as depth_images

    monkeypatch.setattr(targets, "host_limit", lambda: 6 * 32**2 * 76 - 1)
    drawn = []
    project = depth_images.project_mesh
    monkeypatch.setattr(depth_images, "project_mesh",
                        lambda *a, **k: drawn.append(1) or project(*a, **k))
    with pytest.raises(UsageError, match=r"res 32: .*456\.0 KiB of host memory.* at most 31"):
        bake_depth_images(box_mesh(), 32)
    assert not drawn
    assert bake_depth_images(box_mesh(), 31).resolution == 31
    assert len(drawn) == 6
