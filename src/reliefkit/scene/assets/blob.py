"""The blob asset: a closed, lumpy implicit solid with dimples, a ring and an arch."""

from __future__ import annotations

import numpy as np

from ..mesh import RenderMesh
from .colors import mix, rgb, smoothstep
from .geometry import Geometry, MeshBuilder, isosurface, normalize
from .params import check_int


def _smooth_min(a: np.ndarray, b: np.ndarray, k: float) -> np.ndarray:
    """Polynomial smooth minimum: the union of two distance fields, blended over `k`."""
    h = np.maximum(k - np.abs(a - b), 0.0) / k
    return np.minimum(a, b) - h * h * (k / 4.0)


def _length(p: np.ndarray) -> np.ndarray:
    """Euclidean length over the last axis (faster than `numpy.linalg.norm` here)."""
    return np.sqrt(np.einsum("...i,...i->...", p, p))


def _torus(p: np.ndarray, major: float, minor: float) -> np.ndarray:
    """Signed distance to a torus around the local z axis (`p` (..., 3), local coordinates)."""
    ring = np.hypot(p[..., 0], p[..., 1]) - major
    return np.hypot(ring, p[..., 2]) - minor


def _rotation(axis, angle: float) -> np.ndarray:
    """3x3 rotation by `angle` radians about `axis` (Rodrigues)."""
    x, y, z = normalize(np.asarray(axis, dtype=np.float64))
    k = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    return np.eye(3) + np.sin(angle) * k + (1.0 - np.cos(angle)) * (k @ k)


def _dimple_directions(rng: np.random.Generator, count: int) -> np.ndarray:
    """Unit directions for dimples: off the equator (the ring) and, on top, off the arch."""
    out = []
    for _ in range(count):
        x, y, z = rng.normal(size=3)
        y = np.copysign(rng.uniform(0.35, 0.7), y)
        if y > 0:  # the arch stands in the x-y plane: keep top dimples to its front or back
            z = np.copysign(max(abs(z), 1.2 * abs(x)), z)
        out.append(normalize(np.array([x, y, z])))
    return np.array(out)


def _capsule(p: np.ndarray, a: np.ndarray, b: np.ndarray, radius: float) -> np.ndarray:
    """Signed distance to the capsule of `radius` around the segment from `a` to `b`."""
    ab = b - a
    t = np.clip(((p - a) @ ab) / np.float32(ab @ ab), 0.0, 1.0)
    return _length(p - a - t[..., None] * ab) - np.float32(radius)


