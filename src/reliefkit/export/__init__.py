"""glTF export (docs/gltf.md): `export` writes one representation, `export_lod` a mesh and
its representations as an LOD chain; `reliefkit.load` reads either back."""

from .gltf import DEFAULT_FALLBACK_TRIANGLES, export
from .lod import export_lod

__all__ = ["export", "export_lod", "DEFAULT_FALLBACK_TRIANGLES"]
