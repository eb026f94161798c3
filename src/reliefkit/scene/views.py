"""Placing cameras around anything with ``bounds``: the CLI's --view, --size and --light.

A mesh and every representation baked from it are framed by the same box: a baked
representation keeps its source mesh's bounds (``source_bounds``), so one ``--view`` gives one
camera for all of them (`framing_bounds`).
"""

from __future__ import annotations

import numpy as np

from ..core.transforms import MAX_COORDINATE
from ..errors import FormatError, UsageError
from .camera import Camera

DEFAULT_VIEW = (30.0, 25.0, None)  # distance None: fit the bounding sphere in the view
FIT_MARGIN = 1.05                  # the fitted sphere fills 1 / FIT_MARGIN of the view
DEFAULT_SIZE = (512, 512)
DEFAULT_FOV = 40.0                 # vertical field of view in degrees (--fov)
DISTANCE_RANGE = (0.01, 1e4)       # --view DIST in bounding-sphere radii: near/far stay sane
FOV_RANGE = (0.1, 179.0)           # --fov in degrees: the projection stays well conditioned


def parse_view(text: str) -> tuple[float, float, float | None]:
    """'AZ,EL[,DIST]' -> (degrees, degrees, bounding-sphere radii or None: fit the view)."""
    parts = text.split(",")
    try:
        if len(parts) not in (2, 3):
            raise ValueError
        az, el = float(parts[0]), float(parts[1])
        dist = float(parts[2]) if len(parts) == 3 else None
    except ValueError:
        raise UsageError(f"--view must be AZ,EL or AZ,EL,DIST (e.g. 30,25 or 30,25,2.6), got "
                         f"{text!r}") from None
    if not np.isfinite((az, el)).all() or (dist is not None and not (np.isfinite(dist)
                                                                      and dist > 0)):
        raise UsageError(f"--view needs finite angles and a positive distance, got {text!r}")
    lo, hi = DISTANCE_RANGE
    if dist is not None and not lo <= dist <= hi:
        raise UsageError(f"--view distance must be within [{lo:g}, {hi:g}] bounding-sphere "
                         f"radii, got {dist:g}")
    if abs(el) >= 90:
        raise UsageError(f"--view elevation must be strictly between -90 and 90, got {el}")
    return az, el, dist


def parse_light(text: str) -> tuple[float, float]:
    """'AZ,EL' -> the light's (azimuth, elevation) in degrees, the conventions of --view."""
    try:
        az, el = (float(part) for part in text.split(","))
    except ValueError:
        raise UsageError(f"--light must be AZ,EL in degrees (e.g. -60,30), got {text!r}") \
            from None
    if not np.isfinite((az, el)).all() or abs(el) > 90:
        raise UsageError(f"--light needs finite angles and an elevation within [-90, 90], got "
                         f"{text!r}")
    return az, el


def check_fov(fov_deg: float) -> float:
    """The vertical field of view in degrees, within `FOV_RANGE` (a subset of (0, 180) where
    the projection and the fitted distance stay finite and well conditioned)."""
    lo, hi = FOV_RANGE
    if not lo <= fov_deg <= hi:
        raise UsageError(f"--fov must be within [{lo:g}, {hi:g}] degrees (strictly between 0 "
                         f"and 180), got {fov_deg:.10g}")
    return fov_deg


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


def fit_distance(size, fov_deg: float = DEFAULT_FOV) -> float:
    """Distance in bounding-sphere radii at which the sphere fits the view (both directions)."""
    w, h = size
    half_v = np.radians(fov_deg) / 2
    half_h = np.arctan(np.tan(half_v) * w / h)
    return FIT_MARGIN / float(np.sin(min(half_v, half_h)))


def framing_bounds(obj) -> np.ndarray:
    """The box a view of ``obj`` is framed by: its source mesh's bounds for a baked
    representation that keeps them, else its own bounds."""
    source = getattr(obj, "source_bounds", None)
    return np.asarray(source if source is not None else obj.bounds, dtype=np.float64)


def source_box(value, name: str = "source_bounds") -> np.ndarray | None:
    """A representation's world box (``source_bounds``, a relief's ``clip_bounds``) checked:
    a finite (2, 3) float64 (min, max) box with min <= max (flat meshes have flat boxes), or
    None when there is none (not baked from a mesh). Every representation checks it here."""
    if value is None:
        return None
    box = np.asarray(value, dtype=np.float64)
    if box.shape != (2, 3) or not np.isfinite(box).all() or (box[0] > box[1]).any():
        raise UsageError(f"{name} must be finite (min, max) corners with min <= max")
    return box


def orbit_bounds(bounds, azimuth: float, elevation: float, distance: float | None = None,
                 size=DEFAULT_SIZE, fov_deg: float = DEFAULT_FOV) -> Camera:
    """Orbit the box centre at ``distance`` bounding-sphere radii (None: fit the view),
    near/far hugging the box."""
    b = np.asarray(bounds, dtype=np.float64)
    if b.shape != (2, 3) or not np.isfinite(b).all() or np.abs(b).max() > MAX_COORDINATE:
        raise FormatError(f"the input's bounds {_shown(b)} are not finite or exceed "
                          f"{MAX_COORDINATE:g}: no camera can frame them")
    if distance is None:
        distance = fit_distance(size, fov_deg)
    radius = bounds_radius(b)
    d = distance * radius
    near, far = max(d - 1.05 * radius, 0.005 * d), d + 1.05 * radius
    centre = b.mean(axis=0)
    if not (np.isfinite((d, near, far)).all() and 0 < near < far and d > 0
            and far < MAX_COORDINATE and float(np.float32(near)) < float(np.float32(far))):
        raise FormatError(f"cannot place a camera {distance:g} radii from a box of radius "
                          f"{radius:g} (near {near:g}, far {far:g}): use another --view "
                          "distance or check the input's bounds")
    camera = Camera.orbit(tuple(centre), azimuth, elevation, d, fov_deg=fov_deg, size=size,
                          near=near, far=far)
    with np.errstate(all="ignore"):
        finite = np.isfinite(camera.view).all() and np.isfinite(camera.proj).all()
    if not finite:
        raise FormatError(f"the camera for a box of radius {radius:g} has no finite matrices: "
                          "check the input's bounds")
    return camera


def _shown(b: np.ndarray) -> str:
    with np.printoptions(precision=3):
        return str(b.tolist()) if b.size <= 6 else f"of shape {b.shape}"


def turntable(bounds, count: int, elevation: float, distance: float | None, size=DEFAULT_SIZE,
              fov_deg: float = DEFAULT_FOV) -> list[Camera]:
    """``count`` cameras evenly spaced in azimuth around the box."""
    if count < 1 or count > 3600:
        raise UsageError(f"--turntable needs between 1 and 3600 views, got {count}")
    return [orbit_bounds(bounds, 360.0 * k / count, elevation, distance, size, fov_deg)
            for k in range(count)]
