"""`BillboardCloud`: textured rectangles in space (Décoret et al. 2003), their maps in atlases."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...core.transforms import MAX_COORDINATE
from ...errors import UsageError
from ...scene.mesh import RenderMesh
from ...scene.views import source_box
from . import fallback

#: Texels left empty around every rectangle in the atlas, so that bilinear and mipmapped
#: lookups near a rectangle's border never read its neighbour.
GUTTER = 2


@dataclass(eq=False)
class BillboardCloud:
    """Rectangles, each showing the faces within ``epsilon`` of its plane, as seen along it.

    Rectangle p is ``corners[p] + s * u_axes[p] + t * v_axes[p]``, (s, t) in [0, 1]^2; its
    plane's normal ``normalize(u x v)`` faces the side the faces face. Its maps are the atlas
    texels ``rects[p] = (page, x, y, w, h)``: texel (x + i, y + j) of that page holds the
    point s = (i + 0.5) / w, t = (j + 0.5) / h; row 0 of a page is t = 0.

    Attributes
    ----------
    corners, u_axes, v_axes : (P, 3) float64 world.
    rects : (P, 5) int32 atlas placement.
    color : (L, H, W, 4) uint8 sRGB base colour; alpha is the coverage (alpha-tested at 0.5).
    normal : (L, H, W, 3) uint8 world-space unit normals encoded as (n + 1) / 2 * 255.
    epsilon : world distance every face lies within of its rectangle's plane.
    source_bounds : (2, 3) float64 world box of the mesh it was baked from, or None.
    params : the bake's parameters and the generator's report (JSON).
    generation_seconds : how long a fresh bake's plane search took, for its report; not
        stored (a file depends only on its inputs), None once loaded.
    """

    corners: np.ndarray
    u_axes: np.ndarray
    v_axes: np.ndarray
    rects: np.ndarray
    color: np.ndarray
    normal: np.ndarray
    epsilon: float
    source_bounds: np.ndarray | None = None
    params: dict = field(default_factory=dict)
    generation_seconds: float | None = None

    def __post_init__(self) -> None:
        self.corners, self.u_axes, self.v_axes = (
            _vectors(a, name) for a, name in ((self.corners, "corners"),
                                              (self.u_axes, "u_axes"), (self.v_axes, "v_axes")))
        count = len(self.corners)
        if not count or len(self.u_axes) != count or len(self.v_axes) != count:
            raise UsageError("corners, u_axes and v_axes must describe the same P >= 1 "
                             "rectangles")
        cross = np.cross(self.u_axes, self.v_axes)
        sides = np.linalg.norm(self.u_axes, axis=1) * np.linalg.norm(self.v_axes, axis=1)
        if not (np.linalg.norm(cross, axis=1) > 1e-9 * sides).all() or not (sides > 0).all():
            raise UsageError("every rectangle needs two non-parallel sides of non-zero length")
        self.color = np.ascontiguousarray(self.color)
        if self.color.dtype != np.uint8 or self.color.ndim != 4 or self.color.shape[3] != 4 \
                or 0 in self.color.shape:
            raise UsageError(f"color must be an (L, H, W, 4) uint8 atlas, got "
                             f"{self.color.dtype} {self.color.shape}")
        self.normal = np.ascontiguousarray(self.normal)
        if self.normal.dtype != np.uint8 or self.normal.shape != self.color.shape[:3] + (3,):
            raise UsageError(f"normal must be a {self.color.shape[:3] + (3,)} uint8 atlas, "
                             f"got {self.normal.dtype} {self.normal.shape}")
        self.rects = _rects(self.rects, count, self.color.shape[:3])
        self.epsilon = float(self.epsilon)
        if not np.isfinite(self.epsilon) or self.epsilon < 0:
            raise UsageError(f"epsilon must be a finite world distance >= 0, got {self.epsilon}")
        if not (self.color[..., 3] >= 128).any():
            raise UsageError("every texel of the billboard cloud is empty (alpha below 0.5): "
                             "nothing visible to render")
        self.source_bounds = source_box(self.source_bounds)

    @property
    def count(self) -> int:
        """Number of rectangles."""
        return len(self.corners)

    @property
    def normals(self) -> np.ndarray:
        """(P, 3) unit normals of the rectangles' planes."""
        cross = np.cross(self.u_axes, self.v_axes)
        return cross / np.linalg.norm(cross, axis=1, keepdims=True)

    @property
    def rectangle_corners(self) -> np.ndarray:
        """(P, 4, 3) world corners of every rectangle: (0,0), (1,0), (1,1), (0,1) in (s, t)."""
        c, u, v = self.corners[:, None], self.u_axes[:, None], self.v_axes[:, None]
        st = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float64)[None, :, :, None]
        return c + st[:, :, 0] * u + st[:, :, 1] * v

    @property
    def bounds(self) -> np.ndarray:
        """World bounding box of the rectangles."""
        points = self.rectangle_corners.reshape(-1, 3)
        return np.stack([points.min(axis=0), points.max(axis=0)])

    @property
    def center(self) -> np.ndarray:
        return self.bounds.mean(axis=0)

    def fallback_mesh(self, triangles: int = 20_000) -> RenderMesh:
        """What a glTF viewer that knows nothing of reliefkit shows: the rectangles as quads
        textured with the atlas pages (one material each), alpha-tested at the renderer's 0.5
        (MASK), double-sided. Always 2 triangles per rectangle, whatever ``triangles`` says:
        the count is the cloud's."""
        return fallback.fallback_mesh(self)

    def geometric_error(self) -> float:
        """The world distance the cloud may be off the surface: epsilon, every face within
        it of its card (where it projects below one pixel a DMBBC draws this cloud; an LOD
        chain switches to it there, `reliefkit.export.lod`)."""
        return self.epsilon

    def fallback_normal_maps(self) -> dict:
        """The fallback's tangent-space normal map per material (atlas page)."""
        return fallback.fallback_normal_maps(self)

    def memory_bytes(self) -> dict:
        """Bytes of each stored array (the atlases dominate)."""
        return {"color": int(self.color.nbytes), "normal": int(self.normal.nbytes),
                "rectangles": int(self.corners.nbytes + self.u_axes.nbytes
                                  + self.v_axes.nbytes + self.rects.nbytes)}

    def empty_texel_fraction(self) -> float:
        """Fraction of the rectangles' texels that show nothing (alpha below 0.5)."""
        empty = total = 0
        for page, x, y, w, h in self.rects:
            alpha = self.color[page, y:y + h, x:x + w, 3]
            empty += int((alpha < 128).sum())
            total += alpha.size
        return empty / total

    def bake_report(self) -> list[str]:
        """What `reliefkit bake` says of a fresh cloud: planes, faces, skipped, empty texels."""
        gen = self.params.get("generation", {})
        faces = gen.get("faces_per_plane", [])
        lines = [f"billboard cloud: {self.count} planes (faces per plane: "
                 f"{', '.join(map(str, faces))}), {gen.get('skipped', 0)} faces skipped, "
                 f"{100 * self.empty_texel_fraction():.1f}% of the rectangles' texels empty"
                 + ("" if self.generation_seconds is None
                    else f", planes found in {self.generation_seconds:.2f} s")]
        if gen.get("skipped"):
            lines.append(f"warning: {gen['skipped']} faces have no plane: "
                         f"{gen.get('skipped_reason')}")
        return lines

    def summary(self) -> dict:
        lo, hi = self.bounds
        pages, height, width = self.color.shape[:3]
        return {"kind": "billboard-cloud", "rectangles": self.count,
                "atlas": f"{pages} x {width}x{height}", "epsilon": self.epsilon,
                "empty_texel_fraction": round(self.empty_texel_fraction(), 4),
                "bounds_min": lo.tolist(), "bounds_max": hi.tolist(),
                "bytes": self.memory_bytes(), "params": self.params}


