"""`load_mesh`: read OBJ, PLY, STL, OFF, glTF and GLB files into one `RenderMesh`.

Parsing is trimesh's; this module adds what a renderer needs on top of it:

* a scene is flattened with its scene-graph transforms applied, in the file's own world
  coordinates (never rescaled or recentred), and all triangle geometry is concatenated;
* base colours become linear floats (sRGB-encoded 8-bit colours are decoded; glTF colours
  are linear by specification and kept), a single base-colour texture is kept as sRGB RGBA
  bytes with row 0 at v = 0, several different textures are baked into vertex colours;
* the file's vertex normals are kept where they are usable, the rest are computed;
* bad input becomes one `MeshError` that names the file. trimesh silently accepts some
  broken files (a truncated STL reads as an empty scene, a truncated ASCII PLY or OFF
  loses its last faces, missing .mtl/texture/image files are skipped, out-of-range PLY and
  glTF indices are kept as they are), so each format gets a small structural check before
  trimesh parses it, and the parsed geometry is checked again afterwards.
"""

from __future__ import annotations

import io
import json
import os
import re
import struct
import urllib.parse
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import trimesh

from ..errors import MeshError
from .mesh import RenderMesh, vertex_normals

__all__ = ["SUPPORTED_EXTENSIONS", "load_mesh"]

#: File name extensions `load_mesh` reads (lower case, with the dot).
SUPPORTED_EXTENSIONS = (".obj", ".ply", ".stl", ".off", ".gltf", ".glb")

#: Linear base colour of a surface whose file gives none.
DEFAULT_COLOR = (0.8, 0.8, 0.8, 1.0)

_LINEAR_COLOR_FORMATS = ("gltf", "glb")  # glTF stores vertex colours and factors linear


