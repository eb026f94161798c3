"""The impostor baker and its typed parameters (the CLI's ``bake --as octahedral-impostor``)."""

from __future__ import annotations

from dataclasses import dataclass

from ...core.params import param
from ...core.technique import Sizing
from .bake import bake_impostor
from .representation import MAX_ATLAS, MAX_GRID


@dataclass(frozen=True)
class ImpostorParams:
    grid: int = param(12, "frames on each side of the octahedral grid (grid² views)",
                      kind="int", lo=2, hi=MAX_GRID)
    hemi: bool = param(False, "the upper hemisphere only (hemi-octahedral map): frames twice "
                              "as dense for objects never seen from below")
    atlas_res: int = param(1024, "texels on each atlas's side, rounded down to a multiple of "
                           "--grid (1024: 85² per frame at grid 12, baked in seconds; "
                           "2048 for close-ups)", kind="int", lo=16, hi=MAX_ATLAS)
    padding: int = param(2, "texels around each frame the bounding sphere stays out of "
                         "(dilated colour, no coverage), so filtering and the first mip "
                         "levels never mix frames", kind="int", lo=0, hi=64)


#: Texels a frame the shootout keeps as it sizes the atlas down: below 24 at grid 12 it
#: takes fewer frames instead (down to `SIZING_GRIDS`' first), as many texels each.
SIZING_FRAME_TEXELS = 24
SIZING_GRIDS = (6, 12)


def sizing_grid(atlas_res: int) -> int:
    """The grid the shootout bakes an atlas of ``atlas_res`` texels a side with: 12 down to
    `SIZING_FRAME_TEXELS` texels a frame, then fewer frames, never under 6 (12 texels a
    frame, 8 of view inside the padding, at the smallest atlas)."""
    lo, hi = SIZING_GRIDS
    return max(lo, min(hi, atlas_res // SIZING_FRAME_TEXELS))


#: The shootout sizes an impostor by its atlases' side; the grid follows (`sizing_grid`), so
#: the bytes grow with the side and small budgets get a coarser grid.
ATLAS_SIZING = Sizing("atlas_res: texels on each atlas's side (grid = atlas_res // 24, "
                      "6 to 12)", SIZING_GRIDS[0] * 12, min(4096, MAX_ATLAS),
                      lambda n, mesh: {"atlas_res": n, "grid": sizing_grid(n)})


def bake_octahedral(source, p: ImpostorParams, progress=None):
    return bake_impostor(source, grid=p.grid, hemi=p.hemi, atlas_res=p.atlas_res,
                         padding=p.padding, progress=progress)
