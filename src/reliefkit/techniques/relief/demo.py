"""Relief tiles of the demo sheet: heightfield terrain with shadows, box, frustum and a cube
drawn with maximum mipmaps."""

from __future__ import annotations

from ...core.technique import DemoTile


def _baked(asset: str, kind: str, **params):
    def make():
        from ...bake import bake
        from ...scene.assets import make_asset

        return bake(make_asset(asset), kind, **params)

    return make


def demo_tiles() -> list[DemoTile]:
    from ...scene.light import DirectionalLight

    terrain_view, vehicle_view, blob_view = (30.0, 35.0, 2.2), (40.0, 20.0, None), (35, 25, 2.5)
    low_sun = DirectionalLight(direction=(-0.85, 0.35, 0.25))
    return [
        DemoTile("terrain: relief 256, robust + shadows", "terrain-relief",
                 _baked("terrain", "relief", depth_res=256), terrain_view,
                 {"method": "robust", "shadows": True, "light": low_sun}),
        DemoTile("vehicle: orthographic relief", "vehicle-relief",
                 _baked("vehicle", "relief", depth_res=128, color_res=256), vehicle_view),
        DemoTile("vehicle: reverse-perspective relief", "vehicle-frustum",
                 _baked("vehicle", "relief-frustum", depth_res=128, color_res=256),
                 vehicle_view),
        # bakes leave out the safety radii that no tile reads (only the terrain jumps by
        # them: 256², robust); maxmip builds its max pyramid when drawn
        DemoTile("blob: six reverse frusta, maxmip", "blob-cube",
                 _baked("blob", "relief-cube", depth_res=128), blob_view,
                 {"method": "maxmip"}),
    ]
