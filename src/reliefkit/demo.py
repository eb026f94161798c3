"""`reliefkit demo`: the demo assets and every technique's tiles in one titled contact sheet."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from .core.technique import REGISTRY, DemoTile
from .io.atomic import atomic_path
from .pictures import TILE_BACKGROUND, contact_sheet, save_image
from .progress import progress_bar
from .render import render
from .scene.assets import make_asset
from .scene.views import DEFAULT_VIEW, framing_bounds, orbit_bounds


def _asset(name: str) -> Callable[[], object]:
    def make():
        return make_asset(name)

    return make


def mesh_tiles() -> list[DemoTile]:
    """The ground truth: every procedural asset as a mesh."""
    return [
        DemoTile("terrain (mesh)", "terrain-mesh", _asset("terrain"), (30.0, 35.0, 2.2)),
        DemoTile("blob (mesh)", "blob-mesh", _asset("blob"), (35.0, 25.0, 2.5)),
        DemoTile("tree (mesh)", "tree-mesh", _asset("tree"), (20.0, 10.0, 2.4)),
        DemoTile("vehicle (mesh)", "vehicle-mesh", _asset("vehicle"), (40.0, 20.0, None)),
    ]


def demo_tiles() -> list[DemoTile]:
    """Every tile of the sheet: the meshes, then each registered technique's tiles (the
    CLI fills the registry; benches draw these tiles too, so this module sits below the
    composition root)."""
    tiles = mesh_tiles()
    for tech in REGISTRY.techniques():
        if tech.demo_tiles is not None:
            tiles += tech.demo_tiles()
    return tiles


def tile_image(obj, view=DEFAULT_VIEW, size=(256, 256), options: dict | None = None
               ) -> np.ndarray:
    """``obj`` (a mesh or a representation) drawn from ``view`` (azimuth, elevation,
    distance or None to fit) over the tiles' background: an (H, W, 4) uint8 image, as the
    demo sheet and the batch's thumbnails show it."""
    camera = orbit_bounds(framing_bounds(obj), *view, size=size)
    return render(obj, camera, **(options or {})).rgba8(TILE_BACKGROUND)


def build_demo(out_dir: Path, tile_size=(256, 256), columns: int = 4) -> Path:
    """Render every tile into ``out_dir/<slug>.png`` and the sheet into ``out_dir/demo.png``."""
    from PIL import Image

    out_dir.mkdir(parents=True, exist_ok=True)
    tiles = demo_tiles()
    images: list[tuple[str, np.ndarray]] = []
    with progress_bar("demo", len(tiles)) as advance:
        for k, tile in enumerate(tiles):
            rgba = tile_image(tile.make(), tile.view, tile_size, tile.options)
            with atomic_path(out_dir / f"{tile.slug}.png") as tmp:
                Image.fromarray(rgba, "RGBA").save(tmp, format="PNG")
            images.append((tile.title, rgba))
            advance(k + 1)
    sheet = contact_sheet(images, columns, title="reliefkit demo")
    path = out_dir / "demo.png"
    save_image(sheet, path)
    return path
