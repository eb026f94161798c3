"""Image, mask, depth and position metrics between two frames.

Every function takes two frames, the *test* first and the *reference* second. A frame is any
object with the attributes of :class:`reliefkit.render.frame.Frame` that a metric reads:
``color`` (H,W,4 float32, linear, straight alpha), ``mask`` (H,W bool), ``depth`` (H,W float32
window depth) and ``position`` (H,W,3 float32 world position, NaN where ``mask`` is False).

Colour metrics compare what a viewer sees over black: linear RGB premultiplied by alpha (zero
where the pixel is not covered), clipped to [0, 1] and encoded with the exact sRGB transfer
function. They are evaluated over the *union* of the two masks, so a pixel that only one frame
covers counts as an error. Geometric metrics (position, depth) are evaluated where *both*
frames cover the pixel.
"""

from __future__ import annotations

import math

import numpy as np

from .colorspace import srgb_decode, srgb_encode  # noqa: F401  (re-exported)
from .errors import UsageError

__all__ = [
    "srgb_encode",
    "srgb_decode",
    "psnr",
    "ssim",
    "mask_iou",
    "mask_xor",
    "position_error",
    "depth_error",
    "compare",
    "error_image",
    "heat_ramp",
]

# Viridis sampled at 0, 1/4, 1/2, 3/4 and 1 (display values): perceptually ordered and
# readable in greyscale, without importing matplotlib.
_RAMP = np.array(
    [
        [0.267004, 0.004874, 0.329415],
        [0.229739, 0.322361, 0.545706],
        [0.127568, 0.566949, 0.550556],
        [0.369214, 0.788888, 0.382914],
        [0.993248, 0.906157, 0.143936],
    ]
)


# --------------------------------------------------------------------------- helpers


def _size(frame) -> tuple[int, int]:
    """Return (H, W) of a frame, from its mask."""
    mask = np.asarray(frame.mask)
    if mask.ndim != 2:
        raise UsageError(f"a frame's mask must be 2-D (H, W), got shape {mask.shape}")
    return mask.shape


def _check_pair(test, ref) -> tuple[int, int]:
    """Raise UsageError unless the two frames have the same size; return (H, W)."""
    (ht, wt), (hr, wr) = _size(test), _size(ref)
    if (ht, wt) != (hr, wr):
        raise UsageError(f"frames differ in size: {wt}x{ht} vs {wr}x{hr}")
    return ht, wt


def _array(frame, name: str, channels: int | None) -> np.ndarray:
    """Return ``frame.<name>`` as float64 after checking its shape against the mask."""
    arr = np.asarray(getattr(frame, name), dtype=np.float64)
    want = _size(frame) + ((channels,) if channels else ())
    if arr.shape != want:
        raise UsageError(f"a frame's {name} has shape {arr.shape}, expected {want} from its mask")
    return arr


def _display_rgb(frame) -> np.ndarray:
    """Premultiplied, [0,1]-clipped, sRGB-encoded RGB (H,W,3 float64); black where uncovered."""
    color = _array(frame, "color", 4)
    mask = np.asarray(frame.mask, dtype=bool)
    rgb = np.zeros(mask.shape + (3,))
    rgb[mask] = color[mask, :3] * color[mask, 3:4]
    return srgb_encode(rgb).astype(np.float64)


def _union(test, ref, mask=None) -> np.ndarray:
    """The pixels colour metrics evaluate: ``mask`` if given, else the union of the masks."""
    shape = _check_pair(test, ref)
    if mask is None:
        region = np.asarray(test.mask, dtype=bool) | np.asarray(ref.mask, dtype=bool)
    else:
        region = np.asarray(mask, dtype=bool)
        if region.shape != shape:
            raise UsageError(f"mask has shape {region.shape}, expected {shape}")
    if not region.any():
        raise UsageError("both frames are empty: no pixel is covered, nothing to compare")
    return region


def _common(test, ref) -> np.ndarray:
    """Pixels covered by both frames."""
    _check_pair(test, ref)
    return np.asarray(test.mask, dtype=bool) & np.asarray(ref.mask, dtype=bool)


def _stats(err: np.ndarray) -> dict:
    """Summary statistics of a 1-D error array (all NaN and count 0 when empty)."""
    if err.size == 0:
        nan = float("nan")
        return {"mean": nan, "rms": nan, "max": nan, "p95": nan, "median": nan, "count": 0}
    return {
        "mean": float(err.mean()),
        "rms": float(np.sqrt(np.mean(err * err))),
        "max": float(err.max()),
        "p95": float(np.percentile(err, 95.0)),
        "median": float(np.median(err)),
        "count": int(err.size),
    }


