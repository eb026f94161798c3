"""A directional light with ambient term, shared by every renderer's Phong shading."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class DirectionalLight:
    """Light arriving from ``direction`` (a vector pointing from the scene TOWARDS the light)."""

    direction: tuple = (0.45, 0.8, 0.4)
    color: tuple = (1.0, 1.0, 1.0)
    intensity: float = 0.85
    ambient: float = 0.25
    specular: float = 0.15
    shininess: float = 32.0

    @property
    def unit_direction(self) -> np.ndarray:
        d = np.asarray(self.direction, dtype=np.float64)
        return d / np.linalg.norm(d)

    def uniforms(self) -> dict:
        """Values for the ``u_light_*`` uniforms of shaders/include/shading.glsl."""
        return {
            "u_light_dir": tuple(self.unit_direction.astype(np.float32)),
            "u_light_color": tuple(float(c) * self.intensity for c in self.color),
            "u_ambient": float(self.ambient),
            "u_specular": float(self.specular),
            "u_shininess": float(self.shininess),
        }
