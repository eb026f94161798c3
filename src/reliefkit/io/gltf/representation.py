"""A baked representation inside a glTF file: reliefkit's ``RELIEFKIT_<kind>`` extension.

The extension sits on a node (``nodes[i].extensions.RELIEFKIT_relief_object``, the kind's
``-`` and ``.`` written ``_``) and holds what an .rk file holds, so `load` rebuilds the
representation bit for bit: ``kind``, ``kindVersion``, ``params`` (the kind's JSON
parameters) and ``arrays`` (name -> typed array reference, `io.gltf.arrays`: colour as PNG
images, everything else as bufferViews; an array stored block-compressed is its blocks plus
an ``encoding`` record, as in .rk). `reliefkit.export` adds what a renderer needs (the draw
plans, optionally shaders) and a core glTF fallback mesh. Reading validates everything the
.rk reader does, with the same checks, before any array is allocated: the kind and its
version, the array set, each declared dtype and shape against the kind's spec, the arrays'
shapes against each other, the total against ``max_bytes``, each reference's storage
against its shape; then the hashes and finiteness. docs/gltf.md is the specification.
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...errors import FormatError
from .. import rk
from .arrays import array_of, declared, put_array
from .files import read_gltf
from .glb import DEFAULT_MAX_BYTES, MAGIC, MAX_JSON_BYTES, Glb, GlbBuilder, read_glb

__all__ = ["PREFIX", "extension_name", "representation_extension", "is_gltf", "read_document",
           "exported_by_reliefkit", "stored_cache_key",
           "reliefkit_nodes", "GltfRepresentation", "read_representation", "load",
           "read_manifest"]

PREFIX = "RELIEFKIT_"


def extension_name(kind: str) -> str:
    """The extension of ``kind``: ``RELIEFKIT_`` and the kind with ``-`` and ``.`` as ``_``."""
    return PREFIX + re.sub(r"[^A-Za-z0-9_]", "_", kind)


def representation_extension(builder: GlbBuilder, codec: rk.Codec, arrays: dict,
                             params: dict) -> dict:
    """The extension object of a representation's checked arrays and params (`rk.prepare`)."""
    refs = {}
    for name in sorted(arrays):
        stored, encoding = rk.stored_form(arrays[name])
        png = encoding is None and codec.arrays[name].role == "color"
        refs[name] = put_array(builder, stored, png=png)
        if encoding is not None:
            refs[name]["encoding"] = encoding
    return {"kind": codec.kind, "kindVersion": codec.version, "params": params, "arrays": refs}


# --------------------------------------------------------------------------- reading


def is_gltf(path) -> bool:
    """Whether ``path`` is a glTF file: a ``.gltf`` name or GLB's magic bytes."""
    path = Path(path)
    if path.suffix.lower() == ".gltf":
        return True
    try:
        with open(path, "rb") as fh:
            return fh.read(4) == MAGIC
    except OSError:
        return False


def exported_by_reliefkit(path) -> bool:
    """Whether a glTF file declares one of reliefkit's extensions (its JSON alone is read;
    a file that cannot be read says False, and the mesh loader then says why)."""
    used = (_document_json(path) or {}).get("extensionsUsed", [])
    return isinstance(used, list) and any(isinstance(u, str) and u.startswith(PREFIX)
                                          for u in used)


def stored_cache_key(path) -> str | None:
    """The cache key (`reliefkit.batch.key`) in the extras of a reliefkit export's first
    representation, from its JSON alone (cheap for any file size); None when it has none or
    cannot be read (a batch then exports it again)."""
    document = _document_json(path)
    if document is None:
        return None
    try:
        found = reliefkit_nodes(document)
        key = document["nodes"][found[0][0]]["extras"]["reliefkit"]["cacheKey"] if found else None
    except (KeyError, TypeError):
        return None
    return key if isinstance(key, str) else None


def _document_json(path) -> dict | None:
    """The JSON of a .glb or .gltf file, without its binary chunk; None when it cannot be
    read as one."""
    path = Path(path)
    try:
        with open(path, "rb") as fh:
            head = fh.read(20)
            if head[:4] == MAGIC and len(head) == 20:
                length = int.from_bytes(head[12:16], "little")
                text = fh.read(min(length, MAX_JSON_BYTES))
            elif path.suffix.lower() == ".gltf":
                text = head + fh.read(MAX_JSON_BYTES)
            else:
                return None
        document = json.loads(text.decode("utf-8"))
    except (OSError, ValueError, RecursionError):
        return None
    return document if isinstance(document, dict) else None


def read_document(path, *, max_bytes: int = DEFAULT_MAX_BYTES) -> Glb:
    """A validated .glb or .gltf (its JSON, binary buffer and image files)."""
    path = Path(path)
    if path.suffix.lower() == ".gltf":
        return read_gltf(path, max_bytes=max_bytes)
    return read_glb(path, max_bytes=max_bytes)


def reliefkit_nodes(document: dict) -> list[tuple[int, str, dict]]:
    """(node index, extension name, extension object) of every node that carries one of
    reliefkit's extensions, in node order."""
    found = []
    nodes = document.get("nodes", [])
    for k, node in enumerate(nodes if isinstance(nodes, list) else []):
        extensions = node.get("extensions") if isinstance(node, dict) else None
        if not isinstance(extensions, dict):
            continue
        for name, ext in sorted(extensions.items()):
            if name.startswith(PREFIX):
                found.append((k, name, ext))
    return found


