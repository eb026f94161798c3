"""Slice geometry (§3): exact screen-space slices, orthogonal slices, surface slices."""

import numpy as np
import pytest

from reliefkit.errors import UsageError
from reliefkit.scene.camera import Camera, MatrixCamera
from reliefkit.techniques.slicing.slices import (
    best_axis,
    orthogonal_slices,
    screen_slices,
)


def unit_cube():
    return np.eye(4)


def sheared_box():
    """A sheared, rotated, non-uniformly scaled parallelepiped away from the origin."""
    c, s = np.cos(0.7), np.sin(0.7)
    rot = np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]) @ np.array(
        [[1, 0, 0], [0, np.cos(0.4), -np.sin(0.4)], [0, np.sin(0.4), np.cos(0.4)]])
    shear = np.array([[1.0, 0.3, 0.2], [0.0, 1.0, -0.25], [0.0, 0.0, 1.0]])
    m = np.eye(4)
    m[:3, :3] = rot @ shear @ np.diag([1.5, 0.8, 0.6])
    m[:3, 3] = [0.3, -0.2, 0.5]
    return m


BOXES = {"cube": unit_cube, "sheared": sheared_box}


def centre(box):
    return (box @ [0.5, 0.5, 0.5, 1.0])[:3]


def cameras(box):
    t = tuple(centre(box))
    return [
        Camera.orbit(t, 30, 20, 5.0),
        Camera.orbit(t, -120, -50, 4.0, fov_deg=50),
        Camera.orbit(t, 200, 70, 6.0, ortho_height=2.0),
        # perspective, not looking at the box centre
        Camera(eye=(t[0] + 3, t[1] + 1, t[2] + 4), target=(t[0] + 0.4, t[1], t[2])),
    ]


def _cases():
    for name, make in BOXES.items():
        for i, cam in enumerate(cameras(make())):
            yield pytest.param(make(), cam, id=f"{name}-{i}")


CASES = list(_cases())


def project(camera, x):
    clip = (camera.proj @ camera.view @ np.c_[x, np.ones(len(x))].T).T
    assert (clip[:, 3] > 0).all()
    return clip[:, :2] / clip[:, 3:4]


def to_box(box, x):
    return (np.linalg.inv(box) @ np.c_[x, np.ones(len(x))].T).T[:, :3]


def eye_distance(camera, stack, k):
    """Distance from the eye to slice k's plane."""
    return stack.plane_normal @ np.asarray(camera.eye) - stack.plane_offset[k]


@pytest.mark.parametrize("box, camera", CASES)
def test_screen_polygons_are_exact_convex_ccw_and_on_the_boundary(box, camera):
    stack = screen_slices(box, camera, 40)
    assert stack.positions.dtype == np.float64 and stack.box.dtype == np.float64
    assert stack.triangles.dtype == np.int32 and stack.slice_of_triangle.dtype == np.int32
    np.testing.assert_allclose(to_box(box, stack.positions), stack.box, atol=1e-9)
    assert stack.slice_count == 40
    for k in range(stack.slice_count):
        tri = stack.slice_triangles(k)
        assert (stack.slice_of_triangle[stack.first_triangle[k]:stack.first_triangle[k + 1]]
                == k).all()
        n = len(tri) + 2
        assert 3 <= n <= 6
        idx = np.concatenate([tri[:1, 0], tri[:, 1], tri[-1:, 2]])  # the fan's polygon
        assert len(set(idx.tolist())) == n
        x, q = stack.positions[idx], stack.box[idx]
        # in the plane
        np.testing.assert_allclose(x @ stack.plane_normal, stack.plane_offset[k], atol=1e-9)
        # on the box boundary
        assert (q >= -1e-9).all() and (q <= 1 + 1e-9).all()
        assert (np.minimum(np.abs(q), np.abs(q - 1)).min(axis=1) <= 1e-9).all()
        # convex and counter-clockwise on screen
        p = project(camera, x)
        e = np.roll(p, -1, axis=0) - p
        turn = e[:, 0] * np.roll(e, -1, axis=0)[:, 1] - e[:, 1] * np.roll(e, -1, axis=0)[:, 0]
        assert (turn > 0).all()


def point_in_polygon(pts2, poly2):
    """Points strictly inside a CCW convex polygon (2D), and their minimum edge distance."""
    e = np.roll(poly2, -1, axis=0) - poly2
    rel = pts2[:, None, :] - poly2[None]
    cross = (e[None, :, 0] * rel[..., 1] - e[None, :, 1] * rel[..., 0]) / np.linalg.norm(e, axis=1)
    return cross.min(axis=1)


