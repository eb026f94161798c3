"""Blending a DMBBC into its billboard cloud with distance (§3.4.2).

Beyond the distance where epsilon, the boxes' half depth, projects below one pixel the boxes
add nothing a pixel can show: the flat cloud is drawn instead (the *switch distance*). Before
it the boxes are flattened linearly to their rectangles (the paper's geomorphing), so the
switch does not pop: at the switch distance the flattened boxes are the rectangles.
"""

from __future__ import annotations

import math

import numpy as np


def pixel_size(camera, distance: float) -> float:
    """World size of one pixel at ``distance`` from the eye (vertically)."""
    if camera.orthographic:
        return 2.0 * camera.ortho_height / camera.size[1]
    return 2.0 * distance * math.tan(math.radians(camera.fov_deg) / 2) / camera.size[1]


def switch_distance(camera, epsilon: float) -> float:
    """Distance at which ``epsilon`` projects to one pixel (inf for an orthographic camera
    whose pixels are smaller than epsilon, 0 for one whose pixels are larger)."""
    if camera.orthographic:
        return math.inf if epsilon >= pixel_size(camera, 1.0) else 0.0
    return epsilon * camera.size[1] / (2.0 * math.tan(math.radians(camera.fov_deg) / 2))


def flatten_factor(camera, epsilon: float, center, transition: float) -> float:
    """The boxes' depth scale at this camera: 1 closer than ``transition`` x the switch
    distance, 0 from the switch distance on (draw the flat cloud), linear between."""
    switch = switch_distance(camera, epsilon)
    if math.isinf(switch) or switch <= 0:
        return 1.0 if switch > 0 else 0.0
    distance = float(np.linalg.norm(np.asarray(camera.eye) - np.asarray(center)))
    start = transition * switch
    if distance <= start:
        return 1.0
    return max(0.0, (switch - distance) / (switch - start))
