"""The GLB container: one glTF 2.0 JSON document and one binary buffer in a single file.

Written deterministically (sorted JSON keys, fixed separators, every bufferView aligned to 4
bytes, the JSON chunk padded with spaces and the BIN chunk with zeros, as the glTF 2.0
specification's GLB section requires), so equal inputs give byte-identical files, and
atomically (`io.atomic.atomic_path`). Read with the .rk reader's discipline: the file's size
against a cap, then every length, chunk type and offset checked against the bytes that are
really there *before* anything of the claimed size is read or allocated; any problem is a
one-line `FormatError` naming the file.

`GlbBuilder` gathers typed arrays (bufferView + accessor) and PNG images (bufferView +
image) into the document's ``buffers`` / ``bufferViews`` / ``accessors`` / ``images``.
"""

from __future__ import annotations

import hashlib
import json
import os
import struct
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ...errors import FormatError
from ..atomic import atomic_path

__all__ = ["Glb", "GlbBuilder", "glb_bytes", "write_glb", "read_glb", "accessor_array",
           "image_bytes", "DEFAULT_MAX_BYTES", "MAX_JSON_BYTES", "ARRAY_BUFFER",
           "ELEMENT_ARRAY_BUFFER"]

MAGIC = b"glTF"
VERSION = 2
CHUNK_JSON = 0x4E4F534A
CHUNK_BIN = 0x004E4942
DEFAULT_MAX_BYTES = 4 << 30  # as the .rk reader's
MAX_JSON_BYTES = 64 << 20
ALIGN = 4
ARRAY_BUFFER = 34962  # a bufferView's target for vertex attributes
ELEMENT_ARRAY_BUFFER = 34963  # ... and for indices

_HEADER = struct.Struct("<4sII")  # magic, version, total length
_CHUNK = struct.Struct("<II")     # chunk length, chunk type

#: componentType -> numpy dtype (little-endian), as glTF 2.0 defines them.
COMPONENT_TYPES = {5120: np.dtype("i1"), 5121: np.dtype("u1"), 5122: np.dtype("<i2"),
                   5123: np.dtype("<u2"), 5125: np.dtype("<u4"), 5126: np.dtype("<f4")}
_COMPONENT_OF = {dtype: code for code, dtype in COMPONENT_TYPES.items()}
#: accessor type -> number of components.
TYPES = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}
_TYPE_OF_WIDTH = {1: "SCALAR", 2: "VEC2", 3: "VEC3", 4: "VEC4", 16: "MAT4"}
_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def _padded(data: bytes, fill: bytes) -> bytes:
    return data + fill * (-len(data) % ALIGN)


# ------------------------------------------------------------------------------ writing


