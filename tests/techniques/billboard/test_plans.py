"""The billboard drawables as draw plans: plain data that survives JSON, drawn from a list of
cameras with one upload exactly as from each camera alone (the DMBBC's lod switch and
hand-over decided per view), by render modules that create no GL objects themselves."""

from __future__ import annotations

import json

import pytest
from billboard_scenes import stacked
from helpers import assert_same_frames

from reliefkit.core.technique import technique
from reliefkit.render import render
from reliefkit.render.plan import from_json, to_json
from reliefkit.scene.views import orbit_bounds
from reliefkit.techniques.billboard import bake_boxes, box_render
from reliefkit.techniques.billboard import render as cloud_render

SIZE = (64, 48)


@pytest.fixture(scope="module")
def scenes(gl):
    samples = technique("billboard").samples()
    shells = {variant: bake_boxes(stacked(), variant, epsilon=0.05, texel_size=0.1)
              for variant in ("shell", "thick-shell")}
    # three orbit distances in bounding radii (from inside the sample's box on): boxes
    # whole, flattening (with lod auto), the cloud
    sample, shell = (0.8, 1.3, 3.0), (2.4, 5.0, 40.0)
    return {"cloud": (samples["billboard-cloud"], {}, shell),
            "volumetric": (samples["dmbbc"], {}, sample),
            "volumetric exact flattened": (samples["dmbbc"], {"march": "exact",
                                                             "flatten": 0.4}, sample),
            "volumetric lod": (samples["dmbbc"], {"lod": "auto"}, sample),
            "shell lod": (shells["shell"], {"lod": "auto", "march": "uniform"}, shell),
            "thick shell": (shells["thick-shell"], {}, shell)}


def views(rep, distances) -> list:
    return [orbit_bounds(rep.bounds, 30.0 + 70.0 * k, 25.0 - 20.0 * k, distance, size=SIZE)
            for k, distance in enumerate(distances)]


@pytest.mark.parametrize("name", ["cloud", "volumetric", "volumetric exact flattened",
                                  "volumetric lod", "shell lod", "thick shell"])
@pytest.mark.parametrize("counted", [False, True], ids=["plain", "counted"])
def test_a_list_of_cameras_draws_each_as_alone(scenes, name, counted):
    rep, options, distances = scenes[name]
    cameras = views(rep, distances)
    together = render(rep, cameras, count_iterations=counted, **options)
    for camera, frame in zip(cameras, together, strict=True):
        assert_same_frames(frame, render(rep, camera, count_iterations=counted, **options))
    assert all(f.mask.any() for f in together[:2])
    if options.get("lod") == "auto":  # one upload, both levels of detail
        assert [f.stats["lod"] for f in together] == ["boxes", "boxes", "billboard cloud"]
        assert 0.0 < together[1].stats["flatten"] < 1.0  # the hand-over


@pytest.mark.parametrize("name", ["cloud", "volumetric lod", "shell lod", "thick shell"])
def test_plans_survive_json_and_draw_the_same_frames(scenes, name, monkeypatch):
    rep, options, distances = scenes[name]
    cameras = views(rep, distances)
    direct = render(rep, cameras, **options)
    cls = cloud_render.BillboardCloudDrawable if name == "cloud" else \
        box_render.BillboardBoxesDrawable
    made = cls.__init__

    def from_file(self, *args, **kwargs):
        made(self, *args, **kwargs)
        doc, arrays = to_json(self.plans)
        self.plans = from_json(json.loads(json.dumps(doc)), dict(arrays))

    monkeypatch.setattr(cls, "__init__", from_file)
    for a, b in zip(direct, render(rep, cameras, **options), strict=True):
        assert_same_frames(a, b)
