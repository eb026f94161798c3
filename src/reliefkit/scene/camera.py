"""Cameras: look-at and orbit placement, perspective and orthographic projection.

Matrices follow OpenGL conventions: column vectors, right-handed eye space looking down -z,
clip space depth in [-1, 1], window depth in [0, 1]. A pixel (row r, column c) of an image
is the ray through window coordinates (c + 0.5, H - 1 - r + 0.5); row 0 is the top row.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.transforms import transform_points
from ..errors import UsageError


def look_at(eye, target, up=(0.0, 1.0, 0.0)) -> np.ndarray:
    """4x4 view matrix placing the eye at ``eye`` looking at ``target``."""
    eye, target, up = (np.asarray(a, dtype=np.float64) for a in (eye, target, up))
    forward = target - eye
    if np.linalg.norm(forward) == 0:
        raise UsageError("camera eye and target coincide")
    f = forward / np.linalg.norm(forward)
    side = np.cross(f, up)
    if np.linalg.norm(side) < 1e-9:  # looking straight along `up`: pick another up vector
        side = np.cross(f, [0.0, 0.0, -1.0] if abs(f[1]) > 0.5 else [0.0, 1.0, 0.0])
    s = side / np.linalg.norm(side)
    u = np.cross(s, f)
    view = np.eye(4)
    view[0, :3], view[1, :3], view[2, :3] = s, u, -f
    view[:3, 3] = -view[:3, :3] @ eye
    return view


def perspective(fov_y_deg: float, aspect: float, near: float, far: float) -> np.ndarray:
    """4x4 OpenGL perspective projection (gluPerspective)."""
    f = 1.0 / np.tan(np.radians(fov_y_deg) / 2.0)
    proj = np.zeros((4, 4))
    proj[0, 0], proj[1, 1] = f / aspect, f
    proj[2, 2] = (far + near) / (near - far)
    proj[2, 3] = 2.0 * far * near / (near - far)
    proj[3, 2] = -1.0
    return proj


def orthographic(half_height: float, aspect: float, near: float, far: float) -> np.ndarray:
    """4x4 OpenGL orthographic projection of a view volume ``2*half_height`` tall."""
    proj = np.eye(4)
    proj[0, 0] = 1.0 / (half_height * aspect)
    proj[1, 1] = 1.0 / half_height
    proj[2, 2] = -2.0 / (far - near)
    proj[2, 3] = -(far + near) / (far - near)
    return proj


@dataclass(frozen=True)
class Camera:
    """A pinhole (or orthographic) camera with its image size.

    ``ortho_height`` set (the half height of the view volume in world units) makes the
    camera orthographic; otherwise ``fov_deg`` is the vertical field of view.
    """

    eye: tuple
    target: tuple
    up: tuple = (0.0, 1.0, 0.0)
    fov_deg: float = 40.0
    size: tuple = (256, 256)
    near: float = 0.01
    far: float = 100.0
    ortho_height: float | None = None

    def __post_init__(self) -> None:
        w, h = self.size
        if int(w) != w or int(h) != h or w < 1 or h < 1:
            raise UsageError(f"image size must be positive integers, got {self.size}")
        object.__setattr__(self, "size", (int(w), int(h)))
        if not 0 < self.near < self.far:
            raise UsageError(f"need 0 < near < far, got near={self.near}, far={self.far}")
        if self.ortho_height is None and not 0 < self.fov_deg < 180:
            raise UsageError(f"field of view must be in (0, 180) degrees, got {self.fov_deg}")
        for label in ("eye", "target", "up"):
            vec = np.asarray(getattr(self, label), dtype=np.float64)
            if vec.shape != (3,) or not np.isfinite(vec).all():
                raise UsageError(f"camera {label} must be 3 finite numbers")
            object.__setattr__(self, label, tuple(float(x) for x in vec))

    @classmethod
    def orbit(cls, target, azimuth_deg: float, elevation_deg: float, distance: float,
              fov_deg: float = 40.0, size=(256, 256), *, near: float | None = None,
              far: float | None = None, ortho_height: float | None = None) -> Camera:
        """Orbit ``target`` at ``distance``: azimuth about +y from +z towards +x, elevation
        above the xz plane. ``near``/``far`` default to distance/100 and distance*10."""
        if not distance > 0:
            raise UsageError(f"orbit distance must be positive, got {distance}")
        az, el = np.radians(azimuth_deg), np.radians(elevation_deg)
        offset = distance * np.array([np.cos(el) * np.sin(az), np.sin(el), np.cos(el) * np.cos(az)])
        eye = np.asarray(target, dtype=np.float64) + offset
        return cls(eye=tuple(eye), target=tuple(target), fov_deg=fov_deg, size=tuple(size),
                   near=near if near is not None else distance / 100.0,
                   far=far if far is not None else distance * 10.0, ortho_height=ortho_height)

    @property
    def width(self) -> int:
        return self.size[0]

    @property
    def height(self) -> int:
        return self.size[1]

    @property
    def aspect(self) -> float:
        return self.size[0] / self.size[1]

    @property
    def orthographic(self) -> bool:
        return self.ortho_height is not None

    @property
    def origin(self) -> np.ndarray:
        """The point shaders measure world space from (`gl.uniforms.camera_uniforms`): the
        target, so that float32 keeps full precision around what the camera looks at."""
        return np.asarray(self.target, dtype=np.float64)

    @property
    def view(self) -> np.ndarray:
        """World -> eye 4x4 matrix."""
        return look_at(self.eye, self.target, self.up)

    @property
    def proj(self) -> np.ndarray:
        """Eye -> clip 4x4 matrix."""
        if self.orthographic:
            return orthographic(self.ortho_height, self.aspect, self.near, self.far)
        return perspective(self.fov_deg, self.aspect, self.near, self.far)

    @property
    def viewport(self) -> np.ndarray:
        """(x, y, width, height) as GL's glViewport takes it."""
        return np.array([0, 0, self.size[0], self.size[1]], dtype=np.int32)

    def pixel_rays(self) -> tuple[np.ndarray, np.ndarray]:
        """World-space ray origins and unit directions per pixel, (H, W, 3) each, row 0 on top."""
        near, far = pixel_segments(self)
        d = far - near
        return near, d / np.linalg.norm(d, axis=-1, keepdims=True)


