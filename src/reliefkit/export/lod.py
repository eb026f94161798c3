"""`export_lod`: a mesh and representations of it as one glTF LOD chain (``MSFT_lod``).

The mesh is LOD 0, a plain core glTF node; each representation is a node of its own
(`export.gltf.representation_node`: extension + fallback), listed in the mesh node's
``extensions.MSFT_lod.ids`` from the most to the least accurate, and
``extras.MSFT_screencoverage`` gives, per LOD, the smallest share of the screen's height at
which it is shown (Babylon and UnityGLTF read these; other viewers show LOD 0).

Each representation's error ``e`` is a world distance: the one it declares
(``geometric_error()``: a billboard cloud's epsilon, the distance every face lies within of
its card, whose projection below one pixel is also where a DMBBC switches to its cloud), or
else measured: drawn beside the mesh from the six measuring views (the bounding sphere
``S`` pixels across), its outline's mean displacement (the pixels where exactly one of the
two covers, per pixel of the mesh's outline) in the worst view, in world units (``2r/S`` a
pixel). Depth errors along a view ray move nothing on screen and are not counted. Seen at
a share ``c`` of a screen ``H`` pixels high, a bounding sphere of radius ``r`` maps ``e`` to
``e * H * c / (2 r)`` pixels, under one pixel while ``c < 2 r / (e H)``: below that share
the representation is as good as the mesh. A measured error is taken as at least half a
measuring pixel (what the views resolve), so no measured representation takes over above a
share of ``2 S / H`` (0.47).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..io.gltf.mesh import add_render_mesh
from ..io.rk import array_bytes, codec_of
from ..metrics import mask_xor
from ..render import render
from ..scene.sphere_views import cameras
from ..scene.views import bounds_radius
from .gltf import DEFAULT_FALLBACK_TRIANGLES, builder_for, representation_node, write_document

__all__ = ["export_lod", "surface_error", "screen_coverages", "MEASURE_SIZE", "SCREEN_HEIGHT"]

MEASURE_SIZE = 256   # pixels the bounding sphere spans in the measuring views
SCREEN_HEIGHT = 1080  # the screen the thresholds are for


def surface_error(rep, mesh, size: int = MEASURE_SIZE) -> float:
    """``rep``'s error in world units (see the module): declared, or its outline's mean
    displacement against the mesh's in the worst measuring view (at least half a pixel)."""
    declared = getattr(rep, "geometric_error", None)
    if declared is not None:
        return float(declared())
    pixel = 2.0 * bounds_radius(mesh.bounds) / size
    worst = 0.5 * pixel  # what the measuring views resolve
    for camera in cameras(mesh.bounds, size):
        test, truth = render(rep, camera), render(mesh, camera)
        outline = _outline_pixels(truth.mask)
        if outline:
            worst = max(worst, mask_xor(test, truth) / outline * pixel)
    return worst


def _outline_pixels(mask: np.ndarray) -> int:
    """Covered pixels with an uncovered 4-neighbour (or on the image's border)."""
    padded = np.pad(mask, 1)
    inner = padded[:-2, 1:-1] & padded[2:, 1:-1] & padded[1:-1, :-2] & padded[1:-1, 2:]
    return int(np.count_nonzero(mask & ~inner))


def screen_coverages(errors: list[float], radius: float,
                     screen_height: int = SCREEN_HEIGHT) -> list[float]:
    """``MSFT_screencoverage`` of the chain mesh, reps (sorted by error): LOD k is shown
    from its share down to LOD k+1's; the last LOD is never culled (0)."""
    shares = [min(1.0, 2.0 * radius / (e * screen_height)) if e > 0 else 0.0
              for e in errors]
    return [round(s, 6) for s in shares] + [0.0]


def export_lod(mesh, reps, path, *, fallback_triangles: int = DEFAULT_FALLBACK_TRIANGLES,
               embed_shaders: bool = False, source_hash: str | None = None,
               names: list[str] | None = None, progress=None) -> tuple[Path, list[dict]]:
    """Write ``mesh`` and ``reps`` as an LOD chain (see the module); the path and one record
    per LOD (``names[k]`` or the kind, surface error, screen coverage), in chain order."""
    errors = []
    for rep in reps:
        errors.append(surface_error(rep, mesh))
        if progress:
            progress()
    # equal errors: the larger first, so the smaller one is the one shown
    order = sorted(range(len(reps)), key=lambda k: (errors[k], -_bytes(reps[k])))
    coverages = screen_coverages([errors[k] for k in order], bounds_radius(mesh.bounds))
    builder = builder_for(path)
    ids = [representation_node(builder, reps[k], fallback_triangles=fallback_triangles,
                               embed_shaders=embed_shaders, source_hash=source_hash)
           for k in order]
    root = add_render_mesh(builder, mesh, name=mesh.name or "mesh")
    root.setdefault("extensions", {})["MSFT_lod"] = {"ids": ids}
    root.setdefault("extras", {})["MSFT_screencoverage"] = coverages
    document = builder.document
    document["nodes"].append(root)
    used = document.setdefault("extensionsUsed", [])
    used.append("MSFT_lod")
    used.sort()
    written = write_document(path, builder, [len(document["nodes"]) - 1])
    records = [{"level": 0, "kind": "mesh", "surface_error": 0.0, "screen_coverage": coverages[0]}]
    for lod, k in enumerate(order, 1):
        records.append({"level": lod, "kind": names[k] if names else codec_of(reps[k]).kind,
                        "surface_error": errors[k], "screen_coverage": coverages[lod]})
    return written, records


def _bytes(rep) -> int:
    return sum(array_bytes(rep).values())
