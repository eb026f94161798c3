"""`reliefkit demo`: render the demo assets and representations into a titled contact sheet."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .fileio import atomic_path

BACKGROUND = (0.05, 0.055, 0.065)


@dataclass(frozen=True)
class DemoTile:
    """One picture of the sheet: ``make()`` returns the object to render; ``view`` is AZ,EL,DIST."""

    title: str
    slug: str
    make: Callable[[], object]
    view: tuple[float, float, float] = (35.0, 30.0, 2.4)
    options: dict | None = None


def _asset(name: str) -> Callable[[], object]:
    def make():
        from .scene.assets import make_asset

        return make_asset(name)

    return make


def _baked(name: str, kind: str, **bake_options) -> Callable[[], object]:
    def make():
        from .bake import bake
        from .scene.assets import make_asset

        return bake(make_asset(name), kind, **bake_options)

    return make


def demo_tiles() -> list[DemoTile]:
    """Every tile of the demo sheet, in order (representations add theirs here)."""
    terrain_view, vehicle_view, blob_view = (30.0, 35.0, 2.2), (40.0, 20.0, 2.2), (35, 25, 2.5)
    from .scene.light import DirectionalLight

    low_sun = DirectionalLight(direction=(-0.85, 0.35, 0.25))
    robust_shadows = {"method": "robust", "shadows": True, "light": low_sun}
    return [
        DemoTile("terrain (mesh)", "terrain-mesh", _asset("terrain"), terrain_view),
        DemoTile("blob (mesh)", "blob-mesh", _asset("blob"), blob_view),
        DemoTile("tree (mesh)", "tree-mesh", _asset("tree"), (20.0, 10.0, 2.4)),
        DemoTile("vehicle (mesh)", "vehicle-mesh", _asset("vehicle"), vehicle_view),
        DemoTile("terrain: relief 256, robust + shadows", "terrain-relief",
                 _baked("terrain", "relief", depth_res=256), terrain_view, robust_shadows),
        DemoTile("vehicle: orthographic relief", "vehicle-relief",
                 _baked("vehicle", "relief", depth_res=128, color_res=256), vehicle_view),
        DemoTile("vehicle: reverse-perspective relief", "vehicle-frustum",
                 _baked("vehicle", "relief-frustum", depth_res=128, color_res=256),
                 vehicle_view),
        DemoTile("blob: six reverse frusta", "blob-cube",
                 _baked("blob", "relief-cube", depth_res=128), blob_view),
    ]


def build_demo(out_dir: Path, tile_size=(256, 256), columns: int = 4) -> Path:
    """Render every tile into ``out_dir/<slug>.png`` and the sheet into ``out_dir/demo.png``."""
    from PIL import Image

    from .pictures import contact_sheet, save_image
    from .progress import progress_bar
    from .render import render
    from .scene.views import orbit_bounds

    out_dir.mkdir(parents=True, exist_ok=True)
    tiles = demo_tiles()
    images: list[tuple[str, np.ndarray]] = []
    with progress_bar("demo", len(tiles)) as advance:
        for k, tile in enumerate(tiles):
            obj = tile.make()
            camera = orbit_bounds(obj.bounds, *tile.view, size=tile_size)
            rgba = render(obj, camera, **(tile.options or {})).rgba8(BACKGROUND)
            with atomic_path(out_dir / f"{tile.slug}.png") as tmp:
                Image.fromarray(rgba, "RGBA").save(tmp, format="PNG")
            images.append((tile.title, rgba))
            advance(k + 1)
    sheet = contact_sheet(images, columns, title="reliefkit demo")
    path = out_dir / "demo.png"
    save_image(sheet, path)
    return path