@dataclass
class GlbBuilder:
    """A glTF document and its binary buffer, grown one bufferView at a time.

    ``document`` is the JSON object (``asset`` and whatever the caller adds); `add_array` and
    `add_png` append to its ``bufferViews``, ``accessors`` and ``images`` and return the new
    index; `finish` / `glb` complete it (``buffers[0]``).
    """

    document: dict = field(default_factory=lambda: {"asset": {"version": "2.0"}})
    _binary: bytearray = field(default_factory=bytearray)
    #: None: images live in the binary buffer (a .glb); a prefix: each image is a file of its
    #: own named ``{prefix}{k}.png`` beside the document (a .gltf), kept in `files`.
    image_files: str | None = None
    files: dict = field(default_factory=dict)    # uri -> bytes, when image_files is set
    _views: dict = field(default_factory=dict)   # (sha256, stride) -> bufferView
    _images: dict = field(default_factory=dict)  # bufferView or uri -> image

    def add_view(self, data: bytes, *, target: int | None = None,
                 stride: int | None = None) -> int:
        """Append ``data`` as a bufferView starting on a 4-byte boundary; its index. Bytes
        already added without a target, with the same stride, are not stored twice: their view's
        index is returned (an export's draw plans share most arrays with its arrays)."""
        # vertex and index data (a target) is never shared: glTF wants a byteStride on a
        # view two vertex accessors use
        key = None if target is not None else (hashlib.sha256(data).digest(), stride)
        if key in self._views:
            return self._views[key]
        self._binary.extend(b"\0" * (-len(self._binary) % ALIGN))
        view = {"buffer": 0, "byteOffset": len(self._binary), "byteLength": len(data)}
        if stride is not None:
            view["byteStride"] = stride
        if target is not None:
            view["target"] = target
        self._binary.extend(data)
        index = append_item(self.document, "bufferViews", view)
        if key is not None:
            self._views[key] = index
        return index

    def add_array(self, array, *, target: int | None = None, bounds: bool = False,
                  normalized: bool = False) -> int:
        """Append a 1D (SCALAR) or 2D (n, k) array as a bufferView and its accessor; the
        accessor's index. Rows are tightly packed, except vertex attributes (``target``
        ARRAY_BUFFER) whose rows are padded to 4 bytes, as glTF requires. ``bounds`` writes
        ``min``/``max`` per component (glTF requires them on POSITION)."""
        array = np.asarray(array)
        dtype = array.dtype.newbyteorder("<") if array.dtype.byteorder == ">" else array.dtype
        code = _COMPONENT_OF.get(dtype)
        if code is None:
            names = ", ".join(str(d) for d in COMPONENT_TYPES.values())
            raise FormatError(f"glTF accessors hold {names}; got {array.dtype}")
        width = 1 if array.ndim == 1 else array.shape[1] if array.ndim == 2 else 0
        kind = _TYPE_OF_WIDTH.get(width)
        if kind is None:
            raise FormatError(f"a glTF accessor takes an (n,) or (n, 1|2|3|4|16) array; "
                              f"got shape {array.shape}")
        data, stride = _vertex_rows(np.ascontiguousarray(array, dtype=dtype), target)
        view = self.add_view(data, target=target, stride=stride)
        accessor = {"bufferView": view, "componentType": code,
                    "count": int(array.shape[0]), "type": kind}
        if normalized:
            accessor["normalized"] = True
        if bounds and array.shape[0]:
            flat = array.reshape(array.shape[0], -1)
            accessor["min"] = [_number(v) for v in flat.min(axis=0)]
            accessor["max"] = [_number(v) for v in flat.max(axis=0)]
        return append_item(self.document, "accessors", accessor)

    def add_png(self, png: bytes) -> int:
        """Append encoded PNG bytes as a bufferView and an image; the image's index (the
        same image's for the same bytes)."""
        if not png.startswith(_PNG_SIGNATURE):
            raise FormatError("add_png takes encoded PNG bytes (no PNG signature found)")
        if self.image_files is None:
            key = self.add_view(png)
            image = {"bufferView": key, "mimeType": "image/png"}
        else:
            key = hashlib.sha256(png).hexdigest()
            if key not in self._images:
                uri = f"{self.image_files}{len(self.files)}.png"
                self.files[uri] = png
                image = {"uri": uri, "mimeType": "image/png"}
        if key not in self._images:
            self._images[key] = append_item(self.document, "images", image)
        return self._images[key]

    def finish(self) -> tuple[dict, bytes]:
        """The document (with ``buffers[0]`` when there is data) and the binary buffer, for
        `glb_bytes` or `write_glb`."""
        document = dict(self.document)
        if self._binary:
            document["buffers"] = [{"byteLength": len(self._binary)}]
        return document, bytes(self._binary)

    def glb(self) -> bytes:
        """The finished file's bytes."""
        return glb_bytes(*self.finish())


def _vertex_rows(array: np.ndarray, target: int | None) -> tuple[bytes, int | None]:
    """The array's bytes, and the byteStride its bufferView needs: vertex attribute rows
    (``ARRAY_BUFFER``) of a size not a multiple of 4 are padded with zeros to one."""
    row = array.itemsize * (array.shape[1] if array.ndim == 2 else 1)
    if target != ARRAY_BUFFER or row % ALIGN == 0:
        return array.tobytes(), None
    stride = row + (-row % ALIGN)
    padded = np.zeros((len(array), stride), np.uint8)
    padded[:, :row] = np.frombuffer(array.tobytes(), np.uint8).reshape(len(array), row)
    return padded.tobytes(), stride


