"""Six fixed views that measure a representation against its mesh (`reliefkit shootout`,
the glTF export's LOD thresholds): around at three azimuths, from above, from below and
grazing; each framed so that the object's bounding sphere spans exactly the screen size."""

from __future__ import annotations

import math

from .views import orbit_bounds

FOV_DEG = 40.0
#: (name, azimuth, elevation) in degrees; above and below stop short of the poles, where an
#: orbit's up vector is undefined.
VIEWS = (("around 30", 30.0, 15.0), ("around 150", 150.0, 15.0), ("around 270", 270.0, 15.0),
         ("above", 60.0, 80.0), ("below", 240.0, -80.0), ("grazing", 100.0, 3.0))


def sphere_distance(fov_deg: float = FOV_DEG) -> float:
    """Distance in bounding-sphere radii at which the sphere's outline spans the field of
    view: its diameter is then the image's size in pixels."""
    return 1.0 / math.sin(math.radians(fov_deg) / 2)


def cameras(bounds, size: int) -> list:
    """One S x S camera per view, the sphere around ``bounds`` covering S pixels."""
    return [orbit_bounds(bounds, az, el, sphere_distance(), (size, size), FOV_DEG)
            for _, az, el in VIEWS]
