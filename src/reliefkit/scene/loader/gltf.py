"""The structural checks of glTF files: the GLB container and .gltf JSON."""

from __future__ import annotations

import json
import struct

from .badfile import BadFile, decode_text

_GLB_JSON_CHUNK = 0x4E4F534A


def check_glb(data: bytes) -> bytes:
    """Check the GLB header and that every chunk fits inside the file."""
    if len(data) < 12:
        raise BadFile(f"truncated GLB: {len(data)} bytes, less than its 12-byte header")
    magic, version, length = struct.unpack_from("<4sII", data)
    if magic != b"glTF":
        raise BadFile("is not a GLB file (it does not start with 'glTF'); is it corrupt?")
    if version != 2:
        raise BadFile(f"GLB version {version} is not supported (only glTF 2)")
    if length > len(data):
        raise BadFile(
            f"truncated GLB: its header declares {length} bytes but the file has {len(data)}"
        )
    offset, chunk = 12, 0
    while offset < length:
        if offset + 8 > length:
            raise BadFile("truncated GLB: a chunk header is cut off")
        size, kind = struct.unpack_from("<II", data, offset)
        if offset + 8 + size > length:
            raise BadFile(f"truncated GLB: chunk {chunk} needs {size} bytes, fewer remain")
        if chunk == 0 and kind != _GLB_JSON_CHUNK:
            raise BadFile("is not a valid GLB file (its first chunk is not JSON)")
        offset, chunk = offset + 8 + size, chunk + 1
    if chunk == 0:
        raise BadFile("is not a valid GLB file (it has no JSON chunk)")
    return data


def check_gltf(data: bytes) -> bytes:
    """A .gltf must be a JSON object (trimesh would otherwise look for 'model.gltf')."""
    try:
        tree = json.loads(decode_text(data, "glTF"))
    except json.JSONDecodeError as exc:
        raise BadFile(f"is not valid glTF JSON ({exc})") from None
    if not isinstance(tree, dict):
        raise BadFile("is not a glTF file (its JSON is not an object)")
    return data
