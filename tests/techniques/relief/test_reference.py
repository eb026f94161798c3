"""The camera-level exact reference (reference.py) for every relief kind, projective boxes too.

Independent checks: the reference's hits lie on the bilinear surface of the part they hit,
the exact GPU walk agrees with it to within one texel on the demo assets (a frustum's ray can
cross the plane at infinity of its projective box, which a world segment mapped point by
point folds back into the box), and parts are ordered along the ray.
"""

from __future__ import annotations

import numpy as np
import pytest

from reliefkit.reference.heightfield import surface_height
from reliefkit.render import render
from reliefkit.scene.assets import make_asset
from reliefkit.scene.camera import Camera
from reliefkit.scene.views import orbit_bounds
from reliefkit.techniques.relief.bake import bake_relief
from reliefkit.techniques.relief.frustum import bake_relief_cube, bake_relief_frustum
from reliefkit.techniques.relief.reference import reference_hits, wrong_hits
from reliefkit.techniques.relief.representation import ReliefObject

BAKES = {
    "relief": lambda: bake_relief(make_asset("vehicle"), 96, safety=False),
    "relief-frustum": lambda: bake_relief_frustum(make_asset("vehicle"), depth_res=96,
                                                  safety=False),
    "relief-cube": lambda: bake_relief_cube(make_asset("blob"), depth_res=48, safety=False),
}
VIEWS = [(30, 25, 2.6), (200, 10, 2.2), (110, 60, 3.0)]


@pytest.fixture(scope="module", params=list(BAKES))
def baked(request):
    return request.param, BAKES[request.param]()


def _camera(rep, view, orthographic=False):
    lo, hi = rep.bounds
    if orthographic:
        az, el, dist = np.radians(view[0]), np.radians(view[1]), view[2]
        centre = (lo + hi) / 2
        r = np.linalg.norm(hi - lo) / 2
        eye = centre + dist * r * np.array([np.cos(el) * np.sin(az), np.sin(el),
                                            np.cos(el) * np.cos(az)])
        return Camera(eye=tuple(eye), target=tuple(centre), size=(80, 64), ortho_height=r,
                      near=0.01 * r, far=10 * r)
    return orbit_bounds(rep.bounds, *view, size=(80, 64))


@pytest.mark.parametrize("view", VIEWS)
def test_reference_hits_lie_on_the_surface(baked, view):
    kind, rep = baked
    mask, position, part_of = reference_hits(rep, _camera(rep, view))
    assert mask.sum() > 200
    parts = rep.parts if isinstance(rep, ReliefObject) else [rep]
    for index, part in enumerate(parts):
        here = mask & (part_of == index)
        if not here.any():
            continue
        box = part.to_box(position[here])
        assert (box > -1e-6).all() and (box < 1 + 1e-6).all()
        hh, ww = part.height.shape
        surface = surface_height(part.height, box[:, 0] * ww, box[:, 1] * hh)
        on_wall = np.minimum(box[:, :2], 1 - box[:, :2]).min(axis=1) < 1e-6
        np.testing.assert_allclose(box[~on_wall, 2], surface[~on_wall], atol=1e-6)


@pytest.mark.parametrize("orthographic", [False, True], ids=["perspective", "orthographic"])
@pytest.mark.parametrize("view", VIEWS)
def test_exact_walk_agrees_with_the_reference(gl, baked, view, orthographic):
    kind, rep = baked
    camera = _camera(rep, view, orthographic)
    frame = render(rep, camera, method="exact")
    wrong = wrong_hits(frame, rep, camera)
    assert wrong["reference_pixels"] > 200
    assert wrong["wrong_fraction"] <= 0.001, (kind, wrong)
