"""The billboard bakers and their typed parameters (the CLI's ``bake --as billboard-cloud``)."""

from __future__ import annotations

from dataclasses import dataclass

from ...core.params import param
from .bake import bake_billboard_cloud


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