@pytest.mark.parametrize("box, camera", CASES)
def test_screen_polygons_are_exactly_the_cross_sections(box, camera):
    rng = np.random.default_rng(3)
    stack = screen_slices(box, camera, 12)
    n = stack.plane_normal
    e1 = np.cross(n, [0.3, 1.0, 0.2])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    # random points in the box -> pushed onto a random slice's plane
    inside = (box @ np.c_[rng.random((4000, 3)), np.ones(4000)].T).T[:, :3]
    ks = rng.integers(0, stack.slice_count, 4000)
    on_plane = inside - ((inside @ n) - stack.plane_offset[ks])[:, None] * n
    q = to_box(box, on_plane)
    margin = np.minimum(q, 1 - q).min(axis=1)
    hits = misses = 0
    for k in range(stack.slice_count):
        tri = stack.slice_triangles(k)
        idx = np.concatenate([tri[:1, 0], tri[:, 1], tri[-1:, 2]])
        poly = stack.positions[idx]
        sel = (ks == k) & (np.abs(margin) > 1e-6)
        pts = on_plane[sel]
        d = point_in_polygon(np.c_[pts @ e1, pts @ e2], np.c_[poly @ e1, poly @ e2])
        # e1 x e2 = n, so CCW about n is CCW in (e1, e2)
        np.testing.assert_array_equal(d > 0, margin[sel] > 0)
        hits += int((d > 0).sum())
        misses += int((d <= 0).sum())
        # and no other slice's polygon contains them (different planes)
        others = [j for j in range(stack.slice_count) if j != k]
        assert np.all(np.abs(stack.plane_offset[others] - stack.plane_offset[k]) > 1e-6)
    assert hits > 500 and misses > 100  # both sides of the polygons' edges were sampled


@pytest.mark.parametrize("box, camera", CASES)
def test_screen_slices_cavalieri_and_front_to_back(box, camera):
    stack = screen_slices(box, camera, 256)
    volume = abs(np.linalg.det(box[:3, :3]))
    assert stack.slice_areas().sum() * stack.spacing == pytest.approx(volume, rel=0.01)
    dist = [eye_distance(camera, stack, k) for k in stack.front_to_back]
    assert np.all(np.diff(dist) > 0)
    np.testing.assert_array_equal(stack.back_to_front, stack.front_to_back[::-1])
    assert len(stack.triangles_in_order()) == len(stack.triangles)
    assert stack.area_pixels(camera) > 0


def test_screen_planes_face_an_orthographic_view_exactly():
    cam = Camera.orbit((0.5, 0.5, 0.5), 33, 21, 5.0, ortho_height=1.5)
    stack = screen_slices(unit_cube(), cam, 5)
    f = np.subtract(cam.target, cam.eye)
    np.testing.assert_allclose(stack.plane_normal, -f / np.linalg.norm(f))
    # the slices span the box between its nearest and farthest corners
    corners = np.array([[i & 1, (i >> 1) & 1, (i >> 2) & 1] for i in range(8)], float)
    span = np.ptp(corners @ stack.plane_normal)
    assert stack.spacing * 5 == pytest.approx(span)


def test_screen_slice_of_a_cube_along_its_diagonal_is_a_hexagon():
    cam = Camera(eye=(3, 3, 3), target=(0.5, 0.5, 0.5), ortho_height=2.0)
    stack = screen_slices(unit_cube(), cam, 3)
    assert [len(stack.slice_triangles(k)) + 2 for k in range(3)] == [3, 6, 3]


def test_matrix_camera_looks_along_minus_view_dir():
    cam = MatrixCamera(view=np.eye(4), proj=np.eye(4), size=(8, 8), view_dir=(0.0, 0.0, 1.0))
    stack = screen_slices(unit_cube(), cam, 4)
    np.testing.assert_allclose(stack.plane_normal, [0, 0, 1])
    # viewer on +z: nearest slice has the largest z
    z = [stack.box[stack.slice_triangles(k)[0, 0], 2] for k in stack.front_to_back]
    np.testing.assert_allclose(z, [0.875, 0.625, 0.375, 0.125])
    assert orthogonal_slices(unit_cube(), cam, 4).axis == 2


@pytest.mark.parametrize("axis, offset", [(0, (1, 0, 0)), (0, (-1, 0, 0)), (1, (0, 1, 0)),
                                          (1, (0, -1, 0)), (2, (0, 0, 1)), (2, (0, 0, -1))])