class _BadFile(Exception):
    """Internal: what is wrong with the file; `load_mesh` adds the path."""


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
        rescaling or recentring), with unit normals, linear RGBA colours and, when the whole
        mesh uses one base-colour texture, its UVs and the (h, w, 4) uint8 sRGB texture.

    Raises
    ------
    MeshError
        The file is missing, unsupported, unreadable, truncated, empty, has NaN/Inf
        coordinates or out-of-range face indices, or references a missing file. The message
        is one line that starts with the path.
    """
    path = Path(path)
    try:
        return _load(path, name or path.stem)
    except _BadFile as exc:
        raise MeshError(f"{path}: {exc}") from None


def _load(path: Path, label: str) -> RenderMesh:
    file_type = _file_type(path)
    data = _read_bytes(path)
    data = _PRECHECKS[file_type](data)
    scene = _parse(data, file_type, path)
    parts = _scene_parts(scene, srgb=file_type not in _LINEAR_COLOR_FORMATS)
    if not parts:
        raise _BadFile("contains no triangles (only points, lines or nothing); nothing to render")
    return _render_mesh(parts, label, path)


# --------------------------------------------------------------------------------------
# the file itself


def _file_type(path: Path) -> str:
    """Return the trimesh file type of `path` after checking it is a readable kind of file."""
    if not path.exists():
        raise _BadFile("no such file")
    if path.is_dir():
        raise _BadFile("is a directory, not a mesh file")
    suffix = path.suffix.lower()
    if suffix not in SUPPORTED_EXTENSIONS:
        raise _BadFile(
            f"unsupported file type '{suffix or '(no extension)'}'; "
            f"supported: {', '.join(SUPPORTED_EXTENSIONS)}"
        )
    return suffix[1:]


def _read_bytes(path: Path) -> bytes:
    try:
        return path.read_bytes()
    except OSError as exc:
        raise _BadFile(f"cannot read the file ({exc.strerror or exc})") from None


def _text(data: bytes, what: str) -> str:
    """Decode a text format: UTF-8, else Latin-1 (which every byte string decodes as)."""
    if b"\0" in data:
        raise _BadFile(f"is not a text {what} file (it contains NUL bytes); is it corrupt?")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        return data.decode("latin-1")


def _as_utf8(data: bytes, what: str) -> bytes:
    """Text re-encoded as UTF-8, so trimesh never needs to guess an encoding."""
    return _text(data, what).encode("utf-8")


# --------------------------------------------------------------------------------------
# structural checks trimesh does not make (each returns the bytes trimesh should parse)


# OBJ records that define or use indices: (keyword, rest of the line without its comment)
_OBJ_RECORD = re.compile(r"(?m)^[ \t]*(vt|vn|v|f)[ \t]+([^\n#]*)")
# what the index in each field of a face corner v/vt/vn is called, and what it counts
_OBJ_SLOTS = {
    "v": ("face index", "vertices"),
    "vt": ("face texture-coordinate index", "texture coordinates"),
    "vn": ("face normal index", "normals"),
}


def _check_obj(data: bytes) -> bytes:
    """Check every face corner of an OBJ against the v/vt/vn it defines."""
    text = _text(data, "OBJ").replace("\\\n", "")
    records = _OBJ_RECORD.findall(text)
    kinds = [kind for kind, _ in records]
    totals = {slot: kinds.count(slot) for slot in _OBJ_SLOTS}
    fields = _obj_face_fields(" ".join(rest for kind, rest in records if kind == "f"))
    for slot, values in fields.items():
        indices = _integers(values)
        if (indices < 0).any():  # relative indices depend on what precedes each face
            _check_obj_relative(records, totals)
            break
        bad = indices[(indices < 1) | (indices > totals[slot])]
        if bad.size:
            _check_obj_index(str(bad[0]), slot, totals[slot], totals[slot])
    return text.encode("utf-8")


def _obj_face_fields(faces: str) -> dict[str, list[str]]:
    """The non-empty v, vt and vn fields of the face corners ('v', 'v/vt', 'v//vn', ...)."""
    corners = faces.split()
    if "/" not in faces:
        return {"v": corners}
    fields = [corner.split("/") for corner in corners]
    return {
        "v": [f[0] for f in fields],
        "vt": [f[1] for f in fields if len(f) > 1 and f[1]],
        "vn": [f[2] for f in fields if len(f) > 2 and f[2]],
    }


def _integers(fields: list[str]) -> np.ndarray:
    try:
        return np.array(list(map(int, fields)), dtype=np.int64)
    except ValueError as exc:
        raise _BadFile(f"malformed index ({exc})") from None
    except OverflowError:
        raise _BadFile("has an index too large to be real") from None


def _check_obj_relative(records: list[tuple[str, str]], totals: dict[str, int]) -> None:
    """Face corners one by one, resolving negative indices against the records before them."""
    seen = dict.fromkeys(totals, 0)
    for kind, rest in records:
        if kind != "f":
            seen[kind] += 1
            continue
        for corner in rest.split():
            for slot, field in zip(_OBJ_SLOTS, corner.split("/"), strict=False):
                if field:
                    _check_obj_index(field, slot, seen[slot], totals[slot])


def _check_obj_index(field: str, slot: str, seen: int, total: int) -> None:
    """One OBJ face index: 1-based absolute, or negative and relative to the `seen` so far."""
    try:
        index = int(field)
    except ValueError:
        raise _BadFile(f"malformed face entry '{field}' (expected an integer)") from None
    kind, noun = _OBJ_SLOTS[slot]
    if index == 0 or index > total or index < -seen:
        hint = " (OBJ indices start at 1)" if index == 0 else ""
        raise _BadFile(f"{kind} {index} out of range for {total} {noun}{hint}")
    if index < 0 and seen != total:
        raise _BadFile(
            f"uses relative (negative) indices before all {noun} are defined, which the "
            "reader (trimesh) resolves wrongly; re-export it with absolute indices"
        )


def _check_off(data: bytes) -> bytes:
    """Check an OFF file's counts and face indices, line by line as trimesh reads it."""
    text = re.sub(r"#[^\n]*", "", _text(data, "OFF"))
    found = re.search(r"COFF|OFF", text)
    if found is None:
        raise _BadFile("is not an OFF file (no 'OFF' header)")
    lines = [line for line in text[found.end() :].splitlines() if line.strip()]
    counts = lines[0].split() if lines else []
    try:
        n_vertices, n_faces = int(counts[0]), int(counts[1])
    except (IndexError, ValueError):
        raise _BadFile(f"malformed OFF count line '{' '.join(counts)}'") from None
    vertex_lines = lines[1 : 1 + n_vertices]
    face_lines = lines[1 + n_vertices : 1 + n_vertices + n_faces]
    if len(vertex_lines) < n_vertices or len(face_lines) < n_faces:
        raise _BadFile(
            f"truncated: its header declares {n_vertices} vertices and {n_faces} faces, "
            f"the file has {len(vertex_lines)} and {len(face_lines)}"
        )
    _check_range(_off_face_indices(face_lines), n_vertices)
    return data


