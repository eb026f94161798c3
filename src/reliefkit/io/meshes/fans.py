"""glTF triangle fans (primitive mode 6) rewritten as triangle lists before trimesh parses them.

trimesh reads triangle lists (mode 4) and strips (mode 5) but drops fans, so a file made of
fans would load as "contains no triangles". Each fan primitive gets a new index accessor
holding its triangles (first vertex, k, k + 1: the winding glTF defines) and mode 4. The
indices of an indexed fan are read from where its accessor points: the GLB's BIN chunk, a
data: URI, or a buffer file next to the mesh (a regular file within the size cap). A fan
whose indices cannot be found or do not fit is left as it is, for the later checks.
"""

from __future__ import annotations

import base64
import json
import struct
import urllib.parse
from pathlib import Path

import numpy as np

from .badfile import BadFile, read_regular

_FAN, _TRIANGLES = 6, 4
_INDEX_TYPES = {5121: "<u1", 5123: "<u2", 5125: "<u4"}
_DATA_URI = "data:application/octet-stream;base64,"
_GLB_JSON, _GLB_BIN = 0x4E4F534A, 0x004E4942


def triangulate_fans(data: bytes, file_type: str, folder: Path) -> bytes:
    """`data` (a .gltf or .glb) with every fan primitive turned into a triangle list."""
    tree, chunks = _split(data, file_type)
    fans = [p for mesh in _list(tree, "meshes") if isinstance(mesh, dict)
            for p in _list(mesh, "primitives") if isinstance(p, dict) and p.get("mode") == _FAN]
    if not fans:
        return data
    binary = next((c for kind, c in chunks if kind == _GLB_BIN), None)
    appended = bytearray()
    changed = False
    for primitive in fans:
        fan = _fan_indices(tree, primitive, binary, folder)
        if fan is None or len(fan) < 3:
            continue
        triangles = np.empty((len(fan) - 2, 3), "<u4")
        triangles[:, 0], triangles[:, 1], triangles[:, 2] = fan[0], fan[1:-1], fan[2:]
        raw = triangles.tobytes()
        if file_type == "glb":
            if binary is None or "uri" in _buffer(tree, 0):
                continue  # no BIN chunk to extend (trimesh reads no other GLB buffers)
            offset = len(binary) + len(appended)
            appended += raw + b"\0" * (-len(raw) % 4)
            view = {"buffer": 0, "byteOffset": offset, "byteLength": len(raw)}
        else:
            tree.setdefault("buffers", []).append(
                {"byteLength": len(raw), "uri": _DATA_URI + base64.b64encode(raw).decode()})
            view = {"buffer": len(tree["buffers"]) - 1, "byteLength": len(raw)}
        tree.setdefault("bufferViews", []).append(view)
        tree.setdefault("accessors", []).append({
            "bufferView": len(tree["bufferViews"]) - 1, "componentType": 5125,
            "count": int(triangles.size), "type": "SCALAR"})
        primitive["indices"] = len(tree["accessors"]) - 1
        primitive["mode"] = _TRIANGLES
        changed = True
    if not changed:
        return data
    if file_type == "gltf":
        return json.dumps(tree).encode("utf-8")
    if appended:
        tree["buffers"][0]["byteLength"] = len(binary) + len(appended)
        chunks = [(kind, c + bytes(appended) if kind == _GLB_BIN else c) for kind, c in chunks]
    return _glb(tree, chunks)


def _split(data: bytes, file_type: str) -> tuple[dict, list[tuple[int, bytes]]]:
    """The JSON tree and, for a GLB, every chunk after the JSON one (checked before)."""
    if file_type == "gltf":
        return json.loads(data.decode("utf-8", "replace")), []
    (length,) = struct.unpack_from("<I", data, 8)
    offset, chunks, tree = 12, [], None
    while offset + 8 <= length:
        size, kind = struct.unpack_from("<II", data, offset)
        body = data[offset + 8 : offset + 8 + size]
        if tree is None:
            tree = json.loads(body.decode("utf-8", "replace"))
        else:
            chunks.append((kind, body))
        offset += 8 + size
    return tree, chunks


def _glb(tree: dict, chunks: list[tuple[int, bytes]]) -> bytes:
    text = json.dumps(tree).encode("utf-8")
    text += b" " * (-len(text) % 4)
    body = struct.pack("<II", len(text), _GLB_JSON) + text
    body += b"".join(struct.pack("<II", len(c), kind) + c for kind, c in chunks)
    return struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body


def _list(node: dict, key: str) -> list:
    value = node.get(key, [])
    return value if isinstance(value, list) else []


def _buffer(tree: dict, index) -> dict:
    buffers = _list(tree, "buffers")
    ok = isinstance(index, int) and 0 <= index < len(buffers) and isinstance(buffers[index], dict)
    return buffers[index] if ok else {}


def _fan_indices(tree: dict, primitive: dict, binary: bytes | None,
                 folder: Path) -> np.ndarray | None:
    """The fan's vertex order: its index accessor's values, else 0 .. count - 1."""
    accessors = _list(tree, "accessors")
    try:
        if "indices" not in primitive:
            count = int(accessors[primitive["attributes"]["POSITION"]]["count"])
            return np.arange(count, dtype=np.int64)
        accessor = accessors[primitive["indices"]]
        view = _list(tree, "bufferViews")[accessor["bufferView"]]
        dtype = np.dtype(_INDEX_TYPES[accessor["componentType"]])
        count = int(accessor["count"])
        start = int(view.get("byteOffset", 0)) + int(accessor.get("byteOffset", 0))
        source = _buffer_bytes(_buffer(tree, view["buffer"]), view["buffer"], binary, folder)
        if source is None or count < 0 or start < 0 or start + count * dtype.itemsize > len(
                source) or "sparse" in accessor:
            return None
        return np.frombuffer(source, dtype, count, start).astype(np.int64)
    except (KeyError, IndexError, TypeError, ValueError, OverflowError):
        return None


def _buffer_bytes(buffer: dict, index: int, binary: bytes | None, folder: Path) -> bytes | None:
    uri = buffer.get("uri")
    if uri is None:
        return binary if index == 0 else None
    if not isinstance(uri, str):
        return None
    if uri.startswith("data:"):
        head, _, payload = uri.partition(",")
        return base64.b64decode(payload) if head.endswith(";base64") else None
    name = Path(urllib.parse.unquote(uri))
    if name.is_absolute() or ".." in name.parts:
        return None
    try:
        return read_regular(folder / name)
    except BadFile:
        return None