def test_orthogonal_picks_the_axis_along_the_view(axis, offset):
    c = np.array([0.5, 0.5, 0.5])
    for ortho in (None, 1.0):
        up = (0, 0, 1) if axis == 1 else (0, 1, 0)
        cam = Camera(eye=tuple(c + 4 * np.array(offset)), target=tuple(c), up=up,
                     ortho_height=ortho)
        stack = orthogonal_slices(unit_cube(), cam, 10)
        assert stack.axis == axis
        np.testing.assert_allclose(stack.plane_normal, offset, atol=1e-12)
        dist = [eye_distance(cam, stack, k) for k in stack.front_to_back]
        assert np.all(np.diff(dist) > 0)
        assert len(stack.triangles) == 20
        # full cross-sections: every vertex on the box's edges
        assert np.isin(np.delete(stack.box, axis, axis=1), [0.0, 1.0]).all()
        for k in range(10):
            p = project(cam, stack.positions[np.unique(stack.slice_triangles(k))])
            assert np.ptp(p, axis=0).min() > 0
        # CCW on screen
        t = project(cam, stack.positions[stack.triangles.ravel()]).reshape(-1, 3, 2)
        d1, d2 = t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]
        assert (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0] > 0).all()


def test_orthogonal_ties_at_45_degrees():
    c = (0.5, 0.5, 0.5)
    # between u and v (horizontal 45 degrees, looking down the xy-diagonal): u wins
    cam = Camera(eye=(3.5, 3.5, 0.5), target=c, up=(0, 0, 1), ortho_height=1.0)
    assert best_axis(unit_cube(), cam) == 0
    # between u and h: h wins, and between v and h: h wins
    assert best_axis(unit_cube(), Camera(eye=(3.5, 0.5, 3.5), target=c, ortho_height=1.0)) == 2
    assert best_axis(unit_cube(), Camera(eye=(0.5, 3.5, 3.5), target=c, ortho_height=1.0)) == 2
    # the main diagonal: h
    assert best_axis(unit_cube(), Camera(eye=(3, 3, 3), target=c, ortho_height=1.0)) == 2
    # just off the tie, the nearer axis wins
    assert best_axis(unit_cube(), Camera(eye=(3.5, 3.6, 0.5), target=c, up=(0, 0, 1),
                                         ortho_height=1.0)) == 1
    assert best_axis(unit_cube(), Camera(eye=(3.6, 0.5, 3.5), target=c,
                                         ortho_height=1.0)) == 0


def test_orthogonal_on_a_sheared_box_uses_the_slice_plane_normals():
    box = sheared_box()
    g = np.linalg.inv(box[:3, :3])
    for axis in range(3):
        n = g[axis] / np.linalg.norm(g[axis])
        cam = Camera(eye=tuple(centre(box) + 5 * n), target=tuple(centre(box)),
                     up=(0.3, 0.2, 0.9) if abs(n[1]) > 0.9 else (0, 1, 0), ortho_height=2.0)
        stack = orthogonal_slices(box, cam, 7)
        assert stack.axis == axis
        np.testing.assert_allclose(stack.plane_normal, n, atol=1e-12)
        np.testing.assert_allclose(to_box(box, stack.positions), stack.box, atol=1e-12)
        q = stack.box[:, axis][stack.triangles[:, 0]]
        np.testing.assert_allclose(np.unique(q), (np.arange(7) + 0.5) / 7)
        volume = abs(np.linalg.det(box[:3, :3]))
        assert stack.slice_areas().sum() * stack.spacing == pytest.approx(volume)


@pytest.mark.parametrize("count", [0, -3, 2.5, "4", True, None])
def test_bad_counts_are_refused(count):
    cam = Camera.orbit((0.5, 0.5, 0.5), 10, 10, 4.0)
    for call in (lambda: screen_slices(unit_cube(), cam, count),
                 lambda: orthogonal_slices(unit_cube(), cam, count)):
        with pytest.raises(UsageError):
            call()


def test_bad_boxes_and_views_are_refused():
    cam = Camera.orbit((0.5, 0.5, 0.5), 10, 10, 4.0)
    for box in (np.diag([1.0, 1.0, 0.0, 1.0]), np.eye(3), np.full((4, 4), np.nan),
                np.eye(4) + np.eye(4, k=-3)):
        with pytest.raises(UsageError):
            screen_slices(box, cam, 4)
    inside = Camera(eye=(0.5, 0.5, 0.5), target=(1.0, 0.5, 0.5))
    with pytest.raises(UsageError):
        screen_slices(unit_cube(), inside, 4)
    with pytest.raises(UsageError):
        orthogonal_slices(unit_cube(), cam, 4, axis=5)


def test_a_mirrored_box_still_gives_ccw_slices():
    box = np.diag([-1.0, 1.0, 1.0, 1.0])
    box[0, 3] = 1.0  # x in [0, 1] again, but u runs along -x
    cam = Camera.orbit((0.5, 0.5, 0.5), 40, 25, 4.0)
    for stack in (screen_slices(box, cam, 9), orthogonal_slices(box, cam, 9)):
        t = project(cam, stack.positions[stack.triangles.ravel()]).reshape(-1, 3, 2)
        d1, d2 = t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]
        assert (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0] > 0).all()