def append_item(document: dict, key: str, item: dict) -> int:
    items = document.setdefault(key, [])
    items.append(item)
    return len(items) - 1


def _number(value) -> int | float:
    return int(value) if np.issubdtype(type(value), np.integer) else float(value)


def glb_bytes(document: dict, binary: bytes = b"") -> bytes:
    """A GLB file: header, JSON chunk (sorted keys, padded with spaces), and a BIN chunk
    (padded with zeros) when ``binary`` is not empty."""
    try:
        text = json.dumps(document, sort_keys=True, separators=(",", ":"), allow_nan=False,
                          ensure_ascii=False)
    except ValueError as exc:  # NaN or Inf: not JSON
        raise FormatError(f"the glTF document cannot be written as JSON: {exc}") from None
    text = text.encode("utf-8")
    total = _HEADER.size + _CHUNK.size + len(text) + 3 + (
        _CHUNK.size + len(binary) + 3 if binary else 0)
    if total >= 1 << 32:  # the header's length field is 32 bits
        raise FormatError(f"a GLB holds less than 4 GiB; this one would be {total:,} bytes")
    chunks = [(CHUNK_JSON, _padded(text, b" "))]
    if binary:
        chunks.append((CHUNK_BIN, _padded(bytes(binary), b"\0")))
    total = _HEADER.size + sum(_CHUNK.size + len(data) for _, data in chunks)
    out = [_HEADER.pack(MAGIC, VERSION, total)]
    for kind, data in chunks:
        out += [_CHUNK.pack(len(data), kind), data]
    return b"".join(out)


def write_glb(path, document: dict, binary: bytes = b"") -> Path:
    """Write `glb_bytes` to ``path`` atomically; the path."""
    data = glb_bytes(document, binary)
    with atomic_path(path) as tmp:
        Path(tmp).write_bytes(data)
    return Path(path)


# ------------------------------------------------------------------------------ reading


@dataclass(frozen=True)
class Glb:
    """A validated GLB: its JSON document and its BIN chunk (``b""`` when it has none)."""

    document: dict
    binary: bytes
    files: dict = field(default_factory=dict)  # a .gltf's image files: uri -> bytes


def read_glb(path, *, max_bytes: int = DEFAULT_MAX_BYTES) -> Glb:
    """Read and validate a GLB file: header, chunks, and every buffer, bufferView, accessor
    and image range, each against the bytes present before anything is read at its size.
    Raises a one-line `FormatError` naming ``path``."""
    path = Path(path)
    if not path.is_file():
        raise FormatError(f"{path}: {'is not a file' if path.exists() else 'no such file'}")
    try:
        with open(path, "rb") as fh:
            return _read(fh, os.fstat(fh.fileno()).st_size, max_bytes)
    except FormatError as exc:
        raise FormatError(f"{path}: {exc}") from None
    except OSError as exc:
        raise FormatError(f"{path}: cannot read ({exc.strerror or exc}); check the path and "
                          "its permissions") from None


