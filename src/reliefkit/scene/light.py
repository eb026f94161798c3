"""A directional light with ambient term, shared by every renderer's Phong shading.

Angles follow `Camera.orbit` (and the CLI's ``--view``): azimuth about +y from +z towards +x,
elevation above the xz plane, both in degrees; the light arrives from that direction.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import UsageError

# A low sun from the side of the default view (azimuth 30): raking light, so relief and
# `--shadows` read clearly, while faces turned to the camera stay lit.
DEFAULT_LIGHT_ANGLES = (-60.0, 30.0)


def direction_from_angles(azimuth: float, elevation: float) -> tuple[float, float, float]:
    """The unit vector towards a light at ``azimuth``, ``elevation`` (degrees)."""
    if not np.isfinite((azimuth, elevation)).all():
        raise UsageError(f"light angles must be finite, got {azimuth}, {elevation}")
    if abs(elevation) > 90:
        raise UsageError(f"light elevation must be within [-90, 90] degrees, got {elevation}")
    az, el = np.radians(azimuth), np.radians(elevation)
    return (float(np.cos(el) * np.sin(az)), float(np.sin(el)), float(np.cos(el) * np.cos(az)))


@dataclass(frozen=True)
class DirectionalLight:
    """Light arriving from ``direction`` (a vector pointing from the scene TOWARDS the light)."""

    direction: tuple = direction_from_angles(*DEFAULT_LIGHT_ANGLES)
    color: tuple = (1.0, 1.0, 1.0)
    intensity: float = 0.85
    ambient: float = 0.25
    specular: float = 0.15
    shininess: float = 32.0

    @classmethod
    def from_angles(cls, azimuth: float, elevation: float, **kwargs) -> DirectionalLight:
        """A light from ``azimuth``, ``elevation`` degrees (the conventions of ``--view``);
        other fields as keywords."""
        return cls(direction=direction_from_angles(azimuth, elevation), **kwargs)

    @property
    def angles(self) -> tuple[float, float]:
        """(azimuth, elevation) in degrees, the inverse of `from_angles`."""
        x, y, z = self.unit_direction
        return float(np.degrees(np.arctan2(x, z))), float(np.degrees(np.arcsin(np.clip(y, -1, 1))))

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