def _blob_field(p: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Signed-distance-like field (negative inside) of the blob at float32 points `p` (..., 3).

    A lumpy body with deep dimples; a slightly tilted ring around it, held by three spokes
    (overhangs and see-through gaps from above and below); an arch on top (a tunnel along z).
    All smoothly welded together: one solid of genus 4.
    """
    f32 = np.float32
    center = np.array([0.0, -0.05, 0.0])
    waves = rng.normal(size=(4, 3))
    waves *= rng.uniform(4.0, 6.0, size=(4, 1)) / _length(waves)[:, None]
    phases = rng.uniform(0.0, 2.0 * np.pi, size=4)
    dimples = center + 0.56 * _dimple_directions(rng, 6)
    tilt_axis = rng.normal(size=3) * [1.0, 0.0, 1.0] + [1e-3, 0.0, 0.0]
    tilt = _rotation(tilt_axis, rng.uniform(0.05, 0.15))
    spoke_angles = rng.uniform(0.0, 2.0 * np.pi) + 2.0 * np.pi * np.arange(3) / 3.0

    wobble = sum(np.sin(p @ w.astype(f32) + f32(phi)) for w, phi in zip(waves, phases, strict=True))
    body = _length(p - center.astype(f32)) - f32(0.46) + f32(0.025) * wobble
    for c in dimples.astype(f32):
        body = -_smooth_min(-body, _length(p - c) - f32(0.2), 0.05)
    ring_frame = tilt @ _rotation([1.0, 0.0, 0.0], np.pi / 2)  # torus axis z -> tilted y
    shape = _smooth_min(body, _torus(p @ ring_frame.astype(f32), 0.72, 0.1), 0.06)
    for angle in spoke_angles:
        spoke = tilt @ np.array([np.cos(angle), 0.0, np.sin(angle)])
        shape = _smooth_min(
            shape, _capsule(p, (0.3 * spoke).astype(f32), (0.72 * spoke).astype(f32), 0.055), 0.08
        )
    arch = _torus(p - np.array([0.0, 0.38, 0.0], f32), 0.3, 0.085)
    return _smooth_min(shape, arch, 0.1)


def _concavity(positions: np.ndarray, normals: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """Per-vertex concavity (> 0 in dents and creases) from the smoothed umbrella Laplacian."""
    edges = np.concatenate([indices[:, [0, 1]], indices[:, [1, 2]], indices[:, [2, 0]]])
    n = len(positions)
    degree = np.bincount(edges[:, 0], minlength=n).astype(np.float64)
    total = np.zeros_like(positions)
    np.add.at(total, edges[:, 0], positions[edges[:, 1]])
    laplacian = total / np.maximum(degree, 1.0)[:, None] - positions
    mean_edge = np.linalg.norm(positions[edges[:, 0]] - positions[edges[:, 1]], axis=1).mean()
    value = np.einsum("ij,ij->i", laplacian, normals) / mean_edge**2
    for _ in range(4):  # a few smoothing passes tame marching-cubes noise
        acc = np.zeros(n)
        np.add.at(acc, edges[:, 0], value[edges[:, 1]])
        value = 0.5 * value + 0.5 * acc / np.maximum(degree, 1.0)
    return value


def blob(seed: int = 0, subdivisions: int = 4) -> RenderMesh:
    """A closed, lumpy object with dimples, a ring and an arch: no heightfield from any axis.

    It is the zero isosurface of an implicit function (a lumpy sphere with deep dimples, a
    slightly tilted ring around its equator held by three spokes, an arch over its top making
    a tunnel along z), extracted with marching cubes: one watertight, outward-facing,
    smooth-shaded solid of genus 4. Vertical lines through the arch and horizontal lines
    through the ring cross the surface four or more times.

    Parameters
    ----------
    seed : int
        Random seed for the lumps, the dimples and the ring's tilt.
    subdivisions : int
        Level of detail in [1, 5]: the field is sampled on ``5 * 2**subdivisions`` points per
        axis over [-1, 1] (80 at the default, about 30k triangles).

    Returns
    -------
    RenderMesh
        One closed part ``"blob"``; colours go from coral at the bottom to gold at the top,
        with dimples and creases tinted plum.
    """
    n = 5 * 2 ** check_int("subdivisions", subdivisions, 1, 5)
    rng = np.random.default_rng(seed)
    axis = np.linspace(-1.0, 1.0, n)
    grid = np.stack(np.meshgrid(axis, axis, axis, indexing="ij"), axis=-1).astype(np.float32)
    positions, faces, normals = isosurface(_blob_field(grid, rng), 1.0)

    height = smoothstep(positions[:, 1].min(), positions[:, 1].max(), positions[:, 1])
    around = 0.5 + 0.5 * np.sin(3.0 * np.arctan2(positions[:, 2], positions[:, 0]))
    color = mix(rgb(226, 96, 78), rgb(244, 190, 76), height)
    color = mix(color, rgb(236, 140, 96), 0.35 * around)
    color = mix(
        color, rgb(108, 56, 128), smoothstep(0.0, 0.35, _concavity(positions, normals, faces))
    )
    builder = MeshBuilder()
    builder.add("blob", Geometry(positions, faces, normals), color)
    return builder.build("blob")
