"""Fixtures and builders shared by several test modules (test modules never import each other)."""

from __future__ import annotations

import numpy as np

from reliefkit.techniques.relief.bake import heightfield_normals
from reliefkit.techniques.relief.representation import ReliefTexture

# box [-1, 1] x [0, 1] x [-1, 1]: u along +x, v along -z, h along +y
BOX = np.array([[2.0, 0, 0, -1], [0, 0, 1.0, 0], [0, -2.0, 0, 1], [0, 0, 0, 1]])


def make_relief(height, box_to_world=BOX, safety=None, rgb=(0.2, 0.6, 0.3)):
    height = np.asarray(height, np.float32)
    color = np.zeros(height.shape + (4,), np.uint8)
    color[..., :3] = np.round(np.array(rgb) * 255)
    color[..., 3] = 255
    if safety is None:
        safety = np.ones(height.shape, np.uint8)
    return ReliefTexture(height=height, color=color,
                         normal=heightfield_normals(height, box_to_world),
                         box_to_world=box_to_world, safety=safety)
