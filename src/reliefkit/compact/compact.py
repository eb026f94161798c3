"""`compress(representation)`: the same representation with its colour, normals and heights
encoded as a GPU holds them, and its arrays the decoded values, so that CPU references,
metrics and the drawn frames all see what the GPU samples.

Which arrays are encoded is declared where the arrays are: the role of their codec's
`ArraySpec` (``color``, ``normal``, ``height``); every other array stays exact. Arrays
derived from encoded ones (a relief's safety radii) are computed again from the decoded
values by the codec's ``rederive``. The decoded arrays carry their encoding
(`encodings.encoding_of`): `io.rk` stores the blocks and the drawables upload them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.params import make, param
from ..errors import UsageError
from ..io.rk import CodecTable, codec_of
from .encodings import EncodedImage, decoded, encode, encoding_of, texture_bytes

COLOR_FORMATS = ("bc7", "bc1")
NORMAL_FORMATS = ("bc7", "bc1")
HEIGHT_BITS = (16, 8, 32)


COMPRESS = ("none", "bc")


@dataclass(frozen=True)
class CompressOptions:
    """Whether `reliefkit.bake` compresses what it bakes (``bake --compress bc``) and how
    `compress` encodes each role (the flags after it)."""

    compress: str = param("none", "after baking: none, or bc (colour and normals block-"
                          "compressed, heights quantized, as a GPU holds them; "
                          "docs/compact.md)", choices=COMPRESS)
    color_format: str = param("bc7", "compressed colour: bc7 (8 bits a texel, keeps alpha) "
                              "or bc1 (4 bits, opaque colour only)", choices=COLOR_FORMATS)
    normal_format: str = param("bc7", "compressed normals: bc7 (8 bits a texel) or bc1 (4 "
                               "bits, coarser)", choices=NORMAL_FORMATS)
    height_bits: int = param(16, "compressed heights: unorm bits a texel (32: float32, "
                             "exact)", choices=HEIGHT_BITS)


def _layered(array: np.ndarray, role: str) -> bool:
    """Whether the array is a stack of layers: images are (H, W[, C]), colour and normals
    always have channels, heights never do."""
    return array.ndim == (4 if role in ("color", "normal") else 3)


def encode_role(array: np.ndarray, role: str, options: CompressOptions) -> EncodedImage | None:
    """``array`` encoded as its role says, or None where it stays as it is."""
    layered = _layered(array, role)
    if role == "color":
        fmt = options.color_format
        if fmt == "bc1" and array.shape[-1] == 4 and (array[..., 3] != 255).any():
            raise UsageError("--color-format bc1 keeps no alpha, and this representation's "
                             "colour has some (coverage): use bc7")
        return encode(array, fmt, layered=layered, srgb=True, mipmaps=True)
    if role == "normal":
        signed = array.dtype == np.float32
        return encode(array, options.normal_format, layered=layered, mipmaps=True,
                      scale=2.0 if signed else 1.0, bias=-1.0 if signed else 0.0)
    if options.height_bits == 32:
        return None
    return encode(array, f"u{options.height_bits}", layered=layered, keep_nonzero=True)


def compress(representation, options: CompressOptions | None = None, *,
             codecs: CodecTable | None = None):
    """A new representation whose role-bearing arrays hold their decoded values (each
    tied to its encoding), the others and the derived ones exact."""
    options = options or CompressOptions()
    codec = codec_of(representation, codecs=codecs)
    arrays, params = codec.to_arrays(representation)
    arrays = dict(arrays)
    changed = False
    for name, array in arrays.items():
        role = codec.arrays[name].role
        if array is None or role is None or encoding_of(array) is not None:
            continue
        encoded = encode_role(np.asarray(array), role, options)
        if encoded is not None:
            arrays[name] = decoded(encoded)
            changed = True
    if changed and codec.rederive is not None:
        arrays = codec.rederive(arrays, params)
    return codec.from_arrays(arrays, dict(params))


def bake_compression(options) -> CompressOptions:
    """`reliefkit.bake`'s ``compress`` argument checked before anything is baked: "none" or
    "bc", or its fields (a dict or `CompressOptions`); encoding choices without
    ``compress="bc"`` are refused."""
    if isinstance(options, str):
        options = {"compress": options}
    if not isinstance(options, CompressOptions):
        options = make(CompressOptions, dict(options or {}), "bake --compress")
    if options.compress == "none" and options != CompressOptions():
        raise UsageError("--color-format, --normal-format and --height-bits choose how "
                         "--compress bc encodes: add --compress bc")
    return options


def gpu_bytes(representation, *, codecs: CodecTable | None = None) -> dict[str, tuple]:
    """Per array: (format, bytes as a GPU holds it, bytes raw): the encoding and its levels,
    or "raw" and the array as it is (colour and normals with a mip chain either way)."""
    codec = codec_of(representation, codecs=codecs)
    arrays, _ = codec.to_arrays(representation)
    out = {}
    for name, array in arrays.items():
        if array is None:
            continue
        role, array = codec.arrays[name].role, np.asarray(array)
        raw = int(array.nbytes) if role is None else texture_bytes(
            array, layered=_layered(array, role), mipmaps=role in ("color", "normal"))
        encoded = encoding_of(arrays[name])
        out[name] = (encoded.format, encoded.nbytes, raw) if encoded is not None \
            else ("raw", raw, raw)
    return out
