"""Placing cameras around anything with ``bounds``: the CLI's --view and --size."""

from __future__ import annotations

import numpy as np

from ..errors import UsageError
from .camera import Camera

DEFAULT_VIEW = (30.0, 25.0, 2.6)
DEFAULT_SIZE = (512, 512)


def parse_view(text: str) -> tuple[float, float, float]:
    """'AZ,EL,DIST' -> floats (degrees, degrees, bounding-sphere radii)."""
    try:
        az, el, dist = (float(part) for part in text.split(","))
    except ValueError:
        raise UsageError(f"--view must be AZ,EL,DIST (e.g. 30,25,2.6), got {text!r}") from None
    if not all(np.isfinite((az, el, dist))) or dist <= 0:
        raise UsageError(f"--view needs finite angles and a positive distance, got {text!r}")
    if abs(el) >= 90:
        raise UsageError(f"--view elevation must be strictly between -90 and 90, got {el}")
    return az, el, dist


def parse_size(text: str) -> tuple[int, int]:
    """'WxH' -> (W, H)."""
    try:
        w, h = (int(part) for part in text.lower().split("x"))
    except ValueError:
        raise UsageError(f"--size must be WxH (e.g. 512x512), got {text!r}") from None
    if w < 1 or h < 1 or w > 16384 or h > 16384:
        raise UsageError(f"--size must be between 1x1 and 16384x16384, got {text!r}")
    return w, h


def bounds_radius(bounds) -> float:
    """Half the diagonal of an axis-aligned box (never zero)."""
    b = np.asarray(bounds, dtype=np.float64)
    r = 0.5 * float(np.linalg.norm(b[1] - b[0]))
    return r if r > 0 else 1.0


def orbit_bounds(bounds, azimuth: float, elevation: float, distance: float,
                 size=DEFAULT_SIZE, fov_deg: float = 40.0) -> Camera:
    """Orbit the box centre at ``distance`` bounding-sphere radii, near/far hugging the box."""
    b = np.asarray(bounds, dtype=np.float64)
    radius = bounds_radius(b)
    d = distance * radius
    near = max(d - 1.05 * radius, 0.005 * d)
    return Camera.orbit(tuple(b.mean(axis=0)), azimuth, elevation, d, fov_deg=fov_deg,
                        size=size, near=near, far=d + 1.05 * radius)


def turntable(bounds, count: int, elevation: float, distance: float, size=DEFAULT_SIZE,
              fov_deg: float = 40.0) -> list[Camera]:
    """``count`` cameras evenly spaced in azimuth around the box."""
    if count < 1 or count > 3600:
        raise UsageError(f"--turntable needs between 1 and 3600 views, got {count}")
    return [orbit_bounds(bounds, 360.0 * k / count, elevation, distance, size, fov_deg)
            for k in range(count)]