def _off_face_indices(lines: list[str]) -> np.ndarray:
    """The vertex indices on OFF face lines ('n i1 ... in [colour]')."""
    try:  # fast path: every line holds n + 1 integers (and maybe an integer colour)
        values = np.array(list(map(int, " ".join(lines).split())), dtype=np.int64)
        table = values.reshape(len(lines), -1)
        n = int(table[0, 0])
        if n + 1 <= table.shape[1] and (table[:, 0] == n).all():
            return table[:, 1 : n + 1].ravel()
    except (ValueError, OverflowError, IndexError):
        pass  # float colours, mixed polygon sizes, ...: go line by line
    return np.array([i for line in lines for i in _off_face(line.split())], dtype=np.int64)


def _off_face(tokens: list[str]) -> list[int]:
    """The vertex indices of one OFF face line."""
    try:
        count = int(tokens[0])
        indices = [int(t) for t in tokens[1 : 1 + count]]
    except ValueError:
        raise _BadFile(f"malformed OFF face line '{' '.join(tokens)}'") from None
    if len(indices) < count:
        raise _BadFile(f"truncated or malformed OFF face line '{' '.join(tokens)}'")
    return indices


def _check_stl(data: bytes) -> bytes:
    """Detect truncated STL files, which trimesh reads as an empty scene."""
    count = int.from_bytes(data[80:84], "little") if len(data) >= 84 else -1
    expected = 84 + 50 * count
    if len(data) == expected:
        return data
    if data.lstrip()[:5].lower() == b"solid" and b"\0" not in data:
        if not re.search(rb"endsolid[^\n]*\s*$", data[-1024:]):
            raise _BadFile("truncated ASCII STL (no final 'endsolid' line)")
        return data
    if count < 0:
        raise _BadFile(
            f"truncated or not an STL file: {len(data)} bytes is less than a binary STL "
            "header (84 bytes) and it is not ASCII STL"
        )
    if len(data) < expected:
        raise _BadFile(
            f"truncated or corrupt binary STL: its header declares {count} triangles "
            f"({expected} bytes) but the file has {len(data)} bytes"
        )
    return data[:expected]  # trailing bytes after the declared triangles are ignored


_GLB_JSON_CHUNK = 0x4E4F534A


def _check_glb(data: bytes) -> bytes:
    """Check the GLB header and that every chunk fits inside the file."""
    if len(data) < 12:
        raise _BadFile(f"truncated GLB: {len(data)} bytes, less than its 12-byte header")
    magic, version, length = struct.unpack_from("<4sII", data)
    if magic != b"glTF":
        raise _BadFile("is not a GLB file (it does not start with 'glTF'); is it corrupt?")
    if version != 2:
        raise _BadFile(f"GLB version {version} is not supported (only glTF 2)")
    if length > len(data):
        raise _BadFile(
            f"truncated GLB: its header declares {length} bytes but the file has {len(data)}"
        )
    offset, chunk = 12, 0
    while offset < length:
        if offset + 8 > length:
            raise _BadFile("truncated GLB: a chunk header is cut off")
        size, kind = struct.unpack_from("<II", data, offset)
        if offset + 8 + size > length:
            raise _BadFile(f"truncated GLB: chunk {chunk} needs {size} bytes, fewer remain")
        if chunk == 0 and kind != _GLB_JSON_CHUNK:
            raise _BadFile("is not a valid GLB file (its first chunk is not JSON)")
        offset, chunk = offset + 8 + size, chunk + 1
    if chunk == 0:
        raise _BadFile("is not a valid GLB file (it has no JSON chunk)")
    return data


