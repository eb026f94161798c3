"""One image in 4x4 blocks: BC1 (RGB, 4 bits a texel), BC4 (one channel, 4), BC5 (two
channels, 8) and BC7 (RGBA, 8), encoded with etcpak and decoded on the CPU with
texture2ddecoder (etcpak's own decoders crash: never call them).

Images are uint8 unorm (H, W, C) with C the format's channels (BC1 reads RGB, its alpha is
1); sizes that are not multiples of 4 are padded by repeating the last row and column, and
the padding is cut off again when decoding. texture2ddecoder returns BGRA: reordered here.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import UsageError


@dataclass(frozen=True)
class BlockFormat:
    """A block-compressed format: its channels and the bytes of one 4x4 block."""

    name: str
    channels: int
    block_bytes: int

    @property
    def bits_per_texel(self) -> int:
        return self.block_bytes * 8 // 16


FORMATS = {f.name: f for f in (BlockFormat("bc1", 3, 8), BlockFormat("bc4", 1, 8),
                                BlockFormat("bc5", 2, 16), BlockFormat("bc7", 4, 16))}


def block_format(name: str) -> BlockFormat:
    if name not in FORMATS:
        raise UsageError(f"unknown block format {name!r} (known: {', '.join(FORMATS)})")
    return FORMATS[name]


def level_bytes(name: str, height: int, width: int) -> int:
    """Bytes of one H x W image in ``name``'s blocks (the padded size)."""
    return -(-height // 4) * -(-width // 4) * FORMATS[name].block_bytes


def _padded_rgba(image: np.ndarray) -> np.ndarray:
    """(H, W, C) uint8 -> (H4, W4, 4) uint8: edge-padded to multiples of 4, missing channels
    0 (alpha 255)."""
    height, width, channels = image.shape
    pad = ((0, -height % 4), (0, -width % 4), (0, 0))
    padded = np.pad(image, pad, mode="edge")
    out = np.zeros((*padded.shape[:2], 4), np.uint8)
    out[..., 3] = 255
    out[..., :channels] = padded
    return out


def encode(name: str, image: np.ndarray) -> bytes:
    """The blocks of an (H, W, C) uint8 image, C = the format's channels."""
    import etcpak  # a C extension, loaded only when something is encoded

    fmt = block_format(name)
    image = np.asarray(image)
    if image.dtype != np.uint8 or image.ndim != 3 or image.shape[2] != fmt.channels:
        raise UsageError(f"{name} encodes (H, W, {fmt.channels}) uint8 images, got "
                         f"{image.shape} {image.dtype}")
    rgba = _padded_rgba(image)
    data = getattr(etcpak, f"compress_{name}")(rgba.tobytes(), rgba.shape[1], rgba.shape[0])
    assert len(data) == level_bytes(name, *image.shape[:2])
    return data


def decode(name: str, data: bytes, height: int, width: int) -> np.ndarray:
    """The (H, W, C) uint8 image of ``data`` (exactly `level_bytes` long)."""
    import texture2ddecoder  # a C extension, loaded only when something is decoded

    fmt = block_format(name)
    if len(data) != level_bytes(name, height, width):
        raise UsageError(f"{name}: {len(data)} bytes do not hold a {width}x{height} image")
    h4, w4 = -(-height // 4) * 4, -(-width // 4) * 4
    bgra = getattr(texture2ddecoder, f"decode_{name}")(bytes(data), w4, h4)
    image = np.frombuffer(bgra, np.uint8).reshape(h4, w4, 4)[:height, :width]
    return np.ascontiguousarray(image[..., [2, 1, 0, 3][:fmt.channels]])
