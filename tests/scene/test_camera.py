"""Camera matrices against an independent numpy model of the OpenGL conventions."""

import numpy as np
import pytest

from reliefkit.errors import UsageError
from reliefkit.scene.camera import Camera


def _project(camera, point):
    clip = camera.proj @ camera.view @ np.append(point, 1.0)
    return clip[:3] / clip[3]


def test_view_matrix_is_rigid_and_puts_eye_at_origin():
    cam = Camera(eye=(1.0, 2.0, 3.0), target=(0.5, -1.0, 0.0))
    view = cam.view
    np.testing.assert_allclose(view[:3, :3] @ view[:3, :3].T, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(np.linalg.det(view[:3, :3]), 1.0, atol=1e-12)
    np.testing.assert_allclose(view @ [1.0, 2.0, 3.0, 1.0], [0, 0, 0, 1], atol=1e-12)
    target_eye = view @ [0.5, -1.0, 0.0, 1.0]
    assert target_eye[2] < 0  # camera looks down -z
    np.testing.assert_allclose(target_eye[:2], 0.0, atol=1e-12)


def test_perspective_matches_glu_formula():
    cam = Camera(eye=(0, 0, 5), target=(0, 0, 0), fov_deg=60.0, size=(200, 100), near=0.5,
                 far=50.0)
    f = 1.0 / np.tan(np.radians(30.0))
    expected = np.array([[f / 2.0, 0, 0, 0], [0, f, 0, 0],
                         [0, 0, (50.5) / (0.5 - 50.0), 2 * 50.0 * 0.5 / (0.5 - 50.0)],
                         [0, 0, -1, 0]])
    np.testing.assert_allclose(cam.proj, expected, rtol=1e-12)
    # near and far planes map to NDC z = -1 and +1
    np.testing.assert_allclose(_project(cam, [0, 0, 4.5])[2], -1.0, atol=1e-9)
    np.testing.assert_allclose(_project(cam, [0, 0, -45.0])[2], 1.0, atol=1e-9)
    # the top edge of the frustum at depth d is at y = d * tan(fov/2)
    np.testing.assert_allclose(_project(cam, [0, 2 * np.tan(np.radians(30)), 3.0])[1], 1.0)


def test_orthographic_maps_view_volume_to_unit_cube():
    cam = Camera(eye=(0, 0, 10), target=(0, 0, 0), size=(100, 50), near=1.0, far=21.0,
                 ortho_height=2.0)
    np.testing.assert_allclose(_project(cam, [4.0, 2.0, 9.0]), [1, 1, -1], atol=1e-12)
    np.testing.assert_allclose(_project(cam, [-4.0, -2.0, -11.0]), [-1, -1, 1], atol=1e-12)


@pytest.mark.parametrize("az, el, expected", [
    (0, 0, [0, 0, 3]), (90, 0, [3, 0, 0]), (180, 0, [0, 0, -3]), (0, 90 - 1e-9, [0, 3, 0])])
def test_orbit_convention(az, el, expected):
    cam = Camera.orbit((1.0, 1.0, 1.0), az, el, 3.0)
    np.testing.assert_allclose(np.array(cam.eye) - 1.0, expected, atol=1e-6)


def test_pixel_rays_go_through_pixel_centres_top_row_first():
    cam = Camera.orbit((0, 0, 0), 20, 10, 4.0, size=(8, 6))
    origins, dirs = cam.pixel_rays()
    for r, c in [(0, 0), (5, 7), (2, 3)]:
        point = origins[r, c] + 2.0 * dirs[r, c]
        ndc = _project(cam, point)
        window = ((ndc[0] + 1) * 4, (ndc[1] + 1) * 3)
        np.testing.assert_allclose(window, (c + 0.5, 6 - 1 - r + 0.5), atol=1e-9)


@pytest.mark.parametrize("kwargs", [dict(size=(0, 10)), dict(near=0.0), dict(near=2.0, far=1.0),
                                    dict(fov_deg=180.0), dict(eye=(0, np.nan, 1))])
def test_bad_camera_arguments(kwargs):
    base = dict(eye=(0, 0, 5), target=(0, 0, 0))
    with pytest.raises(UsageError):
        Camera(**(base | kwargs))
