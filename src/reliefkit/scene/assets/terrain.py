"""The terrain asset: a fractal heightfield (a ridge, a river valley, a plateau) as a mesh."""

from __future__ import annotations

import numpy as np

from ..mesh import RenderMesh, vertex_normals
from .colors import mix, rgb, smoothstep
from .geometry import Geometry, MeshBuilder, quads_to_triangles
from .params import check_int, check_positive


def _fbm(
    u: np.ndarray,
    v: np.ndarray,
    rng: np.random.Generator,
    octaves: int = 6,
    cells: int = 3,
    persistence: float = 0.5,
) -> np.ndarray:
    """Fractal value noise in about [0, 1] at texture coordinates (`u`, `v`) in [0, 1].

    Octave k interpolates a random lattice of ``cells * 2**k`` cells with cubic splines; the
    random draws do not depend on the sampling, so every resolution samples the same noise.
    """
    from scipy import ndimage  # scipy: slow to import
    total = np.zeros(np.shape(u))
    amplitude, norm = 1.0, 0.0
    for k in range(octaves):
        n = cells * 2**k
        lattice = rng.random((n + 1, n + 1))
        coords = np.stack([np.asarray(v) * n, np.asarray(u) * n])
        total += amplitude * ndimage.map_coordinates(lattice, coords, order=3, mode="nearest")
        norm += amplitude
        amplitude *= persistence
    return total / norm


def _segment_distance(u, v, a, b) -> np.ndarray:
    """Distance from points (`u`, `v`) to the segment from `a` to `b` in the uv square."""
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    ab = b - a
    t = np.clip(((u - a[0]) * ab[0] + (v - a[1]) * ab[1]) / (ab @ ab), 0.0, 1.0)
    return np.hypot(u - (a[0] + t * ab[0]), v - (a[1] + t * ab[1]))


def terrain_heights(resolution: int = 128, seed: int = 0) -> np.ndarray:
    """A fractal landscape heightfield with a ridge, a river valley and a cliff-edged plateau.

    Parameters
    ----------
    resolution : int
        Samples per side, R >= 2.
    seed : int
        Random seed; the random draws do not depend on `resolution`, so other resolutions
        sample the same landscape.

    Returns
    -------
    numpy.ndarray
        (R, R) float32 heights in [0, 1]; ``heights[j, i]`` is the sample at
        ``u = (i + 0.5) / R``, ``v = (j + 0.5) / R`` (the DESIGN.md heightfield convention).
        Height 0 is the flat water of the river running along u near ``v = 0.22``.
    """
    r = check_int("resolution", resolution, 2)
    rng = np.random.default_rng(seed)
    texel = (np.arange(r) + 0.5) / r
    u, v = np.meshgrid(texel, texel)  # u[j, i] = texel[i], v[j, i] = texel[j]
    jitter = rng.uniform(-0.04, 0.04, size=6)
    phase = rng.uniform(0.0, 1.0)

    hills = _fbm(u, v, rng)
    crest = _fbm(u, v, rng, octaves=3, cells=4)
    h = 1.2 * hills

    # A ridge: a line of peaks across the low-u, high-v corner (crest heights follow noise).
    d = _segment_distance(u, v, (0.08 + jitter[0], 0.62 + jitter[1]), (0.55, 0.92 + jitter[2]))
    h += 0.8 * np.exp(-np.minimum((d / 0.075) ** 2, 60.0)) * (0.3 + 1.2 * crest)

    # A river valley meandering along u, with a channel carved down to the water.
    river = 0.22 + jitter[3] + 0.06 * np.sin(2.0 * np.pi * (0.9 * u + phase))
    h -= 0.3 * np.exp(-np.minimum(((v - river) / 0.1) ** 2, 60.0))
    channel = np.exp(-np.minimum(((v - river) / 0.03) ** 2, 60.0))
    h += (h.min() - 0.1 - h) * channel

    # A plateau with a cliff: a rough table top raised above its surroundings.
    center = np.array([0.74 + jitter[4], 0.6 + jitter[5]])
    angle = np.arctan2(v - center[1], u - center[0])
    edge = 0.15 * (1.0 + 0.12 * np.sin(3.0 * angle + 6.0 * phase) + 0.05 * np.sin(7.0 * angle))
    inside = np.clip((edge - np.hypot(u - center[0], v - center[1])) * r / 1.5 + 0.5, 0.0, 1.0)
    top = np.quantile(h, 0.93) + 0.02 * crest
    h = h + (np.maximum(h, top) - h) * inside

    h = (h - h.min()) / max(float(np.ptp(h)), 1e-12)
    water = 0.14
    return np.clip((h - water) / (1.0 - water), 0.0, 1.0).astype(np.float32)