def _vectors(array, name: str) -> np.ndarray:
    a = np.ascontiguousarray(array, dtype=np.float64)
    if a.ndim != 2 or a.shape[1] != 3:
        raise UsageError(f"{name} must be a (P, 3) array, got {a.shape}")
    if not np.isfinite(a).all() or (np.abs(a) > MAX_COORDINATE).any():
        raise UsageError(f"{name} must be finite and within {MAX_COORDINATE:g}")
    return a


def _rects(array, count: int, atlas: tuple[int, int, int]) -> np.ndarray:
    """(P, 5) page, x, y, w, h, each rectangle inside its page."""
    rects = np.asarray(array)
    if rects.shape != (count, 5) or not np.issubdtype(rects.dtype, np.integer):
        raise UsageError(f"rects must be ({count}, 5) integers (page, x, y, w, h), got "
                         f"{rects.dtype} {rects.shape}")
    pages, height, width = atlas
    page, x, y, w, h = rects.T.astype(np.int64)
    if (page < 0).any() or (page >= pages).any() or (x < 0).any() or (y < 0).any() \
            or (w < 1).any() or (h < 1).any() or (x + w > width).any() or (y + h > height).any():
        raise UsageError(f"a rectangle's texels lie outside the {pages} x {width}x{height} "
                         "atlas")
    return np.ascontiguousarray(rects, dtype=np.int32)
