"""The billboard bakers and their typed parameters (the CLI's ``bake --as billboard-cloud`` and
``--as dmbbc``)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...core.params import param
from ...core.technique import Sizing
from .bake import bake_billboard_cloud
from .box_bake import SURFACES, bake_boxes
from .boxes import VARIANTS


def _epsilon():
    return param(0.05, "validity threshold: the farthest a face may lie from its plane, as a "
                 "fraction of the bounding-box diagonal", lo=1e-4, hi=0.5)


def _max_planes():
    return param(None, "stop after this many planes (the faces left are reported as "
                 "skipped; none: until every face has a plane)", kind="int", lo=1, hi=4096)


def _texel_size():
    return param(None, "world size of a texel, for the closest distance the impostor should "
                 "hold (none: the bounding-box diagonal / 256)", kind="float", lo=1e-12)


@dataclass(frozen=True)
class BillboardCloudParams:
    epsilon: float = _epsilon()
    max_planes: int | None = _max_planes()
    texel_size: float | None = _texel_size()


def bake_cloud(source, p: BillboardCloudParams, progress=None):
    return bake_billboard_cloud(source, epsilon=p.epsilon, max_planes=p.max_planes,
                                texel_size=p.texel_size, progress=progress)


@dataclass(frozen=True)
class BillboardBoxesParams:
    variant: str = param("volumetric", "how each box stores what is inside it (§3.3): a "
                         "3D texture, one displacement per texel, or an interval",
                         choices=VARIANTS)
    epsilon: float = _epsilon()
    max_planes: int | None = _max_planes()
    texel_size: float | None = _texel_size()
    thickness: float | None = param(None, "shell: the surface's thickness as a fraction of "
                                    "the box depth (none: the standard deviation of the "
                                    "displacements, the paper's suggestion)", kind="float",
                                    lo=1e-6, hi=1.0)
    surfaces: str = param("average", "several surfaces in one voxel: average them or keep "
                          "the one seen from outside (the shells keep each texel's outermost "
                          "surface either way)", choices=SURFACES)


def bake_dmbbc(source, p: BillboardBoxesParams, progress=None):
    return bake_boxes(source, p.variant, epsilon=p.epsilon, max_planes=p.max_planes,
                      texel_size=p.texel_size, thickness=p.thickness, surfaces=p.surfaces,
                      progress=progress)


def texel_across(n: int, mesh) -> float:
    """The texel size that puts ``n`` texels across the mesh's bounding-box diagonal."""
    return float(np.linalg.norm(np.subtract(*mesh.bounds[::-1]))) / n


#: The shootout sizes a billboard cloud, and each DMBBC variant, by its texel size.
TEXELS_ACROSS = "texels across the bounding-box diagonal (texel_size = diagonal / n)"
CLOUD_SIZING = Sizing(TEXELS_ACROSS, 16, 4096,
                      lambda n, mesh: {"texel_size": texel_across(n, mesh)})
DMBBC_SIZINGS = tuple(
    Sizing(TEXELS_ACROSS, 16, 1024, lambda n, mesh, v=variant: {
        "variant": v, "texel_size": texel_across(n, mesh)}, label=f"dmbbc-{variant}")
    for variant in VARIANTS)