def _check_gltf(data: bytes) -> bytes:
    """A .gltf must be a JSON object (trimesh would otherwise look for 'model.gltf')."""
    try:
        tree = json.loads(_text(data, "glTF"))
    except json.JSONDecodeError as exc:
        raise _BadFile(f"is not valid glTF JSON ({exc})") from None
    if not isinstance(tree, dict):
        raise _BadFile("is not a glTF file (its JSON is not an object)")
    return data


# PLY property types and their numpy codes
_PLY_TYPES = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1",
    "short": "i2", "int16": "i2", "ushort": "u2", "uint16": "u2",
    "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
    "float": "f4", "float32": "f4", "double": "f8", "float64": "f8",
}  # fmt: skip


@dataclass(frozen=True)
class _PlyProperty:
    name: str
    type: str  # numpy code of the value (of each list item, for a list)
    count_type: str | None = None  # numpy code of the list length; None for a scalar


@dataclass(frozen=True)
class _PlyElement:
    name: str
    count: int
    properties: tuple[_PlyProperty, ...]


def _check_ply(data: bytes) -> bytes:
    """Check that the body holds every row the PLY header declares."""
    encoding, elements, body = _ply_header(data)
    if encoding == "ascii":
        _check_ply_ascii(data[body:], elements)
    else:
        endian = "<" if encoding == "binary_little_endian" else ">"
        _check_ply_binary(data, body, elements, endian)
    return data


def _ply_header(data: bytes) -> tuple[str, list[_PlyElement], int]:
    """Parse a PLY header: (encoding, elements, offset of the body)."""
    if not data.startswith(b"ply"):
        raise _BadFile("is not a PLY file (it does not start with 'ply')")
    end = re.search(rb"\bend_header[^\n]*\n", data)
    if end is None:
        raise _BadFile("truncated PLY: the header has no 'end_header' line")
    encoding, elements = None, []
    for line in data[: end.start()].decode("latin-1").splitlines()[1:]:
        words = line.split()
        try:
            if words[:1] == ["format"]:
                encoding = words[1]
            elif words[:1] == ["element"]:
                elements.append(_PlyElement(words[1], int(words[2]), ()))
            elif words[:2] == ["property", "list"]:
                prop = _PlyProperty(words[4], _PLY_TYPES[words[3]], _PLY_TYPES[words[2]])
                elements[-1] = replace(elements[-1], properties=elements[-1].properties + (prop,))
            elif words[:1] == ["property"]:
                prop = _PlyProperty(words[2], _PLY_TYPES[words[1]])
                elements[-1] = replace(elements[-1], properties=elements[-1].properties + (prop,))
        except (IndexError, KeyError, ValueError):
            raise _BadFile(f"malformed PLY header line '{line.strip()}'") from None
    if encoding not in ("ascii", "binary_little_endian", "binary_big_endian"):
        raise _BadFile(f"unknown PLY format '{encoding}'")
    if any(e.count < 0 for e in elements):
        raise _BadFile("malformed PLY header (a negative element count)")
    return encoding, elements, end.end()


def _check_ply_ascii(body: bytes, elements: list[_PlyElement]) -> None:
    """ASCII PLY rows are lines (as trimesh reads them); a cut file ends in a short row."""
    lines = body.splitlines()
    start = 0
    for element in elements:
        have = max(0, min(element.count, len(lines) - start))
        if have < element.count:
            raise _BadFile(
                f"truncated PLY: element '{element.name}' has {have} of its {element.count} rows"
            )
        start += element.count
    last = next((e for e in reversed(elements) if e.count), None)
    if last is not None and not _ply_ascii_row_complete(lines[start - 1].split(), last):
        raise _BadFile(f"truncated PLY: the last row of element '{last.name}' is cut off")


def _ply_ascii_row_complete(tokens: list[bytes], element: _PlyElement) -> bool:
    need = 0
    for prop in element.properties:
        if prop.count_type is not None:
            if need >= len(tokens):
                return False
            try:
                need += int(float(tokens[need]))
            except (ValueError, OverflowError):
                return False
        need += 1
    return len(tokens) >= need