def _position_distance(test, ref, common: np.ndarray) -> np.ndarray:
    """Euclidean world distance at the common pixels (1-D)."""
    pt = _array(test, "position", 3)[common]
    pr = _array(ref, "position", 3)[common]
    return np.sqrt(np.sum((pt - pr) ** 2, axis=-1))


def _win_size(h: int, w: int) -> int:
    """SSIM window: 7, or the largest odd size that fits the smaller side."""
    side = min(h, w)
    if side < 3:
        raise UsageError(f"SSIM needs frames of at least 3x3 pixels, got {w}x{h}")
    return min(7, side if side % 2 else side - 1)


# --------------------------------------------------------------------------- colour


def psnr(test, ref, *, mask=None) -> float:
    """Peak signal-to-noise ratio (dB) of the displayed colours, peak 1.

    Parameters
    ----------
    test, ref : Frame-like
        Frames of the same size.
    mask : array_like of bool, optional
        (H,W) pixels to evaluate; defaults to the union of the two frames' masks.

    Returns
    -------
    float
        ``10 * log10(1 / MSE)`` over the region's RGB values; ``inf`` when identical.

    Raises
    ------
    UsageError
        Sizes differ, or the region is empty.
    """
    region = _union(test, ref, mask)
    diff = _display_rgb(test)[region] - _display_rgb(ref)[region]
    mse = float(np.mean(diff * diff))
    return math.inf if mse == 0.0 else 10.0 * math.log10(1.0 / mse)


def ssim(test, ref) -> float:
    """Mean structural similarity of the displayed colours over the union of the masks.

    The SSIM map of scikit-image (uniform 7x7 window, smaller for tiny frames) is averaged
    over the colour channels and then over the pixels either frame covers.

    Parameters
    ----------
    test, ref : Frame-like
        Frames of the same size, at least 3x3.

    Returns
    -------
    float
        1.0 for identical frames, lower for different ones.

    Raises
    ------
    UsageError
        Sizes differ, a frame is smaller than 3x3, or both frames are empty.
    """
    from skimage.metrics import structural_similarity  # heavy import, only when needed

    region = _union(test, ref)
    win = _win_size(*region.shape)
    _, smap = structural_similarity(
        _display_rgb(test),
        _display_rgb(ref),
        win_size=win,
        channel_axis=-1,
        data_range=1.0,
        full=True,
    )
    return float(np.mean(smap, axis=-1)[region].mean())


# --------------------------------------------------------------------------- masks


def mask_iou(test, ref) -> float:
    """Intersection over union of the two masks.

    Raises
    ------
    UsageError
        Sizes differ, or both masks are empty.
    """
    union = _union(test, ref)
    return float(np.count_nonzero(_common(test, ref)) / np.count_nonzero(union))


def mask_xor(test, ref) -> int:
    """Number of pixels covered by exactly one of the two frames."""
    _check_pair(test, ref)
    return int(np.count_nonzero(np.asarray(test.mask, bool) ^ np.asarray(ref.mask, bool)))


# --------------------------------------------------------------------------- geometry


def position_error(test, ref) -> dict:
    """Euclidean world-space position error where both frames cover the pixel.

    Returns
    -------
    dict
        ``mean``, ``rms``, ``max``, ``p95``, ``median`` (floats, world units) and ``count``
        (int, common pixels); the floats are NaN when no pixel is common.
    """
    common = _common(test, ref)
    return _stats(_position_distance(test, ref, common))


def depth_error(test, ref) -> dict:
    """Absolute window-depth difference where both frames cover the pixel.

    Returns
    -------
    dict
        Same keys as :func:`position_error`.
    """
    common = _common(test, ref)
    dt = _array(test, "depth", None)[common]
    dr = _array(ref, "depth", None)[common]
    return _stats(np.abs(dt - dr))


# --------------------------------------------------------------------------- summary


