"""Shadow maps of the directional light: its orthographic camera over a box (the
"shadow-map" multi-pass kind draws the depth from it; `shaders/include/shadow_map.glsl`
reads it back)."""

from __future__ import annotations

import numpy as np

from ..scene.camera import Camera

SHADOW_SIZE = 1024


def light_camera(bounds, light, size: int = SHADOW_SIZE):
    """An orthographic camera looking along the light over ``bounds`` (its shadow map)."""
    lo, hi = np.asarray(bounds, np.float64)
    centre, radius = 0.5 * (lo + hi), 0.5 * float(np.linalg.norm(hi - lo)) or 1.0
    towards = np.asarray(light.direction, np.float64)
    towards = towards / np.linalg.norm(towards)
    up = (1.0, 0.0, 0.0) if abs(towards[1]) > 0.99 else (0.0, 1.0, 0.0)
    return Camera(eye=tuple(centre + 2.0 * radius * towards), target=tuple(centre), up=up,
                  size=(size, size), near=0.5 * radius, far=3.5 * radius, ortho_height=radius)
