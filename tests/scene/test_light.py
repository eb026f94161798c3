"""`DirectionalLight.from_angles`: the angle conventions of --view, and a default light that
shows shadows (the demo terrain relief, robust method, from the default view)."""

from __future__ import annotations

import numpy as np
import pytest

from reliefkit.errors import UsageError
from reliefkit.scene.camera import Camera
from reliefkit.scene.light import DEFAULT_LIGHT_ANGLES, DirectionalLight
from reliefkit.scene.views import DEFAULT_VIEW, parse_light


@pytest.mark.parametrize("az, el", [(0, 0), (90, 0), (-60, 30), (135, -20), (10, 90)])
def test_angles_match_the_camera_orbit(az, el):
    """A light at the angles of a camera shines from where that camera stands."""
    camera = Camera.orbit((1.0, 2.0, 3.0), az, el, 5.0)
    towards_eye = np.subtract(camera.eye, camera.target) / 5.0
    light = DirectionalLight.from_angles(az, el, intensity=0.5)
    np.testing.assert_allclose(light.unit_direction, towards_eye, atol=1e-12)
    assert light.intensity == 0.5
    if abs(el) < 90:
        np.testing.assert_allclose(light.angles, (az, el), atol=1e-9)


def test_axes():
    np.testing.assert_allclose(DirectionalLight.from_angles(0, 0).direction, (0, 0, 1),
                               atol=1e-12)
    np.testing.assert_allclose(DirectionalLight.from_angles(90, 0).direction, (1, 0, 0),
                               atol=1e-12)
    np.testing.assert_allclose(DirectionalLight.from_angles(0, 90).direction, (0, 1, 0),
                               atol=1e-12)


def test_bad_angles_are_usage_errors():
    for az, el in [(0, 91), (float("nan"), 10), (0, float("inf"))]:
        with pytest.raises(UsageError):
            DirectionalLight.from_angles(az, el)
    for text in ("1", "a,b", "1,2,3", "0,95"):
        with pytest.raises(UsageError, match="--light"):
            parse_light(text)
    assert parse_light("-40,30") == (-40.0, 30.0)


def test_default_light_rakes_from_the_side_of_the_default_view():
    az, el = DirectionalLight().angles
    np.testing.assert_allclose((az, el), DEFAULT_LIGHT_ANGLES, atol=1e-9)
    assert el <= 35, "a high sun casts short shadows"
    apart = abs((az - DEFAULT_VIEW[0] + 180) % 360 - 180)
    assert 60 <= apart <= 120, "light from behind the camera hides the shadows it casts"


def test_default_light_shows_shadows_on_the_demo_terrain(gl):
    from reliefkit.bake import bake
    from reliefkit.render import render
    from reliefkit.scene.assets import make_asset
    from reliefkit.scene.views import framing_bounds, orbit_bounds

    relief = bake(make_asset("terrain"), "relief", depth_res=128)
    camera = orbit_bounds(framing_bounds(relief), DEFAULT_VIEW[0], DEFAULT_VIEW[1], None,
                          (160, 160))
    lit = render(relief, camera, method="robust")
    shadowed = render(relief, camera, method="robust", shadows=True)
    both = lit.mask & shadowed.mask
    darker = both & (shadowed.color[..., :3].mean(-1) < 0.9 * lit.color[..., :3].mean(-1))
    assert darker.sum() > 0.05 * both.sum(), f"{darker.sum()} of {both.sum()} pixels shadowed"