@dataclass(frozen=True)
class GltfRepresentation:
    """One representation read from a glTF file: its node, kind, params and arrays (as
    the representation holds them), and its extension object as written."""

    node: int
    kind: str
    params: dict
    arrays: dict
    extension: dict


def read_representation(glb: Glb, node: int, extension: dict, *,
                        max_bytes: int = DEFAULT_MAX_BYTES,
                        codecs: rk.CodecTable | None = None) -> GltfRepresentation:
    """Validate and read the representation of one node's extension (see the module)."""
    where = f"nodes[{node}]"
    if not isinstance(extension, dict) or not isinstance(extension.get("params"), dict) \
            or not isinstance(extension.get("arrays"), dict):
        raise FormatError(f"{where}: reliefkit's extension needs kind, kindVersion, params "
                          "and arrays objects")
    codec = rk.codec_table(codecs).for_kind(extension.get("kind"))
    version = extension.get("kindVersion")
    if type(version) is not int or not 1 <= version <= codec.version:
        raise FormatError(f"{where}: {codec.kind} version {version!r}; this reliefkit reads "
                          f"1 to {codec.version} (upgrade reliefkit for newer files)")
    refs = extension["arrays"]
    shapes = {}
    for name, ref in refs.items():
        dtype, shape = declared(ref, f"{where}: array {name!r}")
        encoding = ref.get("encoding")
        shapes[name] = (dtype, shape, encoding)
    try:
        rk.check_stored(codec, refs, shapes)
    except FormatError as exc:
        raise FormatError(f"{where}: {exc}") from None
    total = sum(math.prod(s if e is None else e["shape"])
                * np.dtype(d if e is None else e["dtype"]).itemsize
                for d, s, e in shapes.values())
    if total > max_bytes:
        raise FormatError(f"{where}: arrays declare {total / 2**30:.2f} GiB, over the "
                          f"{max_bytes / 2**30:.2f} GiB limit; pass a larger max_bytes if you "
                          "trust this file")
    arrays = {name: rk.decoded_array(array_of(glb, ref, f"{where}: array {name!r}"),
                                     ref.get("encoding"))
              for name, ref in refs.items()}
    try:
        rk.check_finite_arrays(codec, arrays)
    except FormatError as exc:
        raise FormatError(f"{where}: {exc}") from None
    return GltfRepresentation(node, codec.kind, extension["params"], arrays, extension)


def load(path, *, node: int | None = None, max_bytes: int = DEFAULT_MAX_BYTES,
         codecs: rk.CodecTable | None = None):
    """The representation a glTF file that reliefkit exported holds: the first node with
    reliefkit's extension (an LOD chain's first), or node ``node``. A glTF file without one
    is refused with a line that says what to do instead."""
    path = Path(path)
    glb = read_document(path, max_bytes=max_bytes)
    found = reliefkit_nodes(glb.document)
    if node is not None:
        found = [f for f in found if f[0] == node]
    if not found:
        what = f"node {node} carries" if node is not None else "no node carries"
        raise FormatError(f"{path}: {what} a reliefkit extension (RELIEFKIT_<kind>); this is "
                          "not a file reliefkit exported (load a plain glTF mesh with "
                          "load_mesh, or bake it)")
    index, _, extension = found[0]
    try:
        rep = read_representation(glb, index, extension, max_bytes=max_bytes, codecs=codecs)
    except FormatError as exc:
        raise FormatError(f"{path}: {exc}") from None
    codec = rk.codec_table(codecs).for_kind(rep.kind)
    return rk.build(codec, rep.arrays, rep.params, path)


def read_manifest(path) -> dict:
    """What `io.rk.read_manifest` says of an .rk, for a glTF file reliefkit exported: its
    first representation's kind, versions, params, source hash, writer and arrays (dtype,
    shape and sha256 as stored; an encoded array's encoding), from the JSON alone; with
    several (an LOD chain) also every representation's kind, in node order."""
    path = Path(path)
    glb = read_document(path)
    found = reliefkit_nodes(glb.document)
    if not found:
        raise FormatError(f"{path}: no node carries a reliefkit extension (RELIEFKIT_<kind>)")
    index, name, extension = found[0]
    node = glb.document["nodes"][index]
    extras = node.get("extras", {}).get("reliefkit", {}) if isinstance(node.get("extras"),
                                                                         dict) else {}
    arrays = {key: {k: ref[k] for k in ("dtype", "shape", "sha256", "encoding") if k in ref}
              for key, ref in extension.get("arrays", {}).items() if isinstance(ref, dict)}
    others = {"representations": [e.get("kind") for _, _, e in found]} if len(found) > 1 else {}
    return {"format": "glTF 2.0", **others, "extension": name, "kind": extension.get("kind"),
            "kind_version": extension.get("kindVersion"), "params": extension.get("params"),
            "source_hash": extras.get("sourceHash"),
            **({"cache_key": extras["cacheKey"]} if "cacheKey" in extras else {}),
            "created_by": glb.document["asset"].get("generator"), "arrays": arrays}