def _terrain_colors(heights: np.ndarray, up: np.ndarray, seed: int) -> np.ndarray:
    """Linear RGB by altitude and slope: water, beach, grass, forest, rock, snow.

    `heights` are in [0, 1]; `up` is the y component of the unit normals.
    """
    r = heights.shape[0]
    texel = (np.arange(r) + 0.5) / r
    u, v = np.meshgrid(texel, texel)
    rng = np.random.default_rng(np.random.SeedSequence(seed).spawn(1)[0])  # not the heights'
    noise = _fbm(u, v, rng, octaves=4, cells=8) - 0.5
    a = heights + 0.12 * noise  # jittered altitude breaks up straight colour bands

    color = mix(rgb(112, 156, 64), rgb(48, 96, 42), smoothstep(0.1, 0.6, a))
    color = mix(rgb(204, 190, 140), color, smoothstep(0.0, 0.045, a))  # beach
    color = mix(color, rgb(128, 118, 106), smoothstep(0.72, 0.86, a) * 0.8)  # bare highland
    color = mix(color, rgb(116, 110, 104), smoothstep(0.82, 0.6, up))  # steep rock
    snow = smoothstep(0.84, 0.92, a) * smoothstep(0.5, 0.7, up)
    color = mix(color, rgb(242, 244, 250), snow)
    water = mix(rgb(52, 138, 140), rgb(34, 92, 118), smoothstep(0.0, 0.3, -noise))
    return np.where((heights <= 0.0)[..., None], water, color)


def terrain(
    resolution: int = 128, seed: int = 0, size: float = 2.0, height: float = 0.5
) -> RenderMesh:
    """The `terrain_heights` landscape as a grid mesh (a heightfield by construction).

    Parameters
    ----------
    resolution : int
        Grid vertices per side, R >= 2; the mesh has ``2 * (R - 1)**2`` triangles.
    seed : int
        Random seed (see `terrain_heights`).
    size : float
        Side of the square footprint, centred on the origin in x and z.
    height : float
        World height of a height of 1; ``y = heights * height``.

    Returns
    -------
    RenderMesh
        Vertex ``j * R + i`` lies at ``x = (u_i - 0.5) * size``, ``y = heights[j, i] * height``,
        ``z = (v_j - 0.5) * size`` with ``u_i = (i + 0.5) / R``, ``v_j = (j + 0.5) / R``.
        Front faces point +y, so a camera looking down -y sees the top.
    """
    size = check_positive("size", size)
    height = check_positive("height", height)
    heights = terrain_heights(resolution, seed)
    r = heights.shape[0]
    coord = ((np.arange(r) + 0.5) / r - 0.5) * size
    x, z = np.meshgrid(coord, coord)
    positions = np.stack([x, heights * height, z], axis=-1).reshape(-1, 3)
    a = (np.arange(r - 1)[:, None] * r + np.arange(r - 1)[None, :]).ravel()
    # Corners a=(i, j), a+r=(i, j+1), a+r+1, a+1: counter-clockwise seen from +y.
    indices = quads_to_triangles(np.stack([a, a + r, a + r + 1, a + 1], axis=1))
    normals = vertex_normals(positions, indices)
    colors = _terrain_colors(heights, normals[:, 1].reshape(r, r), seed).reshape(-1, 3)
    builder = MeshBuilder()
    builder.add("ground", Geometry(positions, indices, normals), colors, closed=False)
    return builder.build("terrain")
