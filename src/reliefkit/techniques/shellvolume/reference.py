"""Exact CPU reference renderer of a shell volume (Dufort, Leblanc & Poulin 2005, §4.3).

Tests check the GPU renderer against it, so it defines the light transport exactly; the
GPU renderer implements the same transfer (up to float32 and the hardware's filtering).

**Rays.** Pixel (row r, column c), row 0 on top, is the ray through window coordinates
(c + 0.5, H - 1 - r + 0.5) (`reliefkit.scene.camera.pixel_segments`): it starts at the
near-plane point o, has the unit direction d towards the far-plane point, and is clipped to
t in [0, t_far] (t_far = distance from the near to the far point), i.e. to the view volume.

**Segments.** The ray is intersected with *every* tetrahedron: its segment [t_in, t_out] is
the intersection of the four half-spaces plane @ (p, 1) <= 0 and of [0, t_far]. With
eps = 1e-9 x the shell's size (its bounding-box diagonal), a plane parallel to the ray
(|n . d| <= 1e-12, n the unit normal) keeps all or nothing: nothing when the origin is
outside it by more than eps, all when inside by more than eps; a ray lying in the plane
(within eps) is inside when the first component of n of magnitude > 1e-6 is positive (as if
the ray were nudged by -(e, e^2, e^3)), so a ray along a face shared by two tetrahedra, or
along an edge shared by several, is inside exactly one of them. Segments with
t_out - t_in <= eps are dropped; the others are *crossings*. They are sorted by t_in (ties
by tetrahedron index) and composited front to back.

**Samples.** A segment of length L = t_out - t_in gets n samples at the midpoints
lambda_k = (k + 0.5) / n, k = 0..n-1, each standing for dt = L / n:
``samples=N`` takes n = N for every segment (what the GPU does); ``step=h`` takes
n = max(1, ceil(L / h)) (dense); the default is ``step = mean(shell.thickness) / 256``.

**Lookup.** At the sample point p = o + (t_in + lambda_k L) d in tetrahedron t,
(u, v, w) = (M_t @ (p, 1))[:3] with M_t = ``shell.object_to_texture[t]``; the texture is
read at s = (u U, v V, w), (U, V) = ``texture.tile``, with GL trilinear filtering of the
(D, H, W, 4) array indexed [w, v, u]: texel centres at (i + 0.5) / size, so along an axis
of size n, x = s n - 0.5, i0 = floor(x), f = x - i0 and the value is
(1 - f) T[i0] + f T[i0 + 1]; u and v REPEAT (s is first reduced to s - floor(s), indices
taken modulo n, so the filter wraps across the edge), w CLAMP_TO_EDGE (indices clamped to
[0, D - 1]). What is filtered is `textures.marched_volume`: the optical density
sigma = -ln(1 - alpha) / length per unit length (alpha being the opacity over the
texture's ``length``, 1 by default; solid voxels get a large finite density) and the colour
times it plus `textures.density_floor`; a sample's colour is the filtered colour over the
filtered density plus that floor.

**Transfer.** The sample's opacity is a = 1 - exp(-sigma dt) (= 1 - (1 - alpha)^dt on a
texel centre, the paper's §4.3 correction) and its colour c = filtered rgb (unlit). Front
to back, with C and A starting at 0:
C += (1 - A) a c, A += (1 - A) a. The ray stops once A > 1 - 1e-6.

**Outputs.** ``color`` is (C / A, A) (straight colour; 0 where A = 0); ``position`` the
sample point p of the first sample after which A >= 0.5 (NaN where A never gets there);
``crossings`` the number of crossings (all of them, whether or not the ray stopped early).

**Acceleration** (no effect on the result). Tetrahedra are binned by the screen rectangle
of their projected vertices (widened by a pixel) into tiles of `TILE` x `TILE` pixels;
tetrahedra with a vertex behind (or on) the eye plane go to every tile, those entirely
behind it to none. Tiles are rendered in parallel (numba ``prange``).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
from numba import njit, prange

from ...colorspace import srgb_decode
from ...errors import UsageError
from ...scene.camera import pixel_segments
from .binning import bin_by_tile, screen_boxes
from .filtering import mip_pyramid
from .textures import density_floor, marched_volume

#: Tile size (pixels) of the screen-space binning.
TILE = 8

#: Segments not longer than this times the shell's size are not crossings.
MIN_LENGTH = 1e-9

#: |unit normal . unit direction| at most this: the ray is parallel to the face plane.
PARALLEL = 1e-12

#: The ray stops once its accumulated opacity exceeds 1 - OPAQUE.
OPAQUE = 1e-6

#: Dense sampling default: this many steps per mean shell thickness.
STEPS_PER_THICKNESS = 256


@dataclass(frozen=True, eq=False)
class ReferenceImage:
    """A reference rendering.

    Attributes
    ----------
    color : (H, W, 4) float32 straight linear RGB and alpha (accumulated opacity).
    position : (H, W, 3) float64 world point where the opacity first reaches 0.5, NaN where
        it never does.
    crossings : (H, W) int32 tetrahedra the pixel's ray crossed with positive length.
    seconds : wall time of the rendering (binning and kernels, numba compilation included
        on a cold cache).
    """

    color: np.ndarray
    position: np.ndarray
    crossings: np.ndarray
    seconds: float

    @property
    def alpha(self) -> np.ndarray:
        """(H, W) float32 accumulated opacity."""
        return self.color[..., 3]

    @property
    def premultiplied(self) -> np.ndarray:
        """(H, W, 4) float32 premultiplied RGBA (the colour over a black background)."""
        return np.concatenate([self.color[..., :3] * self.color[..., 3:], self.color[..., 3:]],
                              axis=-1)


def reference_render(shell, texture, camera, *, step=None, samples=None, level=None,
                     rgba=None, surface=None, layers=None) -> ReferenceImage:
    """Render `shell` filled with `texture` as seen by `camera` (see the module docstring).

    step: dense sampling, n = max(1, ceil(L / step)) samples per segment (default
        mean thickness / 256). samples: exactly that many per segment (not with step).
    level: None for the texture itself, or an int >= 0, the mip level of
        `filtering.mip_pyramid(texture, level + 1, mean thickness)` to read.
    rgba: an explicit (D, H, W, 4) array (e.g. a mip level) read instead of texture.rgba
        (not with level); ``texture.tile`` still applies.
    surface, layers: the base's material atlas (`TexturedShell.surface`) and each
        tetrahedron's layer in it (`TexturedShell.surface_layers`): colours are multiplied by
        its bilinear (clamped) colour at the sample's base uv, as the renderer does.
    """
    start = time.perf_counter()
    if step is not None and samples is not None:
        raise UsageError("give step or samples, not both")
    mean_thickness = float(np.mean(shell.thickness))
    n_samples, h = _sampling(step, samples, mean_thickness)
    volume = _volume(texture, level, rgba, mean_thickness)
    tile_u, tile_v = (float(x) for x in texture.tile)

    near, far = pixel_segments(camera)
    seg = far - near
    t_far = np.linalg.norm(seg, axis=-1)
    if not (np.isfinite(t_far).all() and (t_far > 0).all()):
        raise UsageError("the camera gives degenerate pixel rays")
    dirs = seg / t_far[..., None]
    width, height = camera.size

    positions = np.asarray(shell.positions, dtype=np.float64)
    size = float(np.linalg.norm(positions.max(axis=0) - positions.min(axis=0)))
    eps = MIN_LENGTH * size
    ntx, nty = -(-width // TILE), -(-height // TILE)
    lo_c, hi_c, lo_r, hi_r = screen_boxes(shell, camera, width, height)
    starts, items = bin_by_tile(lo_c, hi_c, lo_r, hi_r, ntx, nty, TILE)

    if surface is None:  # one white texel: a factor of 1
        tint, layers, box = np.ones((1, 1, 1, 3)), np.zeros(len(shell.tets), np.int64), \
            (0.0, 0.0, 1.0, 1.0)
    else:
        tint, box = srgb_decode(surface.rgba8[..., :3] / 255.0), surface.box
    color = np.zeros((height, width, 4), np.float32)
    position = np.full((height, width, 3), np.nan)
    crossings = np.zeros((height, width), np.int32)
    _render(np.ascontiguousarray(near), np.ascontiguousarray(dirs), t_far,
            np.ascontiguousarray(shell.planes, dtype=np.float64),
            np.ascontiguousarray(shell.object_to_texture, dtype=np.float64),
            starts, items, ntx, volume, tile_u, tile_v, n_samples, h, eps,
            density_floor(mean_thickness), np.ascontiguousarray(tint),
            np.asarray(layers, np.int64), np.asarray(box, np.float64), color, position,
            crossings)
    return ReferenceImage(color, position, crossings, time.perf_counter() - start)


def _sampling(step, samples, mean_thickness) -> tuple[int, float]:
    """(samples per segment or 0, dense step)."""
    if samples is not None:
        if isinstance(samples, bool) or int(samples) != samples or samples < 1:
            raise UsageError(f"samples must be a positive integer, got {samples!r}")
        return int(samples), 0.0
    h = mean_thickness / STEPS_PER_THICKNESS if step is None else step
    try:
        h = float(h)
    except (TypeError, ValueError):
        raise UsageError(f"step must be a positive number, got {step!r}") from None
    if not (math.isfinite(h) and h > 0):
        raise UsageError(f"step must be a positive number, got {step!r}")
    return 0, h


def _volume(texture, level, rgba, mean_thickness) -> np.ndarray:
    """The (D, H, W, 4) float64 array to sample."""
    if rgba is not None and level is not None:
        raise UsageError("give level or rgba, not both")
    if level is not None:
        if isinstance(level, bool) or int(level) != level or level < 0:
            raise UsageError(f"level must be a non-negative integer, got {level!r}")
        rgba = mip_pyramid(texture, int(level) + 1,
                           mean_thickness / texture.length)[int(level)]
    elif rgba is None:
        rgba = texture.rgba
    arr = np.asarray(rgba, dtype=np.float64)
    if arr.ndim != 4 or arr.shape[3] != 4 or min(arr.shape) < 1:
        raise UsageError(f"rgba must have shape (D, H, W, 4), got {arr.shape}")
    if not np.isfinite(arr).all():
        raise UsageError("rgba contains NaN or Inf values")
    return np.ascontiguousarray(marched_volume(arr, texture.length, mean_thickness),
                                dtype=np.float64)


@njit(cache=True)
def _keeps(a, b, c):
    """Whether a ray lying in a face plane of normal (a, b, c) counts as inside: its first
    component of magnitude > 1e-6 is positive (the ray nudged by -(e, e^2, e^3))."""
    if abs(a) > 1e-6:
        return a > 0.0
    if abs(b) > 1e-6:
        return b > 0.0
    return c > 0.0


@njit(cache=True, error_model="numpy")
def _segment(planes, t, ox, oy, oz, dx, dy, dz, t_far, eps):
    """(t_in, t_out) of the ray in tetrahedron t, clipped to [0, t_far]; t_in > t_out when
    it misses."""
    t_in, t_out = 0.0, t_far
    for f in range(4):
        a, b, c, e = planes[t, f, 0], planes[t, f, 1], planes[t, f, 2], planes[t, f, 3]
        num = a * ox + b * oy + c * oz + e  # > 0: origin outside this plane
        den = a * dx + b * dy + c * dz
        if abs(den) <= PARALLEL:
            if num > eps or (num >= -eps and not _keeps(a, b, c)):
                return 1.0, 0.0
        elif den < 0.0:
            t_in = max(t_in, -num / den)
        else:
            t_out = min(t_out, -num / den)
    return t_in, t_out


@njit(cache=True, error_model="numpy")
def _wrap_axis(s, n):
    """REPEAT: (i0, i1, f) of coordinate s on an axis of n texels."""
    x = (s - math.floor(s)) * n - 0.5
    fl = math.floor(x)
    f = x - fl
    i0 = int(fl) % n
    return i0, (i0 + 1) % n, f


@njit(cache=True, error_model="numpy")
def _clamp_axis(s, n):
    """CLAMP_TO_EDGE: (i0, i1, f) of coordinate s on an axis of n texels."""
    x = s * n - 0.5
    fl = math.floor(x)
    f = x - fl
    i0 = int(fl)
    i1 = i0 + 1
    i0 = min(max(i0, 0), n - 1)
    i1 = min(max(i1, 0), n - 1)
    return i0, i1, f


@njit(cache=True, error_model="numpy")
def _fetch(vol, su, sv, sw, out):
    """Trilinear RGBA at texel coordinates (su, sv, sw) into out (4,)."""
    u0, u1, fu = _wrap_axis(su, vol.shape[2])
    v0, v1, fv = _wrap_axis(sv, vol.shape[1])
    w0, w1, fw = _clamp_axis(sw, vol.shape[0])
    for ch in range(4):
        c00 = (1.0 - fu) * vol[w0, v0, u0, ch] + fu * vol[w0, v0, u1, ch]
        c01 = (1.0 - fu) * vol[w0, v1, u0, ch] + fu * vol[w0, v1, u1, ch]
        c10 = (1.0 - fu) * vol[w1, v0, u0, ch] + fu * vol[w1, v0, u1, ch]
        c11 = (1.0 - fu) * vol[w1, v1, u0, ch] + fu * vol[w1, v1, u1, ch]
        c0 = (1.0 - fv) * c00 + fv * c01
        c1 = (1.0 - fv) * c10 + fv * c11
        out[ch] = (1.0 - fw) * c0 + fw * c1


@njit(cache=True, error_model="numpy")
def _tint(tint, layer, box, u, v, out):
    """Multiply out[:3] by the bilinear (clamped) colour of layer ``layer`` of ``tint``
    (M, H, W, 3) at base uv (u, v) over the rectangle ``box`` (u0, v0, u1, v1)."""
    x0, x1, fx = _clamp_axis((u - box[0]) / (box[2] - box[0]), tint.shape[2])
    y0, y1, fy = _clamp_axis((v - box[1]) / (box[3] - box[1]), tint.shape[1])
    for ch in range(3):
        c0 = (1.0 - fx) * tint[layer, y0, x0, ch] + fx * tint[layer, y0, x1, ch]
        c1 = (1.0 - fx) * tint[layer, y1, x0, ch] + fx * tint[layer, y1, x1, ch]
        out[ch] *= (1.0 - fy) * c0 + fy * c1


@njit(cache=True, parallel=True, error_model="numpy")
def _render(origins, dirs, t_far, planes, m, starts, items, ntx, vol, tile_u, tile_v,
            n_samples, h, eps, floor, tint, layers, box, color, position, crossings):
    height, width = t_far.shape
    for k in prange(starts.shape[0] - 1):
        ty, tx = k // ntx, k % ntx
        lo, hi = starts[k], starts[k + 1]
        n = hi - lo
        t_ins = np.empty(n)
        t_outs = np.empty(n)
        ids = np.empty(n, np.int64)
        texel = np.empty(4)
        for r in range(ty * TILE, min((ty + 1) * TILE, height)):
            for c in range(tx * TILE, min((tx + 1) * TILE, width)):
                ox, oy, oz = origins[r, c, 0], origins[r, c, 1], origins[r, c, 2]
                dx, dy, dz = dirs[r, c, 0], dirs[r, c, 1], dirs[r, c, 2]
                hits = 0
                for j in range(lo, hi):
                    t = items[j]
                    a, b = _segment(planes, t, ox, oy, oz, dx, dy, dz, t_far[r, c], eps)
                    if b - a > eps:
                        t_ins[hits] = a
                        t_outs[hits] = b
                        ids[hits] = t
                        hits += 1
                crossings[r, c] = hits
                if hits == 0:
                    continue
                # sort by entry, ties by tetrahedron index (items are in index order)
                order = np.argsort(t_ins[:hits], kind="mergesort")
                acc_r, acc_g, acc_b, acc_a = 0.0, 0.0, 0.0, 0.0
                found = False
                done = False
                for q in range(hits):
                    i = order[q]
                    t = ids[i]
                    t0 = t_ins[i]
                    length = t_outs[i] - t0
                    ns = n_samples if n_samples > 0 else max(1, int(math.ceil(length / h)))
                    dt = length / ns
                    for s in range(ns):
                        tt = t0 + (s + 0.5) / ns * length
                        px, py, pz = ox + tt * dx, oy + tt * dy, oz + tt * dz
                        u = m[t, 0, 0] * px + m[t, 0, 1] * py + m[t, 0, 2] * pz + m[t, 0, 3]
                        v = m[t, 1, 0] * px + m[t, 1, 1] * py + m[t, 1, 2] * pz + m[t, 1, 3]
                        w = m[t, 2, 0] * px + m[t, 2, 1] * py + m[t, 2, 2] * pz + m[t, 2, 3]
                        _fetch(vol, u * tile_u, v * tile_v, w, texel)
                        sigma = max(texel[3], 0.0)
                        a = 1.0 - math.exp(-sigma * dt)
                        weight = sigma + floor  # colour stored times density + floor
                        texel[0] /= weight
                        texel[1] /= weight
                        texel[2] /= weight
                        _tint(tint, layers[t], box, u, v, texel)
                        weight = (1.0 - acc_a) * a
                        acc_r += weight * texel[0]
                        acc_g += weight * texel[1]
                        acc_b += weight * texel[2]
                        acc_a += weight
                        if not found and acc_a >= 0.5:
                            found = True
                            position[r, c, 0] = px
                            position[r, c, 1] = py
                            position[r, c, 2] = pz
                        if acc_a > 1.0 - OPAQUE:
                            done = True
                            break
                    if done:
                        break
                color[r, c, 3] = acc_a
                if acc_a > 0.0:
                    color[r, c, 0] = acc_r / acc_a
                    color[r, c, 1] = acc_g / acc_a
                    color[r, c, 2] = acc_b / acc_a