def _read(fh, size: int, max_bytes: int) -> Glb:
    if size > max_bytes:
        raise FormatError(f"the file is {size:,} bytes, over the {max_bytes:,}-byte limit; "
                          "pass a larger max_bytes if you trust it")
    head = fh.read(_HEADER.size)
    if len(head) < _HEADER.size or head[:4] != MAGIC:
        raise FormatError("not a GLB file (no 'glTF' magic); export it again with reliefkit")
    _, version, total = _HEADER.unpack(head)
    if version != VERSION:
        raise FormatError(f"GLB version {version}; only glTF 2.0 (GLB version 2) is read")
    if total != size:
        raise FormatError(f"the header says {total:,} bytes but the file has {size:,} "
                          "(truncated or forged)")
    length, kind = _chunk_header(fh, _HEADER.size, size)
    if kind != CHUNK_JSON:
        raise FormatError(f"the first chunk is of type 0x{kind:08x}, not JSON")
    if length > MAX_JSON_BYTES:
        raise FormatError(f"the JSON chunk claims {length:,} bytes, over the "
                          f"{MAX_JSON_BYTES:,}-byte limit")
    document = parse_document(fh.read(length))
    binary, bin_offset = b"", _HEADER.size + _CHUNK.size + length
    offset = bin_offset
    while offset < size:
        length, kind = _chunk_header(fh, offset, size)
        if kind == CHUNK_BIN and offset == bin_offset:
            binary = fh.read(length)
        elif kind in (CHUNK_JSON, CHUNK_BIN):
            raise FormatError(f"a second {'JSON' if kind == CHUNK_JSON else 'BIN'} chunk, or "
                              "a BIN chunk not right after the JSON one")
        else:  # chunks of unknown types are skipped, as the specification asks
            fh.seek(length, os.SEEK_CUR)
        offset += _CHUNK.size + length
    check_layout(document, len(binary))
    return Glb(document, binary)


def _chunk_header(fh, offset: int, size: int) -> tuple[int, int]:
    if size - offset < _CHUNK.size:
        raise FormatError(f"a chunk header at byte {offset} is cut off (truncated)")
    length, kind = _CHUNK.unpack(fh.read(_CHUNK.size))
    if length % ALIGN:
        raise FormatError(f"the chunk at byte {offset} is {length} bytes, not a multiple of 4")
    if length > size - offset - _CHUNK.size:
        raise FormatError(f"the chunk at byte {offset} claims {length:,} bytes; only "
                          f"{size - offset - _CHUNK.size:,} follow (truncated or forged)")
    return length, kind


def parse_document(data: bytes, what: str = "the JSON chunk") -> dict:
    """A glTF 2.0 JSON document from its bytes (``what`` names them in errors)."""
    try:
        document = json.loads(data.decode("utf-8"))
    except (UnicodeDecodeError, ValueError) as exc:
        raise FormatError(f"{what} is not valid UTF-8 JSON ({exc})") from None
    except RecursionError:
        raise FormatError(f"{what} nests too deeply to be a glTF document (forged)") from None
    if not isinstance(document, dict) or not isinstance(document.get("asset"), dict):
        raise FormatError(f"{what} is not a glTF document (no 'asset' object)")
    if document["asset"].get("version") != "2.0":
        raise FormatError(f"glTF version {document['asset'].get('version')!r}; only '2.0' "
                          "is read")
    return document


def _items(document: dict, key: str) -> list[dict]:
    items = document.get(key, [])
    if not isinstance(items, list) or not all(isinstance(i, dict) for i in items):
        raise FormatError(f"'{key}' is not a list of objects")
    return items


def _int(item: dict, key: str, where: str, *, default: int | None = None) -> int:
    value = item.get(key, default)
    if type(value) is not int or value < 0:
        raise FormatError(f"{where}: '{key}' is {value!r}, not an integer >= 0")
    return value


def _index(item: dict, key: str, where: str, count: int, what: str) -> int:
    value = _int(item, key, where)
    if value >= count:
        raise FormatError(f"{where}: '{key}' {value} names no {what} (there are {count})")
    return value


