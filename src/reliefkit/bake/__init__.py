"""Baking: `bake(source, kind, **params)` through the registered bakers, and what bakers share:
`reliefkit.bake.project.project_mesh` (a mesh through any box) and
`reliefkit.bake.voxelize.voxelize` (a mesh into a 3D grid)."""

from __future__ import annotations

from ..core import params as options
from ..core.technique import baker
from ..errors import UsageError
from ..gl.context import using


def bake(source, kind: str, *, ctx=None, progress=None, compress=None, **params):
    """Bake a RenderMesh (or a 2D height array) into the representation ``kind``.

    ``params`` are the baker's typed parameters (``reliefkit bake --help`` lists them per
    kind); an unknown or invalid one is a UsageError. ``ctx``: a moderngl context
    (`reliefkit.gl.context.create_context`) every GL call of the bake runs on, instead of
    the process-wide one (which is then never made): a batch worker's own. ``compress``: a
    `reliefkit.compact.compact.CompressOptions` (or its fields as a dict); with
    ``compress="bc"`` the result is `compress`-ed, whatever the kind.
    """
    import numpy as np

    from ..compact.compact import bake_compression
    from ..compact.compact import compress as compressed

    tech, chosen = baker(kind)
    source_kind = "heightmap" if isinstance(source, np.ndarray) else "mesh"
    if source_kind not in chosen.sources:
        raise UsageError(f"--as {kind} bakes a {' or '.join(chosen.sources)}, not a "
                         f"{source_kind}")
    values = options.make(chosen.params, params, f"bake --as {kind}")
    how = bake_compression(compress)
    with using(ctx):  # the bakers' GL users all ask `get_context()` (see `using`)
        rep = chosen.bake(source, values, progress)
    return compressed(rep, how) if how.compress == "bc" else rep


__all__ = ["bake"]
