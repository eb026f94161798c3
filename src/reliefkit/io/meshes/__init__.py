"""`load_mesh`: read OBJ, PLY, STL, OFF, glTF and GLB files into one `RenderMesh`;
`load_mesh_bytes`: the same from their bytes (unpacked privately by :mod:`.unpack`).

Parsing is trimesh's, quietly (:mod:`.parse`); this package adds what a renderer needs on top
of it: a structural check per format before parsing (:mod:`.obj`, which also triangulates
concave polygons with :mod:`.polygons`, :mod:`.ply`, :mod:`.stl`, :mod:`.off`, :mod:`.gltf`,
with triangle fans rewritten as lists by :mod:`.fans`), large plain OBJ files and binary STL
files read with numpy in a few times their size (:mod:`.plain_obj`, :mod:`.stl`),
the scene flattened with its transforms applied (:mod:`.scene`), linear colours and every
material with its texture (:mod:`.materials`, :mod:`.texture_transform`, :mod:`.merge`),
usable normals (:mod:`.normals`), and one `MeshError` naming the file for any bad input.
"""

from __future__ import annotations

import contextlib
import gc
import logging
import os
import warnings
from collections.abc import Mapping
from pathlib import Path

from ...errors import MeshError
from ...scene.mesh import RenderMesh
from .badfile import MAX_FILE_BYTES, BadFile, read_regular, regular_file_size
from .fans import triangulate_fans
from .gltf import check_glb, check_gltf
from .materials import DEFAULT_COLOR  # noqa: F401  (public name, kept importable here)
from .merge import render_mesh
from .obj import check_obj
from .off import check_off
from .parse import parse_file
from .plain_obj import read_plain_obj
from .ply import check_ply
from .scene import MAX_COORDINATE, check_visible, scene_parts
from .stl import binary_stl, check_stl
from .texture_transform import uv_transforms
from .unpack import renamed, unpacked

