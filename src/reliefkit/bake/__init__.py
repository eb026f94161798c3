"""Baking: meshes and heightmaps into representations."""

from .frustum import bake_relief_cube, bake_relief_frustum, fit_reverse_frustum
from .heightfield import DEFAULT_TOLERANCE, bake_relief, relief_from_heights

BAKE_KINDS = ("relief", "relief-frustum", "relief-cube")


def bake(source, kind: str, *, depth_res: int | None = None, color_res: int | None = None,
         tolerance: float = DEFAULT_TOLERANCE, safety: bool = True, axis: str = "y",
         progress=None, **extra):
    """Bake a RenderMesh (or a height array, for ``relief``) into the representation ``kind``."""
    import numpy as np

    from ..errors import UsageError

    if kind not in BAKE_KINDS:
        raise UsageError(f"unknown representation {kind!r} (choose from {', '.join(BAKE_KINDS)})")
    common = dict(safety=safety, tolerance=tolerance, progress=progress)
    if isinstance(source, np.ndarray):
        if kind != "relief":
            raise UsageError("a heightmap can only be baked --as relief")
        return relief_from_heights(source, **common, **extra)
    if kind == "relief":
        return bake_relief(source, depth_res or 256, color_res, axis, **common)
    if kind == "relief-frustum":
        return bake_relief_frustum(source, depth_res=depth_res or 256, color_res=color_res,
                                   axis=axis, **common, **extra)
    return bake_relief_cube(source, depth_res=depth_res or 128, color_res=color_res, **common)


__all__ = ["bake", "bake_relief", "bake_relief_frustum", "bake_relief_cube",
           "relief_from_heights", "fit_reverse_frustum", "BAKE_KINDS"]
