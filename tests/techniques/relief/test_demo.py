"""The relief tiles of the demo sheet bake only what their renders read."""

import numpy as np

from reliefkit.techniques.relief import demo, safety
from reliefkit.techniques.relief.render import ReliefRenderOptions, drawn_method


def test_demo_tiles_bake_safety_radii_only_where_their_render_jumps(gl, monkeypatch):
    """Safety radii were 46% of the demo's time: the vehicle tiles' radii (128², drawn with
    the exact walk) were read by no tile, and the terrain's only by robust's jumps to the
    surface maxmip finds exactly without them. Radii are replaced by zeros here: what is
    checked is which tiles ask for them, not their values."""
    asked = []

    def zero_radii(height, **kwargs):
        asked.append(height.shape)
        return np.zeros(height.shape, np.uint8)

    monkeypatch.setattr(safety, "safety_radii", zero_radii)
    for tile in demo.demo_tiles():
        rep = tile.make()
        options = {k: v for k, v in (tile.options or {}).items() if k != "light"}
        methods = {drawn_method(part, ReliefRenderOptions(**options))
                   for part in getattr(rep, "parts", [rep])}
        has_radii = any(p.safety is not None for p in getattr(rep, "parts", [rep]))
        assert has_radii == ("robust" in methods), tile.slug
    assert not asked
