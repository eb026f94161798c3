"""Mipmap filtering of 3D textures (semi-transparent 3D texture paper, §5.2).

Alpha is opacity per unit of object-space length (as every 3D texture's): a layer of object-space
thickness ``dt`` lets through ``(1 - alpha)^dt``. ``thickness`` is the object-space length of
the shell's w extent, so each of a level's D layers is ``thickness / D`` thick.

**Along w** two layers are composited with the opacity ("over") equation, top-down: the
viewer looks into the shell from outside, so the layer of higher w is in front. Their layer
opacities are ``A = 1 - (1 - alpha)^dt``; the merged layer, of thickness 2 dt, gets the same
total transmittance, which gives ``alpha' = 1 - sqrt((1 - a_front) (1 - a_back))`` whatever
dt is, and the straight colour ``(A_f c_f + (1 - A_f) A_b c_b) / A`` with
``A = 1 - (1 - A_f)(1 - A_b)``.

**Along u, v** 2x2 texels are averaged like a regular mipmap: colour weighted by layer
opacity, and layer opacity (coverage) itself averaged, then converted back to alpha per
unit length. A dimension of size 1 is kept; an odd size > 1 is refused.
"""

from __future__ import annotations

import numpy as np

from ...errors import UsageError


def _rgba(texture) -> np.ndarray:
    rgba = getattr(texture, "rgba", texture)
    rgba = np.asarray(rgba, dtype=np.float64)
    if rgba.ndim != 4 or rgba.shape[3] != 4:
        raise UsageError(f"a 3D texture must have shape (D, H, W, 4), got {rgba.shape}")
    return rgba


def _downsample_mip(rgba, thickness):
    d = rgba.shape[0]
    dt = thickness / d
    alpha = np.clip(rgba[..., 3], 0.0, 1.0)
    if d > 1:
        back, front = rgba[0::2], rgba[1::2]  # higher w is nearer the viewer
        ab, af = np.clip(back[..., 3], 0, 1), np.clip(front[..., 3], 0, 1)
        lb, lf = 1 - (1 - ab) ** dt, 1 - (1 - af) ** dt
        layer = 1 - (1 - lf) * (1 - lb)
        premult = lf[..., None] * front[..., :3] + ((1 - lf) * lb)[..., None] * back[..., :3]
        plain = 0.5 * (front[..., :3] + back[..., :3])
        safe = np.maximum(layer, 1e-12)[..., None]
        colour = np.where(layer[..., None] > 1e-12, premult / safe, plain)
        alpha = 1 - np.sqrt((1 - af) * (1 - ab))
        dt = 2 * dt
    else:
        colour = rgba[..., :3]
    layer = 1 - (1 - alpha) ** dt
    out = []
    for value in (layer[..., None] * colour, layer[..., None], colour):
        for axis in (1, 2):
            if value.shape[axis] > 1:
                n = value.shape[axis]
                value = 0.5 * (value.take(range(0, n, 2), axis) + value.take(range(1, n, 2), axis))
        out.append(value)
    premult, layer, plain = out
    colour = np.where(layer > 1e-12, premult / np.maximum(layer, 1e-12), plain)
    alpha = 1 - (1 - np.clip(layer[..., 0], 0, 1)) ** (1 / dt)
    return np.concatenate([colour, alpha[..., None]], axis=-1)


def _downsample_naive(rgba):
    for axis in (0, 1, 2):
        n = rgba.shape[axis]
        if n > 1:
            rgba = 0.5 * (rgba.take(range(0, n, 2), axis) + rgba.take(range(1, n, 2), axis))
    return rgba


def mip_pyramid(texture, levels: int, thickness: float = 1.0) -> list[np.ndarray]:
    """``levels`` float32 RGBA volumes, level 0 the texture itself, filtered as in §5.2."""
    rgba = _rgba(texture)
    _check_levels(rgba, levels)
    if not thickness > 0:
        raise UsageError(f"thickness must be > 0, got {thickness}")
    out = [rgba]
    for _ in range(levels - 1):
        out.append(_downsample_mip(out[-1], thickness))
    return [level.astype(np.float32) for level in out]


def naive_pyramid(texture, levels: int) -> list[np.ndarray]:
    """Plain 2x2x2 RGBA averaging, for comparison (it smears opacity along w)."""
    rgba = _rgba(texture)
    _check_levels(rgba, levels)
    out = [rgba]
    for _ in range(levels - 1):
        out.append(_downsample_naive(out[-1]))
    return [level.astype(np.float32) for level in out]


def _check_levels(rgba, levels):
    """Refuse ``levels < 1`` and any odd size > 1 met while halving."""
    if levels < 1:
        raise UsageError(f"levels must be >= 1, got {levels}")
    shape = rgba.shape[:3]
    for _ in range(levels - 1):
        for n, name in zip(shape, "DHW", strict=True):
            if n > 1 and n % 2:
                raise UsageError(f"cannot halve {name} = {n}: use even (power-of-two) sizes")
        shape = tuple(n // 2 if n > 1 else n for n in shape)


def slab_transmittance(level_texture, thickness: float = 1.0) -> np.ndarray:
    """(H, W) transmittance of rays straight through the slab along w: prod (1-alpha)^dt."""
    rgba = _rgba(level_texture)
    dt = thickness / rgba.shape[0]
    return np.prod((1 - np.clip(rgba[..., 3], 0, 1)) ** dt, axis=0)
