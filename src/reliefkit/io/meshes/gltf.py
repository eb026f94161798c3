"""The structural checks of glTF files: the GLB container, the JSON, the version, extensions."""

from __future__ import annotations

import json
import struct

from .badfile import BadFile, decode_text

_GLB_JSON_CHUNK = 0x4E4F534A

_DRACO = "KHR_draco_mesh_compression"
# required extensions the loader reads (Draco needs DracoPy), or that only change shading
# this renderer does not do (the other KHR_materials_*), so the base colour stays right
_READABLE = {_DRACO, "EXT_texture_webp", "KHR_materials_pbrSpecularGlossiness",
             "KHR_texture_transform"}  # the last one read by .texture_transform
_HARMLESS_PREFIX = "KHR_materials_"
_GLTF1 = "glTF 1.0 is not supported (only glTF 2.0); convert the file to glTF 2.0"


def check_glb(data: bytes) -> bytes:
    """Check the GLB header, that every chunk fits inside the file, and its JSON."""
    if len(data) < 12:
        raise BadFile(f"truncated GLB: {len(data)} bytes, less than its 12-byte header")
    magic, version, length = struct.unpack_from("<4sII", data)
    if magic != b"glTF":
        raise BadFile("is not a GLB file (it does not start with 'glTF'); is it corrupt?")
    if version == 1:
        raise BadFile(_GLTF1)
    if version != 2:
        raise BadFile(f"GLB version {version} is not supported (only glTF 2.0)")
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
    _check_tree(json_tree(data, "glb"))
    return data


def check_gltf(data: bytes) -> bytes:
    """A .gltf must be a glTF 2.0 JSON object (trimesh would otherwise look for 'model.gltf')."""
    _check_tree(json_tree(data, "gltf"))
    return data


def json_tree(data: bytes, file_type: str) -> dict:
    """The JSON object of a .gltf, or of a .glb's first chunk (its structure checked)."""
    if file_type == "glb":
        (size,) = struct.unpack_from("<I", data, 12)
        data = data[20 : 20 + size]
    try:
        tree = json.loads(decode_text(data, "glTF"))
    except json.JSONDecodeError as exc:
        raise BadFile(f"is not valid glTF JSON ({exc})") from None
    except RecursionError:
        raise BadFile("is not usable glTF JSON (it is nested too deeply); is it corrupt?") from None
    if not isinstance(tree, dict):
        raise BadFile("is not a glTF file (its JSON is not an object)")
    return tree


def _check_tree(tree: dict) -> None:
    """The version, the node hierarchy, and the extensions a reader must understand."""
    asset = tree.get("asset")
    version = str(asset.get("version", "")) if isinstance(asset, dict) else ""
    if version.startswith("1"):
        raise BadFile(_GLTF1)
    _check_nodes(tree.get("nodes"))
    required = tree.get("extensionsRequired", [])
    for name in required if isinstance(required, list) else []:
        if name == _DRACO and not _draco_decoder_installed():
            raise BadFile(
                f"is Draco-compressed ({_DRACO}) and the Draco decoder is not installed; "
                "pip install DracoPy"
            )
        if name not in _READABLE and not str(name).startswith(_HARMLESS_PREFIX):
            raise BadFile(f"requires the glTF extension {name}, which is not supported")


def _check_nodes(nodes) -> None:
    """Node children must be node indices, and the hierarchy must be a forest (no cycles)."""
    if not isinstance(nodes, list):
        return
    children = []
    for k, node in enumerate(nodes):
        kids = node.get("children", []) if isinstance(node, dict) else []
        if not isinstance(kids, list) or not all(
                isinstance(c, int) and not isinstance(c, bool) and 0 <= c < len(nodes)
                for c in kids):
            raise BadFile(f"glTF node {k} has children that are not node indices; is it corrupt?")
        children.append(kids)
    state = [0] * len(nodes)  # 0 unseen, 1 on the current path, 2 done
    for root in range(len(nodes)):
        if state[root]:
            continue
        stack = [(root, iter(children[root]))]
        state[root] = 1
        while stack:
            node, kids = stack[-1]
            child = next(kids, None)
            if child is None:
                state[node] = 2
                stack.pop()
            elif state[child] == 1:
                raise BadFile(
                    f"its glTF node hierarchy has a cycle (node {node} has ancestor {child} as "
                    "a child); is it corrupt?")
            elif state[child] == 0:
                state[child] = 1
                stack.append((child, iter(children[child])))


def _draco_decoder_installed() -> bool:
    try:
        import DracoPy  # noqa: F401 - trimesh imports it to decode Draco primitives
    except ImportError:
        return False
    return True
