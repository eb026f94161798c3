"""Shell-volume tiles of the demo sheet: the paper's Figure 1 on spheres (fur, clouds over an
Earth-like ground, ellipsoids in a medium, uniform absorption, a chain, rocks)."""

from __future__ import annotations

from ...bake import bake
from ...core.technique import DemoTile
from ...scene.assets import make_asset

#: (texture, tile U, V): how each of Figure 1's textures repeats over the sphere.
FIGURE_1 = (("fur", (8, 4)), ("clouds", (2, 1)), ("ellipsoids", (4, 2)),
            ("absorption", (1, 1)), ("chain", (6, 3)), ("rocks", (4, 2)))
THICKNESS = 0.15  # of the unit sphere's radius


def _shell(texture: str, tile):
    def make():
        return bake(make_asset("sphere"), "shell-volume", texture=texture,
                    thickness=THICKNESS, tile=tuple(float(t) for t in tile))

    return make


def demo_tiles() -> list[DemoTile]:
    return [DemoTile(f"shell volume: {name}", f"shell-{name}", _shell(name, tile),
                     (30.0, 20.0, 2.2), {"samples": 12})
            for name, tile in FIGURE_1]