def _check_ply_binary(data: bytes, offset: int, elements: list[_PlyElement], endian: str) -> None:
    """Binary PLY: each element's rows must fit; lists must keep their first row's length."""
    for element in elements:
        if element.count == 0 or not element.properties:
            continue
        row = _ply_row_dtype(data, offset, element, endian)
        if row is None:
            raise _BadFile(f"truncated PLY: element '{element.name}' is cut off")
        size = element.count * row.itemsize
        present = min(element.count, (len(data) - offset) // max(row.itemsize, 1))
        rows = np.frombuffer(data, dtype=row, count=present, offset=offset)
        if any(np.any(rows[f] != rows[f][0]) for f in row.names if f.endswith("#count")):
            raise _BadFile(
                f"binary PLY element '{element.name}' mixes list lengths (e.g. triangles "
                "and quads), which the reader (trimesh) cannot load; triangulate it"
            )
        if offset + size > len(data):
            raise _BadFile(
                f"truncated PLY: element '{element.name}' needs {size} bytes, "
                f"{max(0, len(data) - offset)} remain"
            )
        offset += size


def _ply_row_dtype(data: bytes, offset: int, element: _PlyElement, endian: str) -> np.dtype | None:
    """The structured dtype of a binary row, with list lengths taken from the first row.

    None when the first row is cut off.
    """
    fields, width = [], 0
    for prop in element.properties:
        if prop.count_type is None:
            fields.append((prop.name, endian + prop.type))
            width += np.dtype(prop.type).itemsize
            continue
        count_type = np.dtype(endian + prop.count_type)
        if offset + width + count_type.itemsize > len(data):
            return None
        length = int(np.frombuffer(data, count_type, 1, offset + width)[0])
        fields += [(prop.name + "#count", count_type), (prop.name, endian + prop.type, (length,))]
        width += count_type.itemsize + length * np.dtype(prop.type).itemsize
    try:
        return np.dtype(fields)
    except (TypeError, ValueError) as exc:  # duplicate property names, absurd list lengths
        raise _BadFile(f"malformed PLY element '{element.name}' ({exc})") from None


_PRECHECKS = {
    "obj": _check_obj,
    "off": _check_off,
    "stl": _check_stl,
    "ply": _check_ply,
    "glb": _check_glb,
    "gltf": _check_gltf,
}


# --------------------------------------------------------------------------------------
# parsing with trimesh


class _RecordingResolver(trimesh.resolvers.FilePathResolver):
    """Find referenced files next to the mesh and remember the ones that are missing.

    trimesh skips a missing .mtl, texture or image silently, so `_parse` asks this resolver
    afterwards. Names are also tried URL-decoded (glTF URIs escape spaces as %20), and .mtl
    files are handed over as UTF-8 like the OBJ itself.
    """

    def __init__(self, source: Path):
        super().__init__(str(source))
        self.missing: list[str] = []
        self.outside: list[str] = []

    def get(self, name: str) -> bytes:
        for candidate in dict.fromkeys((name, urllib.parse.unquote(name))):
            try:
                data = super().get(candidate)
            except FileNotFoundError:
                continue
            except ValueError:  # the name leads out of the mesh's folder
                self.outside.append(name)
                raise
            return _as_utf8(data, "MTL") if name.lower().endswith(".mtl") else data
        self.missing.append(name)
        raise FileNotFoundError(name)

    def problem(self) -> str | None:
        """A message for the first unusable reference, or None."""
        if self.missing:
            return f"references missing file '{self.missing[0]}' (looked in {self.parent})"
        if self.outside:
            return (
                f"references '{self.outside[0]}' outside its folder, which is not read; "
                "copy it next to the mesh"
            )
        return None


def _parse(data: bytes, file_type: str, path: Path) -> trimesh.Scene:
    """Parse with trimesh, converting everything it raises into `_BadFile`."""
    resolver = _RecordingResolver(path)
    try:
        with np.errstate(all="ignore"):  # trimesh's own arithmetic on odd but valid data
            scene = trimesh.load_scene(
                io.BytesIO(data), file_type=file_type, resolver=resolver, process=False
            )
    except Exception as exc:  # noqa: BLE001 - any parser failure is a bad file
        raise _BadFile(resolver.problem() or _parse_failure(file_type, exc)) from None
    problem = resolver.problem()
    if problem:
        raise _BadFile(problem)
    return scene if isinstance(scene, trimesh.Scene) else trimesh.Scene(scene)


def _parse_failure(file_type: str, exc: Exception) -> str:
    detail = " ".join(str(exc).split())[:200] or "no details"
    return (
        f"could not read it as {file_type.upper()} ({type(exc).__name__}: {detail}); "
        "is it corrupt or truncated?"
    )


# --------------------------------------------------------------------------------------
# flattening the scene into parts


@dataclass(frozen=True)
class _Part:
    """One triangle geometry as it will enter the merged mesh."""

    positions: np.ndarray  # (V, 3) float64
    faces: np.ndarray  # (F, 3) int64, indices into this part
    normals: np.ndarray  # (V, 3) float64 from the file; NaN rows where there are none
    colors: np.ndarray  # (V, 4) float64 linear RGBA
    uvs: np.ndarray | None = None  # (V, 2) float64
    texture: np.ndarray | None = None  # (h, w, 4) uint8 sRGB, row 0 at v = 0


def _scene_parts(scene: trimesh.Scene, srgb: bool) -> list[_Part]:
    """Every instance of every triangle geometry, placed in world space."""
    local: dict[str, _Part | None] = {}
    parts = []
    several = len(scene.geometry) > 1
    for node in scene.graph.nodes_geometry:
        matrix, geometry_name = scene.graph[node]
        if geometry_name not in local:
            geometry = scene.geometry[geometry_name]
            where = f" in mesh '{geometry_name}'" if several else ""
            local[geometry_name] = _local_part(geometry, srgb, where)
        part = local[geometry_name]
        if part is not None:
            parts.append(_placed(part, np.asarray(matrix, dtype=np.float64)))
    return parts


def _local_part(geometry, srgb: bool, where: str) -> _Part | None:
    """A trimesh geometry as a `_Part`; None for points, lines and meshes without faces."""
    if not isinstance(geometry, trimesh.Trimesh) or len(geometry.faces) == 0:
        return None
    positions = np.asarray(geometry.vertices, dtype=np.float64)
    faces = np.asarray(geometry.faces, dtype=np.int64)
    _check_range(faces, len(positions), where)
    bad = int((~np.isfinite(positions)).any(axis=1).sum())
    if bad:
        raise _BadFile(f"{_vertices_have(bad)} NaN or Inf coordinates{where}")
    surface = _base_color(geometry.visual, len(positions), srgb)
    part = _Part(positions, faces, _file_normals(geometry), *surface)
    if _is_face_colored(geometry.visual):
        corner_colors = np.repeat(_decode_colors(geometry.visual.face_colors, srgb), 3, axis=0)
        part = replace(_unshared(part), colors=corner_colors)
    return part


def _vertices_have(count: int) -> str:
    return "1 vertex has" if count == 1 else f"{count} vertices have"


def _check_range(indices: np.ndarray, count: int, where: str = "") -> None:
    """Raise for the first index outside [0, count)."""
    bad = indices[(indices < 0) | (indices >= count)]
    if bad.size:
        raise _BadFile(f"face index {int(bad[0])} out of range for {count} vertices{where}")


def _file_normals(geometry: trimesh.Trimesh) -> np.ndarray:
    """The vertex normals the file stored, NaN rows for none.

    trimesh computes normals lazily; normals read from a file are the ones already in the
    mesh's cache right after loading (trimesh offers no public way to ask).
    """
    shape = (len(geometry.vertices), 3)
    stored = geometry._cache["vertex_normals"]  # noqa: SLF001 - see docstring
    if stored is None or np.shape(stored) != shape:
        return np.full(shape, np.nan)
    return np.array(stored, dtype=np.float64)


def _is_face_colored(visual) -> bool:
    return isinstance(visual, trimesh.visual.ColorVisuals) and visual.kind == "face"


def _unshared(part: _Part) -> _Part:
    """The same triangles with three vertices of their own each (for per-face attributes)."""
    corners = part.faces.reshape(-1)
    return _Part(
        positions=part.positions[corners],
        faces=np.arange(len(corners), dtype=np.int64).reshape(-1, 3),
        normals=part.normals[corners],
        colors=part.colors[corners],
        uvs=None if part.uvs is None else part.uvs[corners],
        texture=part.texture,
    )


def _placed(part: _Part, matrix: np.ndarray) -> _Part:
    """`part` moved by a 4x4 scene-graph matrix; a mirroring matrix reverses the winding."""
    if np.array_equal(matrix, np.eye(4)):
        return part
    linear = matrix[:3, :3]
    det = np.linalg.det(linear)
    with np.errstate(all="ignore"):
        positions = part.positions @ linear.T + matrix[:3, 3]
        # the cofactor matrix is det * inverse-transpose (and defined for singular matrices):
        # times sign(det) it maps normals to the side the transformed winding faces
        cofactor = np.cross(linear.T[[1, 2, 0]], linear.T[[2, 0, 1]])
        normals = part.normals @ (np.sign(det) * cofactor).T
    bad = int((~np.isfinite(positions)).any(axis=1).sum())
    if bad:
        raise _BadFile(f"{_vertices_have(bad)} NaN or Inf coordinates after the scene transforms")
    faces = part.faces[:, ::-1] if det < 0 else part.faces
    return replace(part, positions=positions, faces=np.ascontiguousarray(faces), normals=normals)


# --------------------------------------------------------------------------------------
# colours


def srgb_to_linear(values: np.ndarray) -> np.ndarray:
    """The exact sRGB decoding function (IEC 61966-2-1) for values in [0, 1]."""
    c = np.clip(np.asarray(values, dtype=np.float64), 0.0, 1.0)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


_SRGB_BYTE_TO_LINEAR = srgb_to_linear(np.arange(256) / 255.0)


def _decode_colors(colors, srgb: bool) -> np.ndarray:
    """(N, 3 or 4) colours (8/16-bit integers or floats in [0, 1]) -> (N, 4) linear float."""
    colors = np.asarray(colors)
    if np.issubdtype(colors.dtype, np.integer):
        unit = colors / float(np.iinfo(colors.dtype).max)
    else:
        unit = np.nan_to_num(colors.astype(np.float64), nan=0.0)
    unit = np.clip(unit, 0.0, 1.0)
    if unit.shape[1] == 3:
        unit = np.column_stack([unit, np.ones(len(unit))])
    if srgb and colors.dtype == np.uint8:
        return np.column_stack([_SRGB_BYTE_TO_LINEAR[colors[:, :3]], unit[:, 3]])
    if srgb:
        return np.column_stack([srgb_to_linear(unit[:, :3]), unit[:, 3]])
    return unit


def _base_color(
    visual, count: int, srgb: bool
) -> tuple[np.ndarray, np.ndarray | None, np.ndarray | None]:
    """Linear colours, UVs and base-colour texture of the `count` vertices of a visual."""
    if isinstance(visual, trimesh.visual.ColorVisuals):
        if visual.kind == "vertex":
            return _decode_colors(visual.vertex_colors, srgb), None, None
        return np.tile(DEFAULT_COLOR, (count, 1)), None, None
    if not isinstance(visual, trimesh.visual.TextureVisuals):
        return np.tile(DEFAULT_COLOR, (count, 1)), None, None
    factor, image = _material(visual.material)
    colors = np.tile(factor, (count, 1))
    vertex_colors = visual.vertex_attributes.get("color")
    if vertex_colors is not None and len(vertex_colors) == count:
        colors = colors * _decode_colors(vertex_colors, srgb)
    uvs = visual.uv
    if uvs is None or len(uvs) != count:
        return colors, None, None
    uvs = np.asarray(uvs, dtype=np.float64)
    bad = int((~np.isfinite(uvs)).any(axis=1).sum())
    if bad:
        raise _BadFile(f"{bad} texture coordinates are NaN or Inf")
    texture = None if image is None else _texture_array(image)
    return colors, uvs, texture


def _material(material) -> tuple[np.ndarray, object]:
    """(linear RGBA factor, PIL image or None) of a trimesh material."""
    if isinstance(material, trimesh.visual.material.PBRMaterial):
        factor = material.baseColorFactor  # linear by the glTF specification
        factor = np.ones(4) if factor is None else np.asarray(factor) / 255.0
        return factor, material.baseColorTexture
    if isinstance(material, trimesh.visual.material.SimpleMaterial):
        image = material.image
        kd = material.kwargs.get("kd")  # present only when the .mtl file gave Kd
        if kd is None:
            return np.array(DEFAULT_COLOR if image is None else (1.0, 1.0, 1.0, 1.0)), image
        kd = np.atleast_1d(np.asarray(kd, dtype=np.float64))
        rgb = kd[:3] if kd.size >= 3 else np.full(3, kd[0])
        return np.append(srgb_to_linear(rgb), 1.0), image
    return np.array(DEFAULT_COLOR), None


def _texture_array(image) -> np.ndarray:
    """A PIL image as (h, w, 4) uint8 RGBA with row 0 at v = 0 (PIL's row 0 is the top)."""
    try:
        rgba = np.asarray(image.convert("RGBA"), dtype=np.uint8)
    except Exception as exc:  # noqa: BLE001 - PIL decodes lazily, so errors surface here
        raise _BadFile(f"its texture image could not be decoded ({exc})") from None
    return np.ascontiguousarray(rgba[::-1])


def _sample_linear(texture: np.ndarray, uvs: np.ndarray) -> np.ndarray:
    """Bilinear, repeating lookup of an sRGB texture at UVs, returning linear RGBA."""
    h, w = texture.shape[:2]
    linear = np.concatenate(
        [_SRGB_BYTE_TO_LINEAR[texture[..., :3]], texture[..., 3:] / 255.0], axis=-1
    )
    x = uvs[:, 0] * w - 0.5
    y = uvs[:, 1] * h - 0.5
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = (x - x0)[:, None], (y - y0)[:, None]
    i0, j0 = x0.astype(np.int64) % w, y0.astype(np.int64) % h  # UVs are finite here
    i1, j1 = (i0 + 1) % w, (j0 + 1) % h
    top = linear[j0, i0] * (1 - fx) + linear[j0, i1] * fx
    bottom = linear[j1, i0] * (1 - fx) + linear[j1, i1] * fx
    return top * (1 - fy) + bottom * fy


# --------------------------------------------------------------------------------------
# merging


def _render_mesh(parts: list[_Part], label: str, path: Path) -> RenderMesh:
    """Concatenate the parts and complete the normals."""
    parts, texture = _resolve_textures(parts)
    offsets = np.cumsum([0] + [len(p.positions) for p in parts[:-1]])
    positions = np.concatenate([p.positions for p in parts])
    faces = np.concatenate([p.faces + o for p, o in zip(parts, offsets, strict=True)])
    uvs = None
    if all(p.uvs is not None for p in parts):
        uvs = np.concatenate([p.uvs for p in parts])
    normals = _usable_normals(np.concatenate([p.normals for p in parts]), positions, faces)
    colors = np.clip(np.concatenate([p.colors for p in parts]), 0.0, 1.0)
    try:
        return RenderMesh(
            positions, faces, normals, colors, uvs, texture, name=label,
            extra={"source": str(path)},
        )  # fmt: skip
    except MeshError as exc:  # the final guard; name the file like every other message
        raise _BadFile(str(exc).removeprefix(f"{label}: ")) from None


def _resolve_textures(parts: list[_Part]) -> tuple[list[_Part], np.ndarray | None]:
    """Keep one texture shared by every part; otherwise bake textures into vertex colours.

    A `RenderMesh` has one texture and no way to mark vertices as untextured, so the texture
    is kept only when every part uses the same one.
    """
    textures = [p.texture for p in parts if p.texture is not None]
    if not textures:
        return parts, None
    first = textures[0]
    if len(textures) == len(parts) and all(_same(t, first) for t in textures):
        return parts, first
    baked = [
        p if p.texture is None
        else replace(p, colors=p.colors * _sample_linear(p.texture, p.uvs), texture=None)
        for p in parts
    ]  # fmt: skip
    return [replace(p, uvs=None) for p in baked], None


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    return a is b or (a.shape == b.shape and np.array_equal(a, b))


def _usable_normals(from_file: np.ndarray, positions: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Unit file normals where finite and non-zero, normals computed from faces elsewhere."""
    with np.errstate(all="ignore"):
        length = np.linalg.norm(from_file, axis=1, keepdims=True)
        unit = from_file / length
    usable = np.isfinite(length) & (length > 1e-12) & np.isfinite(unit).all(axis=1, keepdims=True)
    if usable.all():
        return unit.astype(np.float32)
    return np.where(usable, unit, vertex_normals(positions, faces)).astype(np.float32)
