"""The core's own .rk kind, ``mesh``: a RenderMesh stored as plain arrays."""

from __future__ import annotations

import numpy as np

from ..errors import FormatError
from ..scene.mesh import RenderMesh
from .rk import ArraySpec, Codec, register


def _mesh_to_arrays(mesh: RenderMesh) -> tuple[dict[str, np.ndarray], dict]:
    arrays = {"positions": mesh.positions, "indices": mesh.indices, "normals": mesh.normals,
              "colors": mesh.colors, "uvs": mesh.uvs, "texture": mesh.texture}
    return arrays, {"name": mesh.name}


def _mesh_from_arrays(arrays: dict[str, np.ndarray], params: dict) -> RenderMesh:
    name = params.get("name", "mesh")
    if not isinstance(name, str):
        raise FormatError(f"mesh param 'name' must be a string, got {type(name).__name__}")
    return RenderMesh(name=name, **arrays)


def _rows(dtype: str, cols: int, **options) -> ArraySpec:
    """Spec of an (N, cols) per-vertex or per-triangle table."""
    return ArraySpec((dtype,), ndim=2, trailing=(cols,), **options)


register(Codec(
    kind="mesh",
    cls=RenderMesh,
    arrays={
        "positions": _rows("float32", 3, finite=True),
        "indices": _rows("uint32", 3),
        "normals": _rows("float32", 3, finite=True),
        "colors": _rows("float32", 4, finite=True),
        "uvs": _rows("float32", 2, finite=True, required=False),
        "texture": ArraySpec(("uint8",), ndim=3, trailing=(4,), required=False),
    },
    to_arrays=_mesh_to_arrays,
    from_arrays=_mesh_from_arrays,
))
