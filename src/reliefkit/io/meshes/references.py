"""The files a mesh file references, found as `load_mesh` finds them, without parsing it.

An OBJ's material library (the first ``mtllib``, as trimesh reads it) and the ``map_Kd``
textures it names, a glTF's buffers and images that are files, a PLY's ``TextureFile``:
each name is looked up by the loader's own resolver (URL-decoded, any case, never outside
the mesh's folder), and what the resolver reads is recorded (`badfile.reads_recorded`), so
the list is the files a load reads. A batch hashes them into its cache key and ships them
with the mesh to a worker that has no shared file system.
"""

from __future__ import annotations

import os
import re
from pathlib import Path, PurePosixPath

from ...errors import MeshError
from .badfile import BadFile, read_regular, reads_recorded
from .gltf import json_tree
from .parse import RecordingResolver

_PLY_TEXTURE = re.compile(rb"texturefile(.*)", re.IGNORECASE)


def referenced_files(path: str | os.PathLike) -> dict[str, Path]:
    """The files ``path`` references that exist and would be read, by their name relative
    to its folder (POSIX separators): {"textures/wood.png": Path(...)}. A reference that is
    missing, outside the folder or not a regular file is left out, as the load leaves it
    out (with a warning). Raises `MeshError` for a file that cannot be read at all."""
    path = Path(path)
    try:
        data = read_regular(path)
        names = _names(data, path.suffix.lower())
    except BadFile as exc:
        raise MeshError(f"{path}: {exc}") from None
    resolver = RecordingResolver(path)
    with reads_recorded() as read:
        for name in names:
            content = _resolved(resolver, name)
            if content is not None and name.strip().lower().endswith(".mtl"):
                for texture in _mtl_textures(content):
                    _resolved(resolver, texture)
    found = {}
    for file in read:
        relative = PurePosixPath(*Path(os.path.relpath(file, path.parent)).parts)
        if ".." not in relative.parts:  # the resolver reads nothing outside; never shipped
            found.setdefault(str(relative), file)
    return found


def _resolved(resolver: RecordingResolver, name: str) -> bytes | None:
    try:
        return resolver.get(name)
    except (FileNotFoundError, ValueError, BadFile):
        return None


def _names(data: bytes, suffix: str) -> list[str]:
    """The names a file of this type references, as written in it."""
    if suffix == ".obj":
        text = data.decode("utf-8", "replace")
        at = text.find("mtllib")  # trimesh reads the first library only
        if at < 0:
            return []
        end = text.find("\n", at)
        name = text[at + 6:end if end >= 0 else None].strip()
        return [name] if name else []
    if suffix in (".gltf", ".glb"):
        tree = json_tree(data, suffix[1:])
        return [item["uri"] for key in ("buffers", "images")
                for item in (tree.get(key) if isinstance(tree.get(key), list) else ())
                if isinstance(item, dict) and isinstance(item.get("uri"), str)
                and not item["uri"].startswith("data:")]
    if suffix == ".ply":
        header = data[:data.find(b"end_header")]
        match = _PLY_TEXTURE.search(header)
        name = match.group(1).decode("utf-8", "replace").strip() if match else ""
        return [name] if name else []
    return []


def _mtl_textures(data: bytes) -> list[str]:
    """The ``map_Kd`` names of a material library (the textures trimesh reads)."""
    names = []
    for line in data.decode("utf-8", "replace").splitlines():  # UTF-8 (`as_utf8`)
        stripped = line.strip()
        if stripped.split(maxsplit=1)[:1] and stripped.split()[0].lower() == "map_kd":
            name = stripped[stripped.lower().index("map_kd") + 6:].strip()
            if name:
                names.append(name)
    return names
