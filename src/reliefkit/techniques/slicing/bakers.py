"""The depth-object and visual-hull bakers (``bake --as depth-object|visual-hull``)."""

from __future__ import annotations

from dataclasses import dataclass

from ...core.params import param
from ...core.technique import Sizing
from .depth_images import MAX_RESOLUTION, bake_depth_images
from .representation import DepthObject, VisualHull


@dataclass(frozen=True)
class DepthObjectParams:
    res: int = param(256, "texels per side of each of the six depth images", lo=2,
                     hi=MAX_RESOLUTION)


def bake_depth_object(source, p: DepthObjectParams, progress=None) -> DepthObject:
    images = bake_depth_images(source, p.res)
    return DepthObject(images, {"source": source.name, "res": p.res}, source.bounds)


def bake_visual_hull(source, p: DepthObjectParams, progress=None) -> VisualHull:
    images = bake_depth_images(source, p.res)
    return VisualHull.of(images, {"source": source.name, "res": p.res}, source.bounds)


#: The shootout sizes a depth object (and its visual hull) by its depth images' resolution.
DEPTH_IMAGES_SIZING = Sizing("res: texels per side of each of the six depth images", 8,
                             min(2048, MAX_RESOLUTION), lambda n, mesh: {"res": n})
