"""Relief textures as draw plans: drawn from several cameras in one call, and read back from
JSON plus arrays, they give the frames of single renders bit for bit."""

import io
import json

import numpy as np
import pytest
from helpers import BOX, assert_same_frames, make_relief, sample

from reliefkit.render import render
from reliefkit.render.draw import Scene
from reliefkit.render.plan import from_json, to_json
from reliefkit.scene.camera import Camera
from reliefkit.scene.views import orbit_bounds
from reliefkit.techniques.relief.render import METHODS

TALL = BOX @ np.diag([1.0, 1.0, 4.0, 1.0])  # box height 4: a camera fits inside
#: robust walks the small test fields exactly unless told to jump
JUMP = {"robust": {"exact_field": 0}}


def bumps(n=24):
    u, v = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n))
    return (0.1 + 0.05 * np.sin(7 * u) * np.cos(5 * v)).astype(np.float32)


# outside the box (its back faces culled) and inside it (its front faces culled), each
# measuring world space from its own target
OUTSIDE = Camera.orbit((0.2, 0.3, 0.1), 30, 35, 5.0, size=(48, 40))
INSIDE = Camera(eye=(0.1, 2.0, 0.2), target=(0.3, 0.5, -0.2), size=(48, 40), fov_deg=60,
                near=0.01, far=10.0)


@pytest.mark.parametrize("method", METHODS)
def test_a_relief_texture_from_two_views_in_one_call_equals_two_renders(gl, method):
    relief = make_relief(bumps(), TALL)
    options = {"method": method, "count_iterations": True, **JUMP.get(method, {})}
    both = render(relief, [OUTSIDE, INSIDE], **options)
    for frame, camera in zip(both, (OUTSIDE, INSIDE), strict=True):
        assert frame.mask.mean() > 0.1
        assert_same_frames(frame, render(relief, camera, **options))


def test_a_relief_object_from_two_views_in_one_call_equals_two_renders(gl):
    obj = sample("relief", "relief-object")
    cameras = [orbit_bounds(obj.bounds, 30, 35, 2.4, size=(48, 40)),
               orbit_bounds(obj.bounds, 200, -20, 1.6, size=(48, 40))]
    both = render(obj, cameras, count_iterations=True)
    for frame, camera in zip(both, cameras, strict=True):
        assert frame.mask.any()
        assert_same_frames(frame, render(obj, camera, count_iterations=True))


def _through_json(plans):
    """``plans`` written as JSON text and an .npz of their arrays, and read back."""
    doc, arrays = to_json(plans)
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    buffer.seek(0)
    with np.load(buffer) as stored:
        return from_json(json.loads(json.dumps(doc)), dict(stored))


OCTANTS = np.ones((8, 24, 24), np.uint8)


@pytest.mark.parametrize("case", [
    *((f"relief {m}", lambda: sample("relief", "relief"), {"method": m, **JUMP.get(m, {})})
      for m in METHODS),
    ("relief robust octants", lambda: make_relief(bumps(), TALL, safety=OCTANTS),
     {"method": "robust", "exact_field": 0, "shadows": True}),
    ("relief object", lambda: sample("relief", "relief-object"), {"depth_mode": "exact"}),
], ids=lambda case: case[0])
def test_plans_read_back_from_json_draw_the_same_frame(gl, case):
    _, make, options = case
    rep = make()
    camera = orbit_bounds(rep.bounds, 30, 35, 2.4, size=(48, 40))
    expected = render(rep, camera, ctx=gl, **options)
    with Scene(rep, ctx=gl, **options) as scene:
        drawable = scene.drawables[0]
        drawable.plans = _through_json(drawable.plans)
        scene.executor.upload(drawable.plans)
        assert_same_frames(scene.frame(camera), expected)
