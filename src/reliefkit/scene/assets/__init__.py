"""Procedural demo assets: a terrain, a closed blob, a tree and a van, a cup, and textured
surfaces.

The surfaces (`SURFACE_NAMES`, from :mod:`.surfaces`: a sphere, a dented sphere, a torus, two
spheres, a plane, a tube, a vase and the Utah teapot) carry texture coordinates and smooth
normals for techniques that need (u, v); `make_asset` builds them by name too, while
`ASSET_NAMES` keeps to the four assets (the cup, `SHAPE_NAMES`, is a
test shape for the depth objects).

Every asset is deterministic for a given seed (``np.random.default_rng(seed)``), built with
numpy, scipy and scikit-image only (nothing is downloaded) and returned as a
:class:`~reliefkit.scene.mesh.RenderMesh` with linear RGBA vertex colours picked in sRGB.
Coordinates are right-handed with +y up and fit roughly in [-1, 1].

Each mesh lists its parts in ``mesh.extra["parts"]``: one dict per part with its ``name``,
its triangle range ``triangles`` (start, stop) and whether it is ``closed`` (a closed part
bounds a solid with counter-clockwise, outward-facing triangles, so its signed volume is
positive). Flat-shaded parts (boxes, hulls) have their own vertices per face so their normals
stay crisp; smooth parts (terrain, blob, round sides of cylinders) share vertices.
"""

from __future__ import annotations

from collections.abc import Callable

from ...errors import UsageError
from ..mesh import RenderMesh
from .blob import blob
from .cup import cup
from .surfaces import SURFACES
from .terrain import terrain, terrain_heights
from .tree import tree
from .vehicle import vehicle

__all__ = [
    "ASSET_NAMES",
    "DEMO_NAMES",
    "SHAPE_NAMES",
    "SURFACE_NAMES",
    "blob",
    "cup",
    "make_asset",
    "terrain",
    "terrain_heights",
    "tree",
    "vehicle",
]

ASSET_NAMES = ("terrain", "blob", "tree", "vehicle")
#: Further shapes `make_asset` knows that are not in the demo set (`ASSET_NAMES`).
SHAPE_NAMES = ("cup",)

#: The textured demo surfaces `make_asset` also knows (see :mod:`.surfaces`).
SURFACE_NAMES = tuple(SURFACES)

#: Every name `make_asset` builds, which `demo:NAME` accepts.
DEMO_NAMES = ASSET_NAMES + SHAPE_NAMES + SURFACE_NAMES

_FACTORIES: dict[str, Callable[[], RenderMesh]] = {
    "terrain": terrain,
    "blob": blob,
    "tree": tree,
    "vehicle": vehicle,
    "cup": cup,
}


def make_asset(name: str) -> RenderMesh:
    """The demo asset, shape or surface called `name` (one of `DEMO_NAMES`) with its
    default parameters.

    Raises
    ------
    UsageError
        If `name` is not a known asset.
    """
    factory = (_FACTORIES.get(name) or SURFACES.get(name)) if isinstance(name, str) else None
    if factory is None:
        raise UsageError(f"unknown asset {name!r}; choose one of: "
                         f"{', '.join(ASSET_NAMES + SHAPE_NAMES)} "
                         f"or a surface: {', '.join(SURFACE_NAMES)}")
    return factory()

