"""The encoded form of one array: `EncodedImage`, what `.rk` files store, draw plans carry
and the executor uploads in place of the array.

An encoded array is an image (H, W[, C]) or a stack of layers (L, H, W[, C]) in one of
`FORMATS`: a block format of `blocks` (BC1/BC4/BC5/BC7) or ``u8``/``u16``, plain unorm
quantization. Either way the GPU samples unorm values q in [0, 1]; the array it stands for
holds ``q * scale + bias`` (float32), or q's own bytes where the array is uint8. Only level
0 is stored: the mip levels (``mipmaps``) are derived from the decoded level 0 the same way
on every load (`levels`), so the file stays one level while the GPU gets a whole chain.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..colorspace import srgb_decode, srgb_encode
from ..errors import UsageError
from . import blocks

QUANTIZED = {"u8": np.dtype(np.uint8), "u16": np.dtype("<u2")}
FORMATS = (*blocks.FORMATS, *QUANTIZED)
DECODED_DTYPES = ("uint8", "float32")


@dataclass(frozen=True, eq=False)
class EncodedImage:
    """An array's encoded level 0 (``data``: uint8 bytes, layer after layer) and how to read
    it; ``shape``/``dtype`` are the decoded array's, ``layered`` says whether its first axis
    is layers (a texture array). ``srgb``: colour channels are sRGB-encoded (mips average
    linear light). ``scale``/``bias``: the decode rule of float arrays."""

    format: str
    shape: tuple[int, ...]
    dtype: str
    data: np.ndarray
    layered: bool = False
    srgb: bool = False
    mipmaps: bool = False
    scale: float = 1.0
    bias: float = 0.0

    def __post_init__(self):
        check(self.format, self.shape, self.dtype, self.layered)
        expected = stored_bytes(self.format, self.shape, self.layered)
        if self.data.dtype != np.uint8 or self.data.ndim != 1 or self.data.size != expected:
            raise UsageError(f"{self.format} data of a {self.shape} array must be {expected} "
                             f"bytes, got {self.data.size}")

    @property
    def layers(self) -> int:
        return self.shape[0] if self.layered else 1

    @property
    def size(self) -> tuple[int, int]:
        """(H, W) of level 0."""
        first = 1 if self.layered else 0
        return self.shape[first], self.shape[first + 1]

    @property
    def channels(self) -> int:
        return channels_of(self.shape, self.layered)

    @cached_property
    def levels(self) -> tuple[np.ndarray, ...]:
        """Every level's bytes as the GPU takes them: level 0, then (``mipmaps``) the chain
        down to 1 x 1, each encoded from the half-size average of the decoded level 0."""
        if not self.mipmaps:
            return (self.data,)
        out = [self.data]
        source = _to_linear(self._unorm(0, self.data), self.srgb)
        while max(source.shape[1:3]) > 1:
            source = _half(source)
            out.append(_encode_unorm(_from_linear(source, self.format, self.srgb), self.format))
        return tuple(out)

    @property
    def nbytes(self) -> int:
        """Bytes a GPU holds for it (every level uploaded)."""
        return sum(level.size for level in self.levels)

    def _unorm(self, level: int, data: np.ndarray | None = None) -> np.ndarray:
        """Level ``level`` (its bytes ``data``, by default `levels`') as (L, h, w, C) unorm
        integers (uint8 or uint16)."""
        height, width = (max(n >> level, 1) for n in self.size)
        data = self.levels[level] if data is None else data
        per_layer = data.size // self.layers
        return np.stack([_decode_unorm(self.format, data[k * per_layer:(k + 1) * per_layer],
                                       height, width, self.channels)
                         for k in range(self.layers)])

    def decode(self, level: int = 0) -> np.ndarray:
        """The array level ``level`` stands for (level 0: the array itself)."""
        q = self._unorm(level)
        if self.dtype == "uint8":
            values = q.astype(np.uint8)
        elif self.srgb:  # float linear colour stored sRGB-encoded: decoded as the GL does
            values = _to_linear(q, True).astype(np.float32)
        else:
            top = np.float32(np.iinfo(q.dtype).max)
            values = (q.astype(np.float32) / top * np.float32(self.scale)
                      + np.float32(self.bias)).astype(np.float32)
        shape = values.shape[:3] + ((values.shape[3],) if len(self.shape) > 2 + self.layered
                                    else ())
        return values.reshape(shape)[0 if not self.layered else slice(None)]


def channels_of(shape: tuple[int, ...], layered: bool) -> int:
    return shape[-1] if len(shape) == 3 + layered else 1


def check(fmt: str, shape, dtype: str, layered: bool) -> None:
    """Refuse an encoding that cannot stand for a ``shape`` ``dtype`` array."""
    if fmt not in FORMATS:
        raise UsageError(f"unknown encoding {fmt!r} (known: {', '.join(FORMATS)})")
    if dtype not in DECODED_DTYPES:
        raise UsageError(f"encoded arrays decode to {' or '.join(DECODED_DTYPES)}, not {dtype}")
    ndim = 2 + layered
    if len(shape) not in (ndim, ndim + 1) or any(type(n) is not int or n < 1 for n in shape):
        raise UsageError(f"an encoded {'layered ' if layered else ''}image needs shape "
                         f"({'L, ' if layered else ''}H, W[, C]), got {tuple(shape)}")
    channels = channels_of(tuple(shape), layered)
    allowed = {"bc1": (3, 4), "bc4": (1,), "bc5": (2,), "bc7": (3, 4)}.get(fmt, (1, 2, 3, 4))
    if channels not in allowed:
        raise UsageError(f"{fmt} holds {' or '.join(map(str, allowed))} channels, not {channels}")
    if dtype == "uint8" and fmt == "u16":
        raise UsageError("u16 cannot stand for a uint8 array")


def stored_bytes(fmt: str, shape, layered: bool) -> int:
    """Bytes of level 0 of a ``shape`` array in ``fmt`` (what a file stores)."""
    layers = shape[0] if layered else 1
    height, width = shape[layered:layered + 2]
    if fmt in QUANTIZED:
        return layers * height * width * channels_of(tuple(shape), layered) * \
            QUANTIZED[fmt].itemsize
    return layers * blocks.level_bytes(fmt, height, width)


def _decode_unorm(fmt: str, data: np.ndarray, height: int, width: int,
                  channels: int) -> np.ndarray:
    if fmt in QUANTIZED:
        return data.view(QUANTIZED[fmt]).reshape(height, width, channels)
    image = blocks.decode(fmt, data.tobytes(), height, width)
    if image.shape[2] < channels:  # BC1 standing for RGBA: its alpha is 1
        image = np.concatenate([image, np.full((height, width, 1), 255, np.uint8)], axis=2)
    return image[..., :channels]


def _encode_unorm(q: np.ndarray, fmt: str) -> np.ndarray:
    """(L, H, W, C) unorm integers -> level bytes, layer after layer."""
    if fmt in QUANTIZED:
        return np.ascontiguousarray(q, dtype=QUANTIZED[fmt]).reshape(-1).view(np.uint8)
    need = blocks.FORMATS[fmt].channels
    out = []
    for layer in q:
        image = layer[..., :need]
        if image.shape[2] < need:
            image = np.concatenate([image, np.zeros((*image.shape[:2], need - image.shape[2]),
                                                    np.uint8)], axis=2)
        out.append(np.frombuffer(blocks.encode(fmt, np.ascontiguousarray(image)), np.uint8))
    return np.concatenate(out)


def _to_linear(q: np.ndarray, srgb: bool) -> np.ndarray:
    """Unorm integers -> [0, 1] floats, sRGB colour channels decoded to linear light."""
    values = q.astype(np.float64) / np.iinfo(q.dtype).max
    if srgb:
        values[..., :3] = srgb_decode(values[..., :3])
    return values


def _from_linear(values: np.ndarray, fmt: str, srgb: bool) -> np.ndarray:
    """`_to_linear`'s inverse, rounded to ``fmt``'s unorm integers."""
    values = values.copy()
    if srgb:
        values[..., :3] = srgb_encode(values[..., :3])
    top = np.iinfo(QUANTIZED.get(fmt, np.dtype(np.uint8))).max
    return np.round(np.clip(values, 0.0, 1.0) * top).astype(QUANTIZED.get(fmt, np.uint8))


def _half(values: np.ndarray) -> np.ndarray:
    """(L, H, W, C) -> the next mip level: each texel the mean of its 2x2 footprint (the last
    row or column repeated where a side is odd; 1 stays 1)."""
    height, width = values.shape[1:3]
    rows = np.minimum(np.arange(max(height // 2, 1))[:, None] * 2 + np.arange(2), height - 1)
    cols = np.minimum(np.arange(max(width // 2, 1))[:, None] * 2 + np.arange(2), width - 1)
    picked = values[:, rows][:, :, :, cols]  # (L, h, 2, w, 2, C)
    return picked.mean(axis=(2, 4))


def encode(array: np.ndarray, fmt: str, *, layered: bool = False, srgb: bool = False,
           mipmaps: bool = False, scale: float = 1.0, bias: float = 0.0,
           keep_nonzero: bool = False) -> EncodedImage:
    """``array`` (uint8 unorm, or float32 mapped to unorm by ``(a - bias) / scale``; float32
    ``srgb`` colour: linear, sRGB-encoded) encoded in ``fmt``. ``keep_nonzero``: values
    above ``bias`` never quantize to 0 (a height of 0 means empty). Refuses BC1 for an alpha
    that is not 1 everywhere."""
    array = np.asarray(array)
    dtype = str(array.dtype)
    check(fmt, tuple(int(n) for n in array.shape), dtype, layered)
    q_dtype = QUANTIZED.get(fmt, np.dtype(np.uint8))
    if dtype == "uint8":
        q = array
    elif srgb:
        q = _from_linear(array.astype(np.float64), fmt, True)
    else:
        top = np.iinfo(q_dtype).max
        unit = np.clip((array.astype(np.float64) - bias) / scale, 0.0, 1.0)
        q = np.round(unit * top).astype(q_dtype)
        if keep_nonzero:
            q = np.where((q == 0) & (array > bias), q_dtype.type(1), q)
    stack = q if layered else q[None]
    if stack.ndim == 3:
        stack = stack[..., None]
    if fmt == "bc1" and stack.shape[3] == 4 and (stack[..., 3] != 255).any():
        raise UsageError("bc1 keeps no alpha and this colour has some: use bc7")
    return EncodedImage(fmt, tuple(int(n) for n in array.shape), dtype, _encode_unorm(stack, fmt),
                        layered=layered, srgb=srgb, mipmaps=mipmaps, scale=float(scale),
                        bias=float(bias))


def texture_bytes(array: np.ndarray, *, layered: bool = False, mipmaps: bool = False) -> int:
    """Bytes a GPU holds for ``array`` uploaded as it is: (L,) H, W[, C] texels, plus the
    levels of a mip chain."""
    array = np.asarray(array)
    height, width = array.shape[layered:layered + 2]
    per_texel = array.nbytes // (height * width)
    total, level = 0, 0
    while True:
        h, w = max(height >> level, 1), max(width >> level, 1)
        total += h * w * per_texel
        if not mipmaps or (h, w) == (1, 1):
            return int(total)
        level += 1


# -- which array an encoding stands for ------------------------------------------------------

_BY_ARRAY: dict[int, tuple[weakref.ref, EncodedImage]] = {}


def decoded(encoded: EncodedImage) -> np.ndarray:
    """The array ``encoded`` stands for, read-only and tied to it: `encoding_of` finds the
    encoding again from the array alone, so a representation's codec and drawables pass it
    on (`io.rk` stores it, `render.plan.Texture` uploads it) without holding it anywhere."""
    array = encoded.decode()
    array.flags.writeable = False
    key = id(array)
    _BY_ARRAY[key] = (weakref.ref(array, lambda _: _BY_ARRAY.pop(key, None)), encoded)
    return array


def encoding_of(array) -> EncodedImage | None:
    """The encoding that `decoded` made ``array`` from, or None (a raw array, or one made
    from it by any operation: a copy is not the decoded array)."""
    entry = _BY_ARRAY.get(id(array))
    return entry[1] if entry is not None and entry[0]() is array else None
