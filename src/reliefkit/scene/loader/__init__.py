"""`load_mesh`: read OBJ, PLY, STL, OFF, glTF and GLB files into one `RenderMesh`.

Parsing is trimesh's, quietly (:mod:`.parse`); this package adds what a renderer needs on top
of it: a structural check per format before parsing (:mod:`.obj`, which also triangulates
concave polygons with :mod:`.polygons`, :mod:`.ply`, :mod:`.stl`, :mod:`.off`, :mod:`.gltf`),
the scene flattened with its transforms applied (:mod:`.scene`), linear colours and every
material with its texture (:mod:`.materials`, :mod:`.texture_transform`, :mod:`.merge`),
usable normals (:mod:`.normals`), and one `MeshError` naming the file for any bad input.
"""

from __future__ import annotations

import os
from pathlib import Path

from ...errors import MeshError
from ..mesh import RenderMesh
from .badfile import BadFile
from .gltf import check_glb, check_gltf
from .materials import DEFAULT_COLOR  # noqa: F401  (public name, kept importable here)
from .merge import render_mesh
from .obj import check_obj
from .off import check_off
from .parse import parse_file
from .ply import check_ply
from .scene import scene_parts
from .stl import check_stl
from .texture_transform import uv_transforms

__all__ = ["SUPPORTED_EXTENSIONS", "load_mesh"]

#: File name extensions `load_mesh` reads (lower case, with the dot).
SUPPORTED_EXTENSIONS = (".obj", ".ply", ".stl", ".off", ".gltf", ".glb")

_GLTF_FORMATS = ("gltf", "glb")  # linear vertex colours and factors, KHR_texture_transform

_PRECHECKS = {
    "obj": check_obj,
    "off": check_off,
    "stl": check_stl,
    "ply": check_ply,
    "glb": check_glb,
    "gltf": check_gltf,
}


def load_mesh(path: str | os.PathLike, *, name: str | None = None) -> RenderMesh:
    """Load a triangle mesh file into a validated `RenderMesh`.

    Parameters
    ----------
    path : str or os.PathLike
        An .obj, .ply (ASCII or binary), .stl (ASCII or binary), .off, .gltf or .glb file.
        Files it references (.mtl, textures, .bin buffers, images) are looked up next to it.
    name : str, optional
        Label for pictures and messages; defaults to the file name without its extension.

    Returns
    -------
    RenderMesh
        Every triangle of the file in world space (scene-graph transforms applied, no
        rescaling or recentring), with unit normals, linear RGBA vertex colours, UVs, and
        each distinct material of the file (colour factor, texture, UV transform) with the
        triangles that use it.

    Raises
    ------
    MeshError
        The file is missing, unsupported (glTF 1.0, a required glTF extension that cannot be
        read), unreadable, truncated, empty, has NaN/Inf coordinates or out-of-range face
        indices, or references a missing file. The message is one line that starts with the
        path; nothing the parsing libraries log or warn reaches stderr.
    """
    path = Path(path)
    try:
        return _load(path, name or path.stem)
    except BadFile as exc:
        raise MeshError(f"{path}: {exc}") from None


def _load(path: Path, label: str) -> RenderMesh:
    file_type = _file_type(path)
    data = _read_bytes(path)
    if not data:
        raise BadFile("is empty (0 bytes)")
    data = _PRECHECKS[file_type](data)
    scene = parse_file(data, file_type, path)
    transforms = uv_transforms(data, file_type, scene) if file_type in _GLTF_FORMATS else {}
    parts = scene_parts(scene, srgb=file_type not in _GLTF_FORMATS, uv_transforms=transforms)
    if not parts:
        raise BadFile("contains no triangles (only points, lines or nothing); nothing to render")
    return render_mesh(parts, label, path)


def _file_type(path: Path) -> str:
    """Return the trimesh file type of `path` after checking it is a readable kind of file."""
    if not path.exists():
        raise BadFile("no such file")
    if path.is_dir():
        raise BadFile("is a directory, not a mesh file")
    suffix = path.suffix.lower()
    if suffix not in SUPPORTED_EXTENSIONS:
        raise BadFile(
            f"unsupported file type '{suffix or '(no extension)'}'; "
            f"supported: {', '.join(SUPPORTED_EXTENSIONS)}"
        )
    return suffix[1:]


def _read_bytes(path: Path) -> bytes:
    try:
        return path.read_bytes()
    except OSError as exc:
        raise BadFile(f"cannot read the file ({exc.strerror or exc})") from None
