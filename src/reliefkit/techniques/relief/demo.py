"""Relief tiles of the demo sheet: heightfield terrain with shadows, box, frustum and a cube;
none bakes safety radii (the demo spent 46% of its time on them)."""

from __future__ import annotations

from ...bake import bake
from ...core.technique import DemoTile
from ...scene.assets import make_asset
from ...scene.light import DirectionalLight


def _baked(asset: str, kind: str, **params):
    def make():
        return bake(make_asset(asset), kind, **params)

    return make


def demo_tiles() -> list[DemoTile]:
    terrain_view, vehicle_view, blob_view = (30.0, 35.0, 2.2), (40.0, 20.0, None), (35, 25, 2.5)
    low_sun = DirectionalLight(direction=(-0.85, 0.35, 0.25))
    return [
        # maxmip: exact and needs nothing baked; robust would jump by safety radii here
        # (256²), a third of the demo's time for the same surface
        DemoTile("terrain: relief 256, maxmip + shadows", "terrain-relief",
                 _baked("terrain", "relief", depth_res=256, safety=False), terrain_view,
                 {"method": "maxmip", "shadows": True, "light": low_sun}),
        DemoTile("vehicle: orthographic relief", "vehicle-relief",
                 _baked("vehicle", "relief", depth_res=128, color_res=256), vehicle_view),
        DemoTile("vehicle: reverse-perspective relief", "vehicle-frustum",
                 _baked("vehicle", "relief-frustum", depth_res=128, color_res=256),
                 vehicle_view),
        # bakes leave out the safety radii that no tile reads (robust draws 128² fields
        # with the exact walk); maxmip builds its max pyramid when drawn
        DemoTile("blob: six reverse frusta, maxmip", "blob-cube",
                 _baked("blob", "relief-cube", depth_res=128), blob_view,
                 {"method": "maxmip"}),
    ]
