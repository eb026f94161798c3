"""Meshes shared by the billboard tests: flat-shaded quads coloured by a known function of
position, planes of them, two stacked within one epsilon."""

from __future__ import annotations

import numpy as np

from reliefkit.scene.mesh import RenderMesh


def colour_of(points: np.ndarray) -> np.ndarray:
    """The test meshes' linear colour at world points: linear in position."""
    p = np.asarray(points, dtype=np.float64)
    return np.stack([0.2 + 0.3 * (p[..., 0] + 1), 0.2 + 0.3 * (p[..., 1] + 1),
                     0.2 + 0.3 * (p[..., 2] + 1), np.ones(p.shape[:-1])], axis=-1)


def quads(*corner_sets, colours=None) -> RenderMesh:
    """Flat-shaded quads (4 corners each, counter-clockwise seen from their normal side)."""
    positions, indices, normals, colors = [], [], [], []
    for q, corners in enumerate(corner_sets):
        c = np.asarray(corners, dtype=np.float64)
        n = np.cross(c[1] - c[0], c[2] - c[0])
        positions.append(c)
        indices += [[4 * q, 4 * q + 1, 4 * q + 2], [4 * q, 4 * q + 2, 4 * q + 3]]
        normals.append(np.tile(n / np.linalg.norm(n), (4, 1)))
        colors.append(colour_of(c) if colours is None else np.tile(colours[q], (4, 1)))
    return RenderMesh(np.concatenate(positions), indices, np.concatenate(normals),
                      np.concatenate(colors), name="quads")


def flat(z: float, half=(1.0, 0.5), down=False) -> np.ndarray:
    x, y = half
    corners = np.array([[-x, -y, z], [x, -y, z], [x, y, z], [-x, y, z]])
    return corners[::-1] if down else corners


def stacked(gap: float = 0.1) -> RenderMesh:
    """Two parallel quads ``gap`` apart: within epsilon 0.05 (0.112) of one plane."""
    return quads(flat(0.0), flat(gap, half=(0.9, 0.45)))