__all__ = ["MAX_COORDINATE", "MAX_FILE_BYTES", "SUPPORTED_EXTENSIONS", "load_mesh",
           "load_mesh_bytes"]

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
    path : str, bytes or os.PathLike
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
        The file is missing, not a regular file (a FIFO, a device such as a link to
        /dev/zero, a socket: also for the files it references), larger than
        `MAX_FILE_BYTES`, unsupported (glTF 1.0, a required glTF extension that cannot be
        read), unreadable, truncated, empty, has NaN/Inf coordinates, coordinates or
        scene-graph matrices beyond `MAX_COORDINATE` or not finite, out-of-range face
        indices, no triangle with a visible area (every face of zero area: collinear or
        coincident corners, a node scaled to 0, slivers far thinner than float32 can
        resolve), or a glTF buffer that is missing or cannot be read. The message is one
        line that starts with the path; nothing the parsing libraries log or warn reaches
        stderr. Any other failure while parsing bad input (running out of memory, a parser's
        internal error) is turned into a `MeshError` naming the file as well.

    Notes
    -----
    A mesh with some visible triangles keeps its zero-area ones (they draw nothing). Problems
    that do not stop the mesh from rendering are listed, one line each, in
    ``extra["warnings"]`` (present only when there are some): a ``.mtl`` or a texture that is
    missing, outside the mesh's folder (never read) or not a regular file is one warning, and
    the mesh is drawn with the default material or with the material's colour instead.
    """
    path = Path(os.fsdecode(path))  # bytes names too (undecodable bytes as surrogates)
    try:
        with _silenced():
            return _load(path, name or path.stem)
    except BadFile as exc:
        raise MeshError(f"{path}: {exc}") from None
    except MeshError:
        raise
    except MemoryError:
        raise MeshError(
            f"{path}: ran out of memory while reading it; is it corrupt, or too large for "
            "this machine?") from None
    except RecursionError:
        raise MeshError(f"{path}: is nested too deeply to read; is it corrupt?") from None
    except Exception as exc:  # noqa: BLE001 - the last resort: bad input is never a crash
        detail = " ".join(str(exc).split())[:200] or "no details"
        raise MeshError(
            f"{path}: could not be read ({type(exc).__name__}: {detail}); is it corrupt?"
        ) from exc  # the cause kept for a traceback (RELIEFKIT_DEBUG)


def load_mesh_bytes(file_name: str, data, files: Mapping[str, bytes] | None = None, *,
                    name: str | None = None) -> RenderMesh:
    """`load_mesh` of a file given as bytes: what a worker without the caller's file system
    (a batch task) loads.

    Parameters
    ----------
    file_name : str
        The mesh file's name: its suffix picks the format, and every message and warning
        names it (with the folder it may carry, as "lib/chair.obj": then the referenced
        files' too), never the private folder the bytes are unpacked into.
    data : bytes, bytearray or memoryview
        The file's bytes.
    files : mapping, optional
        The files it references (.mtl, textures, glTF buffers and images) by their name
        relative to its folder, POSIX separators ("textures/wood.png"), with their bytes:
        what `reliefkit.io.meshes.references.referenced_files` lists for the file on disk
        (``{name: path.read_bytes() for name, path in referenced_files(mesh).items()}``).
        One named outside the folder (absolute, ``..``) is refused.
    name : str, optional
        As `load_mesh`'s (default: the file name without its extension).

    Returns
    -------
    RenderMesh
        The mesh `load_mesh` reads from those files on disk, the same arrays and warnings
        (``extra["source"]`` is ``file_name``).

    Raises
    ------
    MeshError
        What `load_mesh` raises for those files, naming ``file_name``; a name in ``files``
        outside the folder; a file that cannot be unpacked (a full disk).
    """
    with unpacked(file_name, data, files or {}) as path:
        try:
            mesh = load_mesh(path, name=name or Path(file_name).stem)
        except MeshError as exc:
            raise MeshError(renamed(str(exc), path, file_name)) from exc
        mesh.extra["source"] = str(file_name)
        if "warnings" in mesh.extra:
            mesh.extra["warnings"] = [renamed(w, path, file_name) for w in mesh.extra["warnings"]]
    return mesh


@contextlib.contextmanager
def _silenced():
    """No library warning or trimesh log record reaches stderr while loading (also outside
    parsing: trimesh computes scene-graph transforms and caches lazily)."""
    log = logging.getLogger("trimesh")
    quiet, propagate = logging.NullHandler(), log.propagate
    log.addHandler(quiet)
    log.propagate = False
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            yield
    finally:
        log.removeHandler(quiet)
        log.propagate = propagate


def _load(path: Path, label: str) -> RenderMesh:
    file_type = _file_type(path)
    notes: list[str] = []  # the load's warnings (a .mtl or texture not read, dropped references)
    scene, transforms = _parsed(path, file_type, notes)
    parts = scene_parts(scene, srgb=file_type not in _GLTF_FORMATS, uv_transforms=transforms)
    del scene  # trimesh's other arrays and caches (and the file's bytes, which its load
    gc.collect()  # record keeps) go before the mesh is merged; they sit in reference cycles
    if not parts:
        raise BadFile("contains no triangles (only points, lines or nothing): no surface to use")
    check_visible(parts)
    mesh = render_mesh(parts, label, path)
    if notes:  # before the ones merging found (textures, see .materials)
        mesh.extra["warnings"] = notes + list(mesh.extra.get("warnings", []))
    return mesh


def _parsed(path: Path, file_type: str, notes: list[str]):
    """The file checked and parsed: (trimesh scene, glTF UV transforms by geometry).

    The file's bytes live only in here, so they are freed before the scene is flattened.
    """
    data = _read_bytes(path)
    if not data:
        raise BadFile("is empty (0 bytes)")
    if file_type == "obj":
        plain = read_plain_obj(data)
        if plain is not None:  # the common large case, read without trimesh's text copies
            del data
            return parse_file(plain, file_type, path, notes), {}
    data = check_obj(data, notes) if file_type == "obj" else _PRECHECKS[file_type](data)
    if file_type == "stl" and (binary := binary_stl(data)) is not None:
        del data  # read in place, not copied once more by trimesh
        return parse_file(binary, file_type, path, notes), {}
    if file_type in _GLTF_FORMATS:
        data = triangulate_fans(data, file_type, path.parent)
    scene = parse_file(data, file_type, path, notes)
    transforms = uv_transforms(data, file_type, scene) if file_type in _GLTF_FORMATS else {}
    return scene, transforms


def _file_type(path: Path) -> str:
    """Return the trimesh file type of `path` after checking it is a readable kind of file."""
    if not os.path.lexists(path):
        raise BadFile("no such file")
    if not path.exists():
        raise BadFile("is a broken symbolic link")
    regular_file_size(path)  # not a directory, FIFO or device, and within the size cap
    suffix = path.suffix.lower()
    if suffix not in SUPPORTED_EXTENSIONS:
        raise BadFile(
            f"unsupported file type '{suffix or '(no extension)'}'; "
            f"supported: {', '.join(SUPPORTED_EXTENSIONS)}"
        )
    return suffix[1:]


def _read_bytes(path: Path) -> bytes:
    return read_regular(path)
