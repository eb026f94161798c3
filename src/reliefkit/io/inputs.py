"""Open whatever the user names: a mesh file, a .rk representation, or a demo asset.

The one place that reads ``demo:NAME``: the CLI's inputs (`load_input`) and the public
``reliefkit.load_mesh`` (`load_mesh`) both go through it.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

from ..errors import FormatError, MeshError, UsageError
from ..scene.assets import make_asset
from ..scene.mesh import RenderMesh
from .gltf import representation as gltf_representation
from .rk import codec_of, load

DEMO_PREFIX = "demo:"


def load_input(spec: str):
    """``demo:NAME`` -> a procedural RenderMesh, ``*.rk`` or a glTF file reliefkit exported
    -> its representation, else a mesh."""
    if not _is_demo(spec):
        suffix = Path(spec).suffix.lower()
        if suffix == ".rk":
            return load(spec)
        if suffix in (".glb", ".gltf") and gltf_representation.exported_by_reliefkit(spec):
            return gltf_representation.load(spec)
    return load_mesh(spec)


def load_mesh(spec: str | os.PathLike, *, name: str | None = None):
    """A mesh file (see `reliefkit.io.meshes.load_mesh`), or ``demo:NAME``: the procedural
    asset or surface the CLI calls so (`reliefkit.scene.assets.make_asset`).

    `name` labels the mesh in pictures and messages (default: the file name without its
    extension, or the asset's own name). Raises `MeshError` for a file that cannot be
    loaded or an unknown demo name.
    """
    if not _is_demo(spec):
        from .meshes import load_mesh as load_mesh_file  # trimesh: slow to import

        return load_mesh_file(spec, name=name)

    try:
        mesh = make_asset(spec[len(DEMO_PREFIX):])
    except UsageError as exc:  # an unknown name: a missing input (exit 1), not a bad flag
        raise MeshError(f"{spec}: {exc}") from None
    if name is None:
        return mesh
    return RenderMesh(mesh.positions, mesh.indices, mesh.normals, mesh.colors, mesh.uvs,
                      name=name, extra=mesh.extra, materials=mesh.materials,
                      material=mesh.material, origin=mesh.origin)


def _is_demo(spec) -> bool:
    """Only a string names a demo asset (a path object is always a file)."""
    return isinstance(spec, str) and spec.startswith(DEMO_PREFIX)


def kind_of(obj) -> str:
    """What users know ``obj`` as: "mesh", or the kind its .rk file names (`bake --as`,
    `reliefkit info`), not its class; the class only for an object no codec saves."""
    if isinstance(obj, RenderMesh):
        return "mesh"
    try:
        return codec_of(obj).kind
    except FormatError:
        return type(obj).__name__


def what_it_is(spec: str, obj) -> str:
    """``spec`` and its kind for a message: "tree.rk, an octahedral-impostor .rk",
    "demo:vehicle, a mesh"."""
    kind = kind_of(obj)
    article = "an" if kind[:1].lower() in "aeiou" else "a"
    suffix = " .rk" if kind != "mesh" and str(spec).lower().endswith(".rk") else ""
    return f"{spec}, {article} {kind}{suffix}"


def describe(obj) -> dict:
    """A short JSON-able summary for `reliefkit info`."""
    if isinstance(obj, RenderMesh):
        lo, hi = obj.bounds
        return {"kind": "mesh", "name": obj.name, "vertices": len(obj.positions),
                "triangles": obj.triangle_count, "bounds_min": lo.tolist(),
                "bounds_max": hi.tolist(), "materials": len(obj.materials),
                "textures": _texture_count(obj), "textured": obj.textured,
                "uvs": obj.uvs is not None}
    summary = getattr(obj, "summary", None)
    return summary() if callable(summary) else {"kind": type(obj).__name__}


def _texture_count(mesh) -> int:
    """How many distinct images the materials use (materials that share one, or carry equal
    copies of one file, count it once)."""
    return len({(m.texture.shape, hashlib.blake2b(m.texture.data, digest_size=16).digest())
                for m in mesh.materials if m.texture is not None})