def pixel_segments(camera) -> tuple[np.ndarray, np.ndarray]:
    """World points where each pixel's ray meets the near and the far plane, (H, W, 3) each,
    row 0 on top; for any camera with ``view``, ``proj`` and ``size``."""
    w, h = camera.size
    cols, rows = np.meshgrid(np.arange(w) + 0.5, np.arange(h) + 0.5)
    ndc_x = 2.0 * cols / w - 1.0
    ndc_y = 1.0 - 2.0 * rows / h  # row 0 is the top of the image
    inv = np.linalg.inv(np.asarray(camera.proj) @ np.asarray(camera.view))
    return tuple(transform_points(inv, np.stack([ndc_x, ndc_y, np.full_like(ndc_x, z)], axis=-1))
                 for z in (-1.0, 1.0))


@dataclass(frozen=True, eq=False)
class MatrixCamera:
    """A camera given directly by its matrices (projective ``view`` allowed), for baking.

    Shading treats it as orthographic looking along ``view_dir`` (scene towards viewer).
    ``origin`` is the world point shaders measure from (see `Camera.origin`), e.g. the
    centre of the baked box.
    """

    view: np.ndarray
    proj: np.ndarray
    size: tuple
    view_dir: tuple = (0.0, 0.0, 1.0)
    near: float = 0.0
    origin: tuple = (0.0, 0.0, 0.0)

    orthographic = True

    @property
    def eye(self) -> tuple:
        return tuple(float(x) for x in self.view_dir)

    @property
    def target(self) -> tuple:
        return (0.0, 0.0, 0.0)

    @property
    def viewport(self) -> np.ndarray:
        return np.array([0, 0, self.size[0], self.size[1]], dtype=np.int32)
