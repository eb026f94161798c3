"""Open whatever the user names: a mesh file, a .rk representation, or a demo asset."""

from __future__ import annotations

from pathlib import Path

DEMO_PREFIX = "demo:"


def load_input(spec: str):
    """``demo:NAME`` -> a procedural RenderMesh, ``*.rk`` -> its representation, else a mesh."""
    if spec.startswith(DEMO_PREFIX):
        from ..errors import MeshError, UsageError
        from ..scene.assets import make_asset

        try:
            return make_asset(spec[len(DEMO_PREFIX):])
        except UsageError as exc:  # an unknown name: a missing input (exit 1), not a bad flag
            raise MeshError(f"{spec}: {exc}") from None
    if Path(spec).suffix.lower() == ".rk":
        from .rk import load

        return load(spec)
    from ..scene.loader import load_mesh

    return load_mesh(spec)


def describe(obj) -> dict:
    """A short JSON-able summary for `reliefkit info`."""
    from ..scene.mesh import RenderMesh

    if isinstance(obj, RenderMesh):
        lo, hi = obj.bounds
        return {"kind": "mesh", "name": obj.name, "vertices": len(obj.positions),
                "triangles": obj.triangle_count, "bounds_min": lo.tolist(),
                "bounds_max": hi.tolist(), "materials": len(obj.materials),
                "textured": obj.textured}
    summary = getattr(obj, "summary", None)
    return summary() if callable(summary) else {"kind": type(obj).__name__}