def compare(test, ref, *, scene_size=None) -> dict:
    """All metrics in one flat dict of Python floats and ints (for JSON reports).

    Parameters
    ----------
    test, ref : Frame-like
        Frames of the same size.
    scene_size : float, optional
        Scene scale, e.g. the bounding-sphere radius; when given, ``position_*_rel`` keys
        hold the position errors divided by it.

    Returns
    -------
    dict
        ``psnr``, ``ssim``, ``iou``, ``xor``, ``xor_fraction`` (of the union),
        ``common_pixels``, ``position_mean``/``_rms``/``_max``/``_p95``, ``depth_mean``,
        ``depth_max`` and, with ``scene_size``, ``position_mean_rel`` etc. ``psnr`` may be
        ``inf`` and geometric values NaN (``json.dumps`` writes ``Infinity``/``NaN``).

    Raises
    ------
    UsageError
        Sizes differ, both frames are empty, or ``scene_size`` is not a positive number.
    """
    if scene_size is not None and not (math.isfinite(scene_size) and scene_size > 0):
        raise UsageError(f"scene_size must be a positive finite number, got {scene_size!r}")
    xor = mask_xor(test, ref)
    union = int(np.count_nonzero(_union(test, ref)))
    pos, dep = position_error(test, ref), depth_error(test, ref)
    out = {
        "psnr": psnr(test, ref),
        "ssim": ssim(test, ref),
        "iou": mask_iou(test, ref),
        "xor": xor,
        "xor_fraction": xor / union,
        "common_pixels": pos["count"],
        "depth_mean": dep["mean"],
        "depth_max": dep["max"],
    }
    for key in ("mean", "rms", "max", "p95"):
        out[f"position_{key}"] = pos[key]
        if scene_size is not None:
            out[f"position_{key}_rel"] = pos[key] / float(scene_size)
    return out


# --------------------------------------------------------------------------- pictures


def heat_ramp(values) -> np.ndarray:
    """Map values in [0, 1] (clipped) to a viridis-like colour ramp.

    Returns
    -------
    numpy.ndarray
        float32 display (sRGB-encoded) colours, shape ``values.shape + (3,)``.
    """
    t = np.clip(np.asarray(values, dtype=np.float64), 0.0, 1.0) * (len(_RAMP) - 1)
    i = np.minimum(t.astype(np.int64), len(_RAMP) - 2)
    f = (t - i)[..., None]
    return ((1.0 - f) * _RAMP[i] + f * _RAMP[i + 1]).astype(np.float32)


def heat_ramp_stops() -> np.ndarray:
    """The colours `heat_ramp` interpolates between, at 0, 1/(n-1), ..., 1: (n, 3) float32
    (what the viewer's shaders get, so the ramp has one source)."""
    return _RAMP.astype(np.float32)


def _check_scale(scale) -> float:
    if not (math.isfinite(scale) and scale > 0):
        raise UsageError(f"scale must be a positive finite number, got {scale!r}")
    return float(scale)


def error_image(test, ref, kind: str = "color", *, scale=None) -> np.ndarray:
    """A picture of where and how much two frames differ.

    Parameters
    ----------
    test, ref : Frame-like
        Frames of the same size.
    kind : {"color", "position", "mask"}
        ``"color"``: largest per-channel absolute difference of the displayed colours,
        divided by ``scale`` (default 1), on a heat ramp; black outside the union of masks.
        ``"position"``: world distance divided by ``scale`` (default: the largest distance)
        on a heat ramp; black where the frames do not both cover the pixel.
        ``"mask"``: green where both cover the pixel, red only test, blue only reference,
        black neither.
    scale : float, optional
        Error that maps to the top of the ramp.

    Returns
    -------
    numpy.ndarray
        (H,W,3) float32 display colours in [0, 1].
    """
    h, w = _check_pair(test, ref)
    mt, mr = np.asarray(test.mask, bool), np.asarray(ref.mask, bool)
    out = np.zeros((h, w, 3), np.float32)
    if kind == "mask":
        out[mt & mr, 1] = 1.0
        out[mt & ~mr, 0] = 1.0
        out[~mt & mr, 2] = 1.0
    elif kind == "color":
        s = 1.0 if scale is None else _check_scale(scale)
        diff = np.abs(_display_rgb(test) - _display_rgb(ref)).max(axis=-1)
        union = mt | mr
        out[union] = heat_ramp(diff[union] / s)
    elif kind == "position":
        common = mt & mr
        dist = _position_distance(test, ref, common)
        if scale is not None:
            s = _check_scale(scale)
        else:
            s = float(dist.max()) if dist.size and dist.max() > 0 else 1.0
        out[common] = heat_ramp(dist / s)
    else:
        raise UsageError(f"unknown error image kind {kind!r}: use 'color', 'position' or 'mask'")
    return out
