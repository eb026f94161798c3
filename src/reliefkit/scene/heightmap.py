"""Heightmap files for terrain-like inputs: 8/16-bit greyscale PNG or a 2D .npy array."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import FormatError
from ..io.npy import npy_header

HEIGHTMAP_SUFFIXES = (".png", ".npy")
MAX_SIDE = 8192


def is_heightmap(path) -> bool:
    return Path(str(path)).suffix.lower() in HEIGHTMAP_SUFFIXES


def check_file(path) -> Path:
    """``path``, refused unless it is a regular file: a folder, a FIFO (which would block the
    read) or a device is a one-line `FormatError`."""
    path = Path(path)
    if not path.is_file():
        raise FormatError(f"{path}: {'is not a file' if path.exists() else 'no such file'}")
    return path


def load_heightmap(path) -> np.ndarray:
    """(H, W) float64 heights; row 0 is the image's top row, which a relief bake puts at the
    far edge (-z) seen from above (`relief_from_heights`)."""
    path = check_file(path)
    heights = _load_npy(path) if path.suffix.lower() == ".npy" else _load_png(path)
    if heights.ndim != 2 or min(heights.shape) < 4 or max(heights.shape) > MAX_SIDE:
        raise FormatError(f"{path}: a heightmap must be 2D, between 4 and {MAX_SIDE} texels "
                          f"per side; got shape {heights.shape}")
    if not np.isfinite(heights).all():
        raise FormatError(f"{path}: the heightmap contains NaN or Inf values")
    return heights


def _load_npy(path: Path) -> np.ndarray:
    try:
        with open(path, "rb") as fh:
            shape, _, dtype = npy_header(fh)
            if dtype.hasobject or dtype.kind not in "biuf":
                raise FormatError(f"{path}: heightmap must be a numeric array, got {dtype}")
            if len(shape) != 2 or max(shape, default=0) > MAX_SIDE:
                raise FormatError(f"{path}: a heightmap must be 2D and at most {MAX_SIDE} "
                                  f"per side; got shape {shape}")
        return np.load(path, allow_pickle=False).astype(np.float64)
    except FormatError:
        raise
    except Exception as exc:
        raise FormatError(f"{path}: not a readable .npy array ({exc})") from None


def _load_png(path: Path) -> np.ndarray:
    from PIL import Image, UnidentifiedImageError

    try:
        with Image.open(path) as image:
            if max(image.size) > MAX_SIDE:
                raise FormatError(f"{path}: heightmap larger than {MAX_SIDE} per side")
            if image.mode in ("I;16", "I;16B", "I;16L", "I"):
                return np.asarray(image, dtype=np.float64) / 65535.0
            return np.asarray(image.convert("L"), dtype=np.float64) / 255.0
    except FormatError:
        raise
    except (UnidentifiedImageError, OSError, ValueError) as exc:
        raise FormatError(f"{path}: not a readable PNG image ({exc})") from None
