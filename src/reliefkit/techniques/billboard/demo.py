"""Billboard tiles of the demo sheet: the tree and the vehicle as billboard clouds and as
volumetric displacement-mapped billboard clouds with the same planes."""

from __future__ import annotations

from ...bake import bake
from ...core.technique import DemoTile
from ...scene.assets import make_asset


def _baked(asset: str, kind: str, **params):
    def make():
        return bake(make_asset(asset), kind, **params)

    return make


def demo_tiles() -> list[DemoTile]:
    return [
        DemoTile("tree: billboard cloud", "tree-bbc", _baked("tree", "billboard-cloud"),
                 (20.0, 10.0, 2.4)),
        DemoTile("tree: volumetric DMBBC", "tree-dmbbc", _baked("tree", "dmbbc"),
                 (20.0, 10.0, 2.4)),
        DemoTile("vehicle: billboard cloud", "vehicle-bbc", _baked("vehicle", "billboard-cloud"),
                 (40.0, 20.0, None)),
        DemoTile("vehicle: volumetric DMBBC", "vehicle-dmbbc", _baked("vehicle", "dmbbc"),
                 (40.0, 20.0, None)),
    ]
