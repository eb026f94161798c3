"""`compare`'s sheet: the coverage tile is the default variant's, named, whatever comes last."""

from __future__ import annotations

import numpy as np
from slicing_scenes import cup_mesh

from reliefkit import metrics
from reliefkit.bake import bake
from reliefkit.compare import compare, comparison_tiles
from reliefkit.scene.views import framing_bounds, orbit_bounds


def test_coverage_tile_shows_the_default_variant_named(gl):
    """The cup's depth object sees into the cup, its visual hull (the last variant) fills
    it: from above the two cover different pixels, and the tile is the depth object's."""
    mesh = cup_mesh()
    rep = bake(mesh, "depth-object", res=16)
    camera = orbit_bounds(framing_bounds(rep), 20, 60, 2.2, size=(48, 48))
    result = compare(mesh, rep, camera)
    assert result["default"] == "ray cast"
    tiles = dict(comparison_tiles(result))
    coverage = [caption for caption in tiles if caption.startswith("coverage vs mesh")]
    assert coverage == ["coverage vs mesh: ray cast"]
    frames, truth = result["frames"], result["frames"]["mesh"]

    def tile_of(name):
        rgb = np.round(np.clip(metrics.error_image(frames[name], truth, "mask"), 0, 1) * 255)
        return rgb.astype(np.uint8)

    got = tiles[coverage[0]][..., :3]
    assert np.array_equal(got, tile_of("ray cast"))
    assert not np.array_equal(got, tile_of("visual hull"))
