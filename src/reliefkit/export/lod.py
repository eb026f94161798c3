"""`export_lod`: a mesh and representations of it as one glTF LOD chain (``MSFT_lod``).

The mesh is LOD 0, a plain core glTF node; each representation is a node of its own
(`export.gltf.representation_node`: extension + fallback), listed in the mesh node's
``extensions.MSFT_lod.ids`` from the most to the least accurate, and
``extras.MSFT_screencoverage`` gives, per LOD, the smallest share of the screen's height at
which it is shown (Babylon and UnityGLTF read these; other viewers show LOD 0).

The thresholds come from measurement, not from a formula per kind: each representation is
drawn beside the mesh from the shootout's six views and its surface error ``e`` (the 95th
percentile of the world-space distance between the points both draw, worst view) is the
error it makes. Seen at a share ``c`` of a screen ``H`` pixels high, a bounding sphere of
radius ``r`` maps ``e`` to ``e * H * c / (2 r)`` pixels, under one pixel while
``c < 2 r / (e H)``: below that share the representation is as good as the mesh. A
representation drawn with no error gets share 0 as the mesh's successor; a DMBBC's own
switch to its cloud by distance happens inside its node, as it draws.
"""

from __future__ import annotations

import math
from pathlib import Path

from ..io.gltf.mesh import add_render_mesh
from ..io.rk import codec_of
from ..metrics import compare
from ..render import render
from ..scene.sphere_views import cameras
from ..scene.views import bounds_radius
from .gltf import DEFAULT_FALLBACK_TRIANGLES, builder_for, representation_node, write_document

__all__ = ["export_lod", "surface_error", "screen_coverages", "MEASURE_SIZE", "SCREEN_HEIGHT"]

MEASURE_SIZE = 192   # pixels the bounding sphere spans in the measuring views
SCREEN_HEIGHT = 1080  # the screen the thresholds are for


def surface_error(rep, mesh, size: int = MEASURE_SIZE) -> float:
    """The worst view's 95th-percentile world distance between what ``rep`` and ``mesh``
    draw at the same pixels (see the module)."""
    views = cameras(mesh.bounds, size)
    errors = []
    for camera in views:
        scores = compare(render(rep, camera), render(mesh, camera))
        if not math.isnan(scores["position_p95"]):
            errors.append(scores["position_p95"])
    return max(errors) if errors else math.inf


def screen_coverages(errors: list[float], radius: float,
                     screen_height: int = SCREEN_HEIGHT) -> list[float]:
    """``MSFT_screencoverage`` of the chain mesh, reps (sorted by error): LOD k is shown
    from its share down to LOD k+1's; the last LOD is never culled (0)."""
    shares = [min(1.0, 2.0 * radius / (e * screen_height)) if e > 0 else 0.0
              for e in errors]
    return [round(s, 6) for s in shares] + [0.0]


def export_lod(mesh, reps, path, *, fallback_triangles: int = DEFAULT_FALLBACK_TRIANGLES,
               embed_shaders: bool = False, source_hash: str | None = None,
               progress=None) -> tuple[Path, list[dict]]:
    """Write ``mesh`` and ``reps`` as an LOD chain (see the module); the path and one record
    per LOD (kind, surface error, screen coverage), in chain order."""
    errors = []
    for rep in reps:
        errors.append(surface_error(rep, mesh))
        if progress:
            progress()
    order = sorted(range(len(reps)), key=lambda k: errors[k])
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
        records.append({"level": lod, "kind": codec_of(reps[k]).kind,
                        "surface_error": errors[k], "screen_coverage": coverages[lod]})
    return written, records
