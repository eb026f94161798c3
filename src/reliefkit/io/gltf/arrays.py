"""Typed arrays in a glTF document: what accessors cannot hold, as reliefkit's extensions
store it.

A *typed array reference* is a JSON object ``{"dtype": NAME, "shape": [...], "sha256": HEX}``
plus where the values are: ``"bufferView": i`` (the C-order little-endian bytes, exactly
``prod(shape) * itemsize`` of them), ``"image": i`` (a PNG image holding a uint8 array:
(H, W) grey, (..., H, W, C) with C of 1 to 4 channels, leading dimensions stacked down the
rows) or neither for an empty array. ``sha256`` is the hash of the array's bytes. Reading
checks the dtype, the shape against what the caller allows, the view's length or the PNG's
header against the shape, all before anything of that size is allocated, then the hash.
"""

from __future__ import annotations

import hashlib
import io
import math
import re
import struct

import numpy as np
from PIL import Image

from ...errors import FormatError
from .glb import Glb, GlbBuilder, image_bytes

__all__ = ["DTYPES", "put_array", "array_of", "declared", "png_of"]

#: The dtypes a reference may name (little-endian where it matters).
DTYPES = ("bool", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64", "uint64",
          "float16", "float32", "float64")
_SHA = re.compile(r"[0-9a-f]{64}\Z")
_PNG_MODES = {1: "L", 2: "LA", 3: "RGB", 4: "RGBA"}
_PNG_COLOR_TYPES = {0: 1, 4: 2, 2: 3, 6: 4}  # IHDR colour type -> channels
_IHDR = struct.Struct(">8sI4sIIBBBBB")


def _sha(array: np.ndarray) -> str:
    return hashlib.sha256(np.ascontiguousarray(array).tobytes()).hexdigest()


def png_of(array: np.ndarray) -> bytes | None:
    """``array`` (uint8) as lossless PNG bytes, or None when no PNG layout holds it."""
    if array.dtype != np.uint8 or array.size == 0 or array.ndim < 2:
        return None
    if array.ndim == 2:
        rows = array
    elif array.shape[-1] in _PNG_MODES:
        rows = array.reshape(-1, array.shape[-2], array.shape[-1])
        rows = rows[..., 0] if array.shape[-1] == 1 else rows
    else:
        return None
    if rows.shape[0] >= 1 << 31 or rows.shape[1] >= 1 << 31:
        return None
    out = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(rows), _PNG_MODES[1 if rows.ndim == 2 else
                                                            rows.shape[-1]]).save(
        out, format="PNG", compress_level=6)
    return out.getvalue()


def put_array(builder: GlbBuilder, array: np.ndarray, *, png: bool = False) -> dict:
    """A reference to ``array`` stored in ``builder``: as a PNG image when ``png`` and a PNG
    holds it exactly, else as a bufferView of its bytes."""
    array = np.ascontiguousarray(array)
    array = array.astype(array.dtype.newbyteorder("<"), copy=False)
    if array.dtype.name not in DTYPES:
        raise FormatError(f"a glTF typed array cannot hold dtype {array.dtype}")
    ref = {"dtype": array.dtype.name, "shape": list(array.shape), "sha256": _sha(array)}
    encoded = png_of(array) if png else None
    if encoded is not None:
        ref["image"] = builder.add_png(encoded)
    elif array.size:
        ref["bufferView"] = builder.add_view(array.tobytes())
    return ref


def declared(ref, where: str) -> tuple[np.dtype, tuple[int, ...]]:
    """The dtype and shape a reference declares, checked for form only."""
    ok = (isinstance(ref, dict) and ref.get("dtype") in DTYPES
          and isinstance(ref.get("shape"), list)
          and all(type(d) is int and 0 <= d < 1 << 40 for d in ref["shape"])
          and len(ref["shape"]) <= 8
          and isinstance(ref.get("sha256"), str) and _SHA.match(ref["sha256"])
          and not ("bufferView" in ref and "image" in ref))
    if not ok:
        raise FormatError(f"{where} needs dtype (one of {', '.join(DTYPES)}), shape (at most "
                          "8 non-negative ints), sha256 and at most one of bufferView / image")
    return np.dtype(ref["dtype"]).newbyteorder("<"), tuple(ref["shape"])


