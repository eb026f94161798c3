"""`Frame`: what every renderer returns, a colour image plus its AOVs and camera matrices."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..colorspace import to_rgba8
from ..core.transforms import transform_points
from ..errors import UsageError
from ..io.atomic import atomic_path

AOV_NAMES = ("color", "mask", "depth", "position", "normal", "view", "proj", "viewport")


@dataclass(eq=False)
class Frame:
    """A rendered image with its arbitrary output variables; row 0 is the top row.

    color : (H, W, 4) float32 linear RGB with straight alpha.
    mask : (H, W) bool, the representation covers the pixel.
    depth : (H, W) float32 window depth in [0, 1] (1 where nothing was drawn).
    position : (H, W, 3) float64 world-space hit point, NaN where ``mask`` is False (float64:
        the file's own coordinates, exact also for meshes far from the world origin).
    normal : (H, W, 3) float32 world-space unit normal, 0 where ``mask`` is False.
    view, proj : 4x4 float64 camera matrices; viewport : (x, y, w, h) int32.
    stats : counters: ``covered`` pixels always; ``fragments`` and ``iterations_*`` where
        the render was instrumented (``count_iterations=True``); technique-specific ones.
    extra : arrays that are no AOV (``iterations``: per-pixel loop counts, NaN where no
        fragment ran).
    warnings : human-readable lines a drawable wants the user to see about this picture (a
        known inexactness and its remedy); the CLI prints each as ``warning: ...``.
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
    warnings: list = field(default_factory=list)

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
        """Every AOV and matrix, keyed by its attribute name (`AOV_NAMES`)."""
        return {name: np.asarray(getattr(self, name)) for name in AOV_NAMES}

    def save_aovs(self, path) -> None:
        """Write every AOV and matrix to a compressed .npz (plain arrays, deflated; loadable
        with ``numpy.load(path, allow_pickle=False)``), atomically."""
        if not str(path).endswith(".npz"):
            raise UsageError(f"AOV file must end in .npz, got {path}")
        with atomic_path(path) as tmp, open(tmp, "wb") as handle:
            np.savez_compressed(handle, **self.aovs())


def frame_from_passes(camera, images) -> Frame:
    """Assemble a Frame from read-back pass images (`reliefkit.gl.targets.PassImages`).

    Opaque pixels keep their colour and AOVs; where the transparent pass drew, its
    premultiplied colour lies over the opaque one, and the AOVs belong to the point where the
    accumulated opacity first reached 0.5 (the transparent gate, else the opaque surface
    behind, else NaN). Colour is returned straight (not premultiplied). Shaders write
    positions relative to ``camera.origin`` (`gl.uniforms.camera_uniforms`); the Frame's are
    world coordinates in float64.
    """
    covered = images.position[..., 3] > 0.5
    color = np.where(covered[..., None], images.color, 0.0)
    origin = np.asarray(camera.origin, dtype=np.float64)
    pos = np.where(covered[..., None], images.position[..., :3] + origin, np.nan)
    nrm = np.where(covered[..., None], images.normal[..., :3], 0.0)
    depth = np.where(covered, images.depth, 1.0)  # counted misses leave depth below 1
    mask = covered
    if images.transparent is not None:
        t_color, t_pos, t_nrm = images.transparent
        t_alpha = t_color[..., 3:4]
        o_alpha = color[..., 3:4]
        alpha = t_alpha + (1.0 - t_alpha) * o_alpha
        rgb = t_color[..., :3] + (1.0 - t_alpha) * color[..., :3] * o_alpha
        with np.errstate(divide="ignore", invalid="ignore"):
            straight = np.where(alpha > 0, rgb / np.where(alpha > 0, alpha, 1.0), 0.0)
        color = np.concatenate([straight, alpha], axis=-1)
        gate = t_pos[..., 3] > 0.5
        pos = np.where(gate[..., None], t_pos[..., :3] + origin, pos)
        nrm = np.where(gate[..., None], t_nrm[..., :3], nrm)
        depth = np.where(gate, window_depth(pos, camera.view, camera.proj, depth), depth)
        mask = covered | (t_alpha[..., 0] > 0)
        pos = np.where((covered | gate)[..., None], pos, np.nan)
    return Frame(color=color.astype(np.float32), mask=mask, depth=depth.astype(np.float32),
                 position=pos, normal=nrm.astype(np.float32),
                 view=camera.view, proj=camera.proj, viewport=camera.viewport)


def window_depth(position: np.ndarray, view: np.ndarray, proj: np.ndarray,
                 fallback: np.ndarray) -> np.ndarray:
    """Window depth of world positions (H, W, 3); ``fallback`` where position is NaN."""
    valid = np.isfinite(position).all(axis=-1)
    p = np.where(valid[..., None], position, 0.0)
    depth = 0.5 * transform_points(np.asarray(proj) @ np.asarray(view), p)[..., 2] + 0.5
    return np.where(valid, depth, fallback).astype(np.float32)
