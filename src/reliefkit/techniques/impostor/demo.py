"""Impostor tiles of the demo sheet: the tree and the vehicle as octahedral impostors with
the defaults (12 x 12 frames, 1024² atlases), seen between frames."""

from __future__ import annotations

from ...bake import bake
from ...core.technique import DemoTile
from ...scene.assets import make_asset


def _baked(asset: str):
    def make():
        return bake(make_asset(asset), "octahedral-impostor")

    return make


def demo_tiles() -> list[DemoTile]:
    return [DemoTile("tree: octahedral impostor", "tree-impostor", _baked("tree"),
                     (20.0, 10.0, 2.4)),
            DemoTile("vehicle: octahedral impostor", "vehicle-impostor", _baked("vehicle"),
                     (40.0, 20.0, None))]
