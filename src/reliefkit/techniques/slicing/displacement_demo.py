"""Displacement tiles of the demo sheet: the paper's furry donut (Fig. 1: a torus of 625
polygons with a fur displacement, orthogonal slicing, 20 slices) and a bumpy square seen
from a grazing angle with each slicing."""

from __future__ import annotations

from ...core.technique import DemoTile
from ...scene.assets.surfaces import torus
from .displacement import DisplacementMap
from .displacement_bake import square_base
from .displacement_textures import bumps, fur

DONUT_QUADS = 25   # 25 x 25 quads: the paper's 625 polygons
DONUT_SLICES = 20  # the paper used 15-25
DONUT_SCALE = 0.08
DONUT_TILE = (8.0, 4.0)


def furry_donut(res: int = 64, scale: float = DONUT_SCALE, tile=DONUT_TILE):
    """Fig. 1: a 25 x 25 torus with the fur texture tiled over it."""
    base = torus(major_segments=DONUT_QUADS, minor_segments=DONUT_QUADS)
    color, height = fur(res=res)
    return DisplacementMap(base, color, height, scale, tuple(tile), True,
                           {"source": "torus", "texture": "fur"})


def bumpy_square(res: int = 64):
    color, height = bumps(res=res)
    return DisplacementMap(square_base(), color, height, 0.4, (1.0, 1.0), False,
                           {"source": "square", "texture": "bumps"})


def demo_tiles() -> list[DemoTile]:
    tiles = [DemoTile("displacement: furry donut (Fig. 1)", "displacement-donut",
                      furry_donut, (30.0, 35.0, 2.4),
                      {"slicing": "orthogonal", "slices": DONUT_SLICES})]
    for mode in ("surface", "orthogonal", "screen"):
        tiles.append(DemoTile(f"displacement: bumps, {mode} slicing", f"displacement-{mode}",
                              bumpy_square, (20.0, 15.0, 2.7),
                              {"slicing": mode, "slices": 32}))
    return tiles