def check_layout(document: dict, bin_length: int, *, files=(), external_buffer=False) -> None:
    """Every buffer, bufferView, accessor and image range lies inside the binary buffer (a
    GLB's BIN chunk, or with ``external_buffer`` a .gltf's one .bin file, already read), and
    every image file is one of ``files``."""
    buffers = _items(document, "buffers")
    lengths = []
    for k, buffer in enumerate(buffers):
        where = f"buffers[{k}]"
        if "uri" in buffer and not external_buffer:
            raise FormatError(f"{where} refers to an external file ({buffer['uri']!r}); "
                              "only the GLB's own BIN chunk is read")
        length = _int(buffer, "byteLength", where)
        if k:
            raise FormatError(f"{len(buffers)} buffers; reliefkit reads one (a GLB's BIN "
                              "chunk or a .gltf's .bin file)")
        if not bin_length - 3 <= length <= bin_length:
            raise FormatError(f"{where} claims {length:,} bytes; the BIN chunk holds "
                              f"{bin_length:,} (truncated or forged)")
        lengths.append(length)
    views = _items(document, "bufferViews")
    for k, view in enumerate(views):
        where = f"bufferViews[{k}]"
        buffer = _index(view, "buffer", where, len(lengths), "buffer")
        end = _int(view, "byteOffset", where, default=0) + _int(view, "byteLength", where)
        if end > lengths[buffer]:
            raise FormatError(f"{where} ends at byte {end:,}, past its buffer's "
                              f"{lengths[buffer]:,} (truncated or forged)")
    for k, accessor in enumerate(_items(document, "accessors")):
        _check_accessor(accessor, f"accessors[{k}]", views)
    for k, image in enumerate(_items(document, "images")):
        if "bufferView" in image:
            _index(image, "bufferView", f"images[{k}]", len(views), "bufferView")
        elif image.get("uri") not in files:
            raise FormatError(f"images[{k}] refers to a file ({image.get('uri')!r}) this "
                              "reader did not read; only its own image files are read")


def _check_accessor(accessor: dict, where: str, views: list[dict]) -> None:
    code, kind = accessor.get("componentType"), accessor.get("type")
    if code not in COMPONENT_TYPES or kind not in TYPES:
        raise FormatError(f"{where}: componentType {code!r} / type {kind!r} is not glTF's")
    count = _int(accessor, "count", where)
    if "sparse" in accessor:
        raise FormatError(f"{where}: sparse accessors are not read")
    if "bufferView" not in accessor:
        return
    view = views[_index(accessor, "bufferView", where, len(views), "bufferView")]
    element = COMPONENT_TYPES[code].itemsize * TYPES[kind]
    stride = _int(view, "byteStride", where, default=element) or element
    if stride < element:
        raise FormatError(f"{where}: its bufferView's byteStride {stride} is less than an "
                          f"element's {element} bytes")
    end = _int(accessor, "byteOffset", where, default=0) + (
        (count - 1) * stride + element if count else 0)
    if end > view["byteLength"]:
        raise FormatError(f"{where}: {count:,} elements end at byte {end:,}, past its "
                          f"bufferView's {view['byteLength']:,} (truncated or forged)")


def accessor_array(glb: Glb, index: int) -> np.ndarray:
    """Accessor ``index`` of a validated `Glb` as a numpy array of its own (shape (count,)
    for SCALAR, else (count, components))."""
    accessor = glb.document["accessors"][index]
    dtype = COMPONENT_TYPES[accessor["componentType"]]
    width, count = TYPES[accessor["type"]], accessor["count"]
    shape = (count,) if accessor["type"] == "SCALAR" else (count, width)
    if "bufferView" not in accessor:
        return np.zeros(shape, dtype)
    view = glb.document["bufferViews"][accessor["bufferView"]]
    start = view.get("byteOffset", 0) + accessor.get("byteOffset", 0)
    stride = view.get("byteStride") or dtype.itemsize * width
    rows = np.ndarray((count, width), dtype, buffer=glb.binary, offset=start,
                      strides=(stride, dtype.itemsize)) if count else np.zeros((0, width), dtype)
    return rows.reshape(shape).copy()


def image_bytes(glb: Glb, index: int) -> bytes:
    """The encoded bytes of image ``index`` of a validated `Glb` (held in a bufferView, or
    a .gltf's file)."""
    image = glb.document["images"][index]
    if "uri" in image:
        return glb.files[image["uri"]]
    view = glb.document["bufferViews"][image["bufferView"]]
    start = view.get("byteOffset", 0)
    return glb.binary[start:start + view["byteLength"]]
