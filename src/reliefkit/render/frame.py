"""`Frame`: what every renderer returns, a colour image plus its AOVs and camera matrices."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..colorspace import to_rgba8
from ..errors import UsageError
from ..fileio import atomic_path

AOV_NAMES = ("color", "mask", "depth", "position", "normal", "view", "proj", "viewport")


@dataclass(eq=False)
class Frame:
    """A rendered image with its arbitrary output variables; row 0 is the top row.

    color : (H, W, 4) float32 linear RGB with straight alpha.
    mask : (H, W) bool, the representation covers the pixel.
    depth : (H, W) float32 window depth in [0, 1] (1 where nothing was drawn).
    position : (H, W, 3) float32 world-space hit point, NaN where ``mask`` is False.
    normal : (H, W, 3) float32 world-space unit normal, 0 where ``mask`` is False.
    view, proj : 4x4 float64 camera matrices; viewport : (x, y, w, h) int32.
    stats : renderer-specific counters (iterations per pixel, fragments, ...).
    """

    color: np.ndarray
    mask: np.ndarray
    depth: np.ndarray
    position: np.ndarray
    normal: np.ndarray
    view: np.ndarray
    proj: np.ndarray
    viewport: np.ndarray
    stats: dict = field(default_factory=dict)
    extra: dict = field(default_factory=dict)

    @property
    def size(self) -> tuple[int, int]:
        """(width, height)."""
        return self.mask.shape[1], self.mask.shape[0]

    def rgba8(self, background=None) -> np.ndarray:
        """sRGB uint8 image; with ``background`` (linear RGB) composited and opaque."""
        color = self.color
        if background is not None:
            bg = np.asarray(background, dtype=np.float32)[:3]
            alpha = color[..., 3:4]
            color = np.concatenate([color[..., :3] * alpha + bg * (1 - alpha),
                                    np.ones_like(alpha)], axis=-1)
        return to_rgba8(color)

    def save(self, path, background=None) -> None:
        """Write the colour image as a PNG (transparent where nothing was drawn)."""
        from PIL import Image

        image = Image.fromarray(self.rgba8(background), "RGBA")
        with atomic_path(path) as tmp:
            image.save(tmp, format="PNG")

    def aovs(self) -> dict[str, np.ndarray]:
        """Every AOV under the names of DESIGN.md."""
        return {name: np.asarray(getattr(self, name)) for name in AOV_NAMES}

    def save_aovs(self, path) -> None:
        """Write every AOV and matrix to an .npz (plain arrays, loadable without pickle)."""
        if not str(path).endswith(".npz"):
            raise UsageError(f"AOV file must end in .npz, got {path}")
        with atomic_path(path) as tmp, open(tmp, "wb") as handle:
            np.savez(handle, **self.aovs())


def frame_from_targets(camera, color, position, normal, depth, stats=None) -> Frame:
    """Assemble a Frame from read-back targets (RGBA float arrays, row 0 on top).

    ``position``'s alpha channel is the coverage written by the shader (1 where drawn).
    """
    mask = position[..., 3] > 0.5
    pos = np.where(mask[..., None], position[..., :3], np.nan).astype(np.float32)
    nrm = np.where(mask[..., None], normal[..., :3], 0.0).astype(np.float32)
    col = np.where(mask[..., None], color, 0.0).astype(np.float32)
    return Frame(color=col, mask=mask, depth=depth.astype(np.float32), position=pos, normal=nrm,
                 view=camera.view, proj=camera.proj, viewport=camera.viewport,
                 stats=dict(stats or {}))


def window_depth(position: np.ndarray, view: np.ndarray, proj: np.ndarray,
                 fallback: np.ndarray) -> np.ndarray:
    """Window depth of world positions (H, W, 3); ``fallback`` where position is NaN."""
    valid = np.isfinite(position).all(axis=-1)
    p = np.where(valid[..., None], position, 0.0).astype(np.float64)
    clip = np.concatenate([p, np.ones(p.shape[:-1] + (1,))], axis=-1) @ (proj @ view).T
    with np.errstate(divide="ignore", invalid="ignore"):
        depth = 0.5 * clip[..., 2] / clip[..., 3] + 0.5
    return np.where(valid, depth, fallback).astype(np.float32)
