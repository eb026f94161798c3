"""The tree asset: a flared trunk, recursive tapered branches and double-sided leaves."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..mesh import RenderMesh
from .colors import mix, rgb
from .geometry import (
    Geometry,
    MeshBuilder,
    lathe,
    normalize,
    perpendicular_frame,
    quads_to_triangles,
)
from .params import check_int


class _Branch(NamedTuple):
    """One tapered cylinder of the tree: start point, unit direction, length, radii, depth."""

    start: np.ndarray
    direction: np.ndarray
    length: float
    radius: float
    tip_radius: float
    depth: int


def _tilt(direction: np.ndarray, angle: float, azimuth: float) -> np.ndarray:
    """`direction` turned by `angle` radians towards the side given by `azimuth`."""
    e1, e2 = perpendicular_frame(direction)
    side = np.cos(azimuth) * e1 + np.sin(azimuth) * e2
    return np.cos(angle) * direction + np.sin(angle) * side


def _grow(rng: np.random.Generator, branch: _Branch, out: list[_Branch]) -> None:
    """Append `branch` and, recursively, its 2-3 children to `out`."""
    out.append(branch)
    if branch.depth == 0:
        return
    count = int(rng.integers(2, 4))
    azimuth0 = rng.uniform(0.0, 2.0 * np.pi)
    for k in range(count):
        leader = k == 0  # the first child carries on from the tip, the others fork lower
        t = 1.0 if leader else rng.uniform(0.5, 0.92)
        angle = np.radians(rng.uniform(8, 22) if leader else rng.uniform(30, 55))
        direction = _tilt(branch.direction, angle, azimuth0 + 2.0 * np.pi * k / count)
        direction = normalize(direction + [0.0, 0.25, 0.0])  # branches reach for the light
        radius = branch.radius + (branch.tip_radius - branch.radius) * t
        radius *= 0.9 if leader else 0.7
        start = branch.start + branch.direction * branch.length * t - direction * radius
        length = branch.length * rng.uniform(0.62, 0.78)
        _grow(rng, _Branch(start, direction, length, radius, radius * 0.7, branch.depth - 1), out)


def _leaf_quads(rng: np.random.Generator, branches: list[_Branch], count: int) -> Geometry:
    """Make `count` double-sided kite-shaped leaves on the outer branches.

    Each leaf has 8 vertices and 4 triangles: the front and the back are separate vertices
    with opposite normals and opposite windings.
    """
    twigs = [b for b in branches if b.depth <= 1]
    pick = rng.integers(0, len(twigs), size=count)
    t = rng.uniform(0.2, 1.0, size=count)
    start = np.array([twigs[i].start for i in pick])
    along = np.array([twigs[i].direction * twigs[i].length for i in pick])
    stem = start + along * t[:, None] + rng.normal(scale=0.025, size=(count, 3))
    up = normalize(
        normalize(along) * 0.6 + rng.normal(scale=0.7, size=(count, 3)) + [0.0, 0.2, 0.0]
    )
    normal = normalize(np.cross(up, rng.normal(size=(count, 3))))
    across = np.cross(up, normal)  # cross(across, up) == normal
    length = rng.uniform(0.1, 0.16, size=(count, 1))
    width = 0.42 * length
    corners = np.stack(
        [
            stem,
            stem + 0.45 * length * up + width * across,
            stem + length * up,
            stem + 0.45 * length * up - width * across,
        ],
        axis=1,
    )
    front = np.arange(count)[:, None] * 8 + np.arange(4)
    back = front + 4
    positions = np.concatenate([corners, corners], axis=1).reshape(-1, 3)
    normals = np.concatenate(
        [np.repeat(normal[:, None], 4, 1), np.repeat(-normal[:, None], 4, 1)], axis=1
    ).reshape(-1, 3)
    indices = np.concatenate([quads_to_triangles(front), quads_to_triangles(back[:, ::-1])])
    return Geometry(positions, indices, normals)


def _leaf_colors(rng: np.random.Generator, count: int) -> np.ndarray:
    """Per-vertex linear RGB for `count` leaves: greens varying per leaf, backs paler."""
    shade = mix(rgb(38, 104, 34), rgb(126, 176, 52), rng.uniform(0.0, 1.0, size=count))
    shade *= rng.uniform(0.8, 1.15, size=(count, 1))
    back = mix(shade, rgb(170, 196, 110), 0.35)
    return np.concatenate(
        [np.repeat(shade[:, None], 4, 1), np.repeat(back[:, None], 4, 1)], axis=1
    ).reshape(-1, 3)


def tree(seed: int = 0, leaves: int = 600) -> RenderMesh:
    """A tree: a flared, tapered trunk, recursive branches and double-sided leaf quads.

    Parameters
    ----------
    seed : int
        Random seed for the branching and the leaves.
    leaves : int
        Number of leaves (>= 0); each is one quad emitted twice (both windings).

    Returns
    -------
    RenderMesh
        Stands on y = -1 and reaches to about y = 1. Parts: ``"trunk"`` and ``"branch"``
        (closed tapered cylinders, browns) and ``"leaves"`` (open, ``4 * leaves`` triangles,
        greens).
    """
    leaves = check_int("leaves", leaves, 0)
    rng = np.random.default_rng(seed)
    trunk = _Branch(np.array([0.0, -1.0, 0.0]), np.array([0.0, 1.0, 0.0]), 0.8, 0.075, 0.055, 4)
    branches: list[_Branch] = []
    _grow(rng, trunk, branches)
    builder = MeshBuilder()
    bark = rgb(96, 64, 38)
    for b in branches:
        if b.depth == trunk.depth:  # a flared foot for the trunk
            profile = [(b.radius * 1.5, 0.0), (b.radius, 0.12), (b.tip_radius, b.length)]
        else:
            profile = [(b.radius, 0.0), (b.tip_radius, b.length)]
        segments = 14 if b.depth >= 3 else 7
        color = bark * rng.uniform(0.85, 1.15)
        name = "trunk" if b.depth == trunk.depth else "branch"
        builder.add(name, lathe(b.start, b.direction, profile, segments), color)
    if leaves:
        builder.add(
            "leaves", _leaf_quads(rng, branches, leaves), _leaf_colors(rng, leaves), closed=False
        )
    return builder.build("tree")