def array_of(glb: Glb, ref: dict, where: str) -> np.ndarray:
    """The array a reference names, read after checking that its storage holds exactly the
    declared shape (call `declared` and check the shape first: nothing is allocated here
    that the stored bytes do not already hold)."""
    dtype, shape = declared(ref, where)
    count = math.prod(shape)
    if "image" in ref:
        array = _from_png(glb, ref["image"], dtype, shape, where)
    elif "bufferView" in ref:
        views = glb.document.get("bufferViews", [])
        index = ref["bufferView"]
        if type(index) is not int or not 0 <= index < len(views):
            raise FormatError(f"{where}: bufferView {index!r} names no bufferView")
        view = views[index]
        if view.get("byteLength") != count * dtype.itemsize or count == 0:
            raise FormatError(f"{where}: {ref['dtype']} {tuple(shape)} is "
                              f"{count * dtype.itemsize:,} bytes, its bufferView holds "
                              f"{view.get('byteLength'):,} (truncated or forged)")
        if view.get("buffer") != 0 or "byteStride" in view:
            raise FormatError(f"{where}: its bufferView must be tightly packed in buffer 0")
        start = view.get("byteOffset", 0)
        array = np.frombuffer(glb.binary, dtype, count, start).reshape(shape).copy()
    elif count:
        raise FormatError(f"{where}: {tuple(shape)} holds {count:,} values but names no "
                          "bufferView or image")
    else:
        array = np.zeros(shape, dtype)
    if _sha(array) != ref["sha256"]:
        raise FormatError(f"{where}: its bytes do not match its sha256 (corrupt or forged)")
    return array


def _from_png(glb: Glb, index, dtype: np.dtype, shape: tuple, where: str) -> np.ndarray:
    images = glb.document.get("images", [])
    if type(index) is not int or not 0 <= index < len(images):
        raise FormatError(f"{where}: image {index!r} names no image")
    data = image_bytes(glb, index)
    channels = 1 if len(shape) == 2 else shape[-1]
    rows = shape[0] if len(shape) == 2 else math.prod(shape[:-2])  # leading dims stacked
    width = shape[-1] if len(shape) == 2 else shape[-2]
    if dtype != np.uint8 or len(shape) < 2 or channels not in _PNG_MODES:
        raise FormatError(f"{where}: a PNG holds uint8 (H, W) or (..., H, W, 1-4) arrays, "
                          f"not {dtype.name} {shape}")
    if len(data) < _IHDR.size:
        raise FormatError(f"{where}: image {index} is not a PNG")
    sig, _, chunk, w, h, depth, color, _, _, _ = _IHDR.unpack_from(data)
    if sig != b"\x89PNG\r\n\x1a\n" or chunk != b"IHDR":
        raise FormatError(f"{where}: image {index} is not a PNG")
    if (w, h, depth, _PNG_COLOR_TYPES.get(color)) != (width, rows, 8, channels):
        raise FormatError(f"{where}: image {index} is {w}x{h}, {depth}-bit colour type "
                          f"{color}; {shape} uint8 needs {width}x{rows}, 8-bit, {channels} "
                          "channels (forged)")
    try:
        with Image.open(io.BytesIO(data)) as image:
            pixels = np.asarray(image)
    except (OSError, ValueError, Image.DecompressionBombError) as exc:
        raise FormatError(f"{where}: image {index} cannot be decoded ({exc})") from None
    if pixels.size != math.prod(shape) or pixels.dtype != np.uint8:
        raise FormatError(f"{where}: image {index} decodes to {pixels.shape} {pixels.dtype}, "
                          f"not {shape} uint8 (forged)")
    return pixels.reshape(shape).copy()
