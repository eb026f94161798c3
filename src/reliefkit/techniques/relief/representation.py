"""`ReliefTexture`: a texture with depth over the bottom face of a box (or a reverse frustum)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...core.transforms import (
    MAX_COORDINATE,
    box_center,
    invert_box,
    transform_points,
    translation,
    unit_cube_corners,
)
from ...errors import UsageError
from ...scene.mesh import RenderMesh
from ...scene.views import source_box


@dataclass(eq=False)
class ReliefTexture:
    """A heightfield with colour and normals, mapped into the world by ``box_to_world``.

    Box coordinates are (u, v, h) in [0, 1]^3. ``height[j, i]`` is the surface height at
    u = (i + 0.5) / W, v = (j + 0.5) / H, interpolated bilinearly between texel centres and
    clamped at the border; the solid lies below the surface. Height 0 means *empty*: a ray
    that reaches the bottom face where the height is 0 misses (so the bottom face of the box
    is not drawn), which is why bakes keep a ring of zero texels around the footprint.

    Attributes
    ----------
    height : (H, W) float32 in [0, 1].
    color : (Hc, Wc, 4) uint8 sRGB base colour with alpha; its own resolution (§4.3).
    normal : (Hc, Wc, 3) float32 world-space unit normals, at the colour resolution.
    box_to_world : (4, 4) float64 map from box coordinates to world (projective for a
        reverse-perspective frustum; affine for a box).
    safety : (H, W) uint8/uint16 safety radii in texels, or (8, H, W): one radius per
        projected-direction octant (`safety.octant`); or None (then the robust method
        cannot render it).
    clip_bounds : (2, 3) float64 world box (min, max corner) that the drawn proxy is cut to
        (§4.1: fewer fragments for a frustum), or None to draw the whole box.
    source_bounds : (2, 3) float64 world bounding box of the mesh it was baked from, or None;
        views frame a representation by it, so a mesh and its bakes share one camera.
    params : bake parameters (JSON), kept in the .rk manifest.
    """

    height: np.ndarray
    color: np.ndarray
    normal: np.ndarray
    box_to_world: np.ndarray
    safety: np.ndarray | None = None
    clip_bounds: np.ndarray | None = None
    source_bounds: np.ndarray | None = None
    params: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.height = np.ascontiguousarray(self.height, dtype=np.float32)
        if self.height.ndim != 2 or min(self.height.shape) < 2:
            raise UsageError(f"height must be an (H, W) array with H, W >= 2, got "
                             f"{self.height.shape}")
        if not np.isfinite(self.height).all() or self.height.min() < 0 or self.height.max() > 1:
            raise UsageError("height values must be finite and within [0, 1]")
        if not self.height.any():
            raise UsageError("the heightfield is empty (every height is 0): nothing visible "
                             "to render")
        self.color = np.ascontiguousarray(self.color, dtype=np.uint8)
        if self.color.ndim != 3 or self.color.shape[2] != 4:
            raise UsageError(f"color must be (H, W, 4) uint8, got {self.color.shape}")
        self.normal = np.ascontiguousarray(self.normal, dtype=np.float32)
        if self.normal.shape != self.color.shape[:2] + (3,):
            raise UsageError(f"normal must be {self.color.shape[:2] + (3,)}, got "
                             f"{self.normal.shape}")
        self.box_to_world = _checked_box(self.box_to_world)
        if self.safety is not None:
            self.safety = np.ascontiguousarray(self.safety)
            if self.safety.shape not in (self.height.shape, (8, *self.height.shape)) or \
                    self.safety.dtype not in (np.uint8, np.uint16):
                raise UsageError("safety must be uint8/uint16 with the height's shape (H, W), "
                                 "or (8, H, W) for one radius per direction octant")
            # a jump of max(W, H) centrelines crosses the whole field: larger radii are noise
            limit = max(MAX_UINT8_RADIUS, *self.height.shape)
            if int(self.safety.max()) > limit:
                raise UsageError(f"safety radii up to {int(self.safety.max())} texels on a "
                                 f"{self.height.shape[1]}x{self.height.shape[0]} heightfield; "
                                 f"at most {limit} make sense")
        self.clip_bounds = source_box(self.clip_bounds, "clip_bounds")
        self.source_bounds = source_box(self.source_bounds)
        if self.clip_bounds is not None:
            corners = self.corners
            lo = np.maximum(corners.min(axis=0), self.clip_bounds[0])
            hi = np.minimum(corners.max(axis=0), self.clip_bounds[1])
            if (lo >= hi).any():
                raise UsageError("clip_bounds do not overlap the relief's box: nothing would "
                                 "be drawn")

    @property
    def depth_resolution(self) -> tuple[int, int]:
        """(W, H) of the height texture."""
        return self.height.shape[1], self.height.shape[0]

    @property
    def color_resolution(self) -> tuple[int, int]:
        return self.color.shape[1], self.color.shape[0]

    @property
    def world_to_box(self) -> np.ndarray:
        return invert_box(self.box_to_world)

    @property
    def corners(self) -> np.ndarray:
        """(8, 3) world positions of the box (frustum) corners, index = u + 2v + 4h."""
        return transform_points(self.box_to_world, unit_cube_corners())

    @property
    def center(self) -> np.ndarray:
        """World point at the centre of the box (frustum): box coordinates (0.5, 0.5, 0.5)."""
        return box_center(self.box_to_world)

    @property
    def bounds(self) -> np.ndarray:
        """World bounding box: of the box (frustum), cut to ``clip_bounds``."""
        c = self.corners
        lo, hi = c.min(axis=0), c.max(axis=0)
        if self.clip_bounds is not None:
            lo, hi = np.maximum(lo, self.clip_bounds[0]), np.minimum(hi, self.clip_bounds[1])
        return np.stack([lo, hi])

    def to_world(self, uvh: np.ndarray) -> np.ndarray:
        """Box coordinates (..., 3) -> world positions (..., 3)."""
        return transform_points(self.box_to_world, uvh)

    def to_box(self, world: np.ndarray) -> np.ndarray:
        """World positions (..., 3) -> box coordinates (..., 3)."""
        return transform_points(self.world_to_box, world)

    def fallback_mesh(self, triangles: int = 20_000) -> RenderMesh:
        """What a glTF viewer that knows nothing of reliefkit shows: the heightfield
        triangulated at the finest grid within ``triangles``, mapped through
        ``box_to_world``, cut to ``clip_bounds``, textured by ``color`` (`fallback`)."""
        from .fallback import relief_fallback  # the reference's numba: slow to import

        return relief_fallback(self, triangles)

    def memory_bytes(self) -> dict:
        """Bytes of each array as stored."""
        arrays = {"height": self.height, "color": self.color, "normal": self.normal}
        if self.safety is not None:
            arrays["safety"] = self.safety
        return {name: int(a.nbytes) for name, a in arrays.items()}

    def summary(self) -> dict:
        w, h = self.depth_resolution
        cw, ch = self.color_resolution
        lo, hi = self.bounds
        return {"kind": "relief", "depth_resolution": f"{w}x{h}",
                "color_resolution": f"{cw}x{ch}", "has_safety": self.safety is not None,
                "bounds_min": lo.tolist(), "bounds_max": hi.tolist(),
                "bytes": self.memory_bytes(), "params": self.params}


MAX_UINT8_RADIUS = 255   # what bakes store in uint8, whatever the field's size
MAX_CONDITION = 1e12     # box_to_world this ill-conditioned loses the box in rounding
MIN_EXTENT = 1e-20       # a smaller box underflows in float32 on the GPU


def _checked_box(matrix) -> np.ndarray:
    """box_to_world: finite, well conditioned, its corners finite and in front (w > 0).

    w is affine in box coordinates, so w > 0 at the eight corners means w > 0 everywhere in
    the box: a projective box never contains its plane at infinity.
    """
    m = np.asarray(matrix, dtype=np.float64)
    if m.shape != (4, 4) or not np.isfinite(m).all():
        raise UsageError("box_to_world must be a finite 4x4 matrix")
    with np.errstate(all="ignore"):
        centre = m @ [0.5, 0.5, 0.5, 1.0]
        centre = centre[:3] / centre[3] if np.isfinite(centre[:3] / centre[3]).all() else 0.0
        # conditioned as drawn: relative to the box (camera-relative rendering), wherever it is
        condition = np.linalg.cond(translation(-centre) @ m)
        corners = np.c_[unit_cube_corners(), np.ones(8)] @ m.T
    if not np.isfinite(condition) or condition > MAX_CONDITION:
        raise UsageError(f"box_to_world is singular or badly conditioned (condition number "
                         f"{condition:.3g}); the box cannot be drawn")
    w = corners[:, 3]
    if not (w > 0).all() and not (w < 0).all():
        raise UsageError("box_to_world maps part of the box beyond the plane at infinity "
                         "(w changes sign inside the box)")
    points = corners[:, :3] / w[:, None]
    extent = float(np.ptp(points, axis=0).max())
    reach = float(np.abs(points).max())
    if not np.isfinite(points).all() or reach > MAX_COORDINATE or extent <= reach * 1e-12 \
            or extent < MIN_EXTENT:
        raise UsageError(f"box_to_world puts the box at {reach:.3g} from the origin with a "
                         f"size of {extent:.3g}; it cannot be drawn there")
    return m


@dataclass(eq=False)
class ReliefObject:
    """Several relief textures drawn together (the six frusta of a cube, §4.2)."""

    parts: list[ReliefTexture]
    params: dict = field(default_factory=dict)
    source_bounds: np.ndarray | None = None

    def __post_init__(self) -> None:
        if not self.parts or not all(isinstance(p, ReliefTexture) for p in self.parts):
            raise UsageError("a relief object needs one or more ReliefTexture parts")
        self.source_bounds = source_box(self.source_bounds)

    @property
    def bounds(self) -> np.ndarray:
        b = np.stack([p.bounds for p in self.parts])
        return np.stack([b[:, 0].min(axis=0), b[:, 1].max(axis=0)])

    def fallback_mesh(self, triangles: int = 20_000) -> RenderMesh:
        """What a glTF viewer that knows nothing of reliefkit shows: every part's heightfield
        triangulated, ``triangles`` shared out by their texels, with the curtains the
        parts draw between near and far surfaces (`fallback`)."""
        from .fallback import relief_object_fallback  # the reference's numba: slow to import

        return relief_object_fallback(self, triangles)

    def summary(self) -> dict:
        return {"kind": "relief-object", "parts": len(self.parts),
                "part_summaries": [p.summary() for p in self.parts], "params": self.params}
