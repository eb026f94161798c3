"""`DisplacementMap` (the ``displacement`` kind, §3): a base mesh with a displacement texture,
and its displacement volume as tetrahedra.

Conventions
-----------
The displacement texture is ``color`` (H, W, 4) float32 linear straight alpha and ``height``
(H, W) float32 in [0, 1], sampled as the core's heightfields: ``height[j, i]`` at
texture coordinates s = (i + 0.5) / W, t = (j + 0.5) / H, bilinear between texel centres,
clamped at the border (or wrapped, ``wrap``, for periodic textures that tile). A base vertex
with uv (u, v) reads the texture at (s, t) = (u * tile[0], v * tile[1]). Height 0 is no
displacement: the base itself is the surface there, unless the colour's alpha (bilinear)
is below 0.5, where there is nothing (a projected mesh's background); height 1 moves the
base point by ``scale`` (world units) along the normal interpolated from the vertex normals
(not renormalised, so the volume is exactly the union of the prisms below).

The displacement volume (§3.1, Fig. 3) extrudes every base triangle (p0, p1, p2) along its
vertex normals into a prism with top p_i + scale * n_i; each prism is split into three
tetrahedra, each side quad along the diagonal from its lowest-index vertex, so the faces two
neighbouring prisms share are split the same way (the shell-volume construction). Every
volume vertex carries box coordinates (u, v, h) (uv of its base vertex, h = 0 at the base
and 1 at the top); inside a tetrahedron (u, v, h) and the world position are affine in each
other, so any plane cuts a tetrahedron in a 3- or 4-vertex polygon whose vertices carry the
exact (u, v, h) (`displacement_slices`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...bake.uv_atlas import MAX_MATERIALS, MaterialAtlas, linear_tint
from ...errors import UsageError
from ...scene.mesh import RenderMesh, vertex_normals
from ...scene.views import source_box
from .displacement_fallback import displacement_fallback

MAX_TEXELS = 8192 * 8192
MAX_TILE = 4096.0


@dataclass(eq=False)
class DisplacementMap:
    """A base RenderMesh (uvs and vertex normals) displaced by a texture along its normals.

    base : RenderMesh with uvs.
    color : (H, W, 4) float32 linear RGBA, straight alpha.
    height : (H, W) float32 in [0, 1].
    scale : world length of height 1 along the interpolated normals (> 0).
    tile : (U, V) repeats of the texture over the uvs (> 0).
    wrap : the texture repeats (periodic lookups across its border) instead of clamping.
    params : bake provenance (never anything that changes rendering).
    source_bounds : the box of the mesh it was baked from (None for a heightmap): views
        frame the map by it, as they frame its mesh.
    surface : the base's own materials in its uv space (`reliefkit.bake.uv_atlas`), one
        layer per material of ``base.material``; the texture's colours are multiplied by it
        at the base uv (the surface tints its displacement). None: the texture's colours.
    """

    base: object
    color: np.ndarray
    height: np.ndarray
    scale: float
    tile: tuple = (1.0, 1.0)
    wrap: bool = False
    params: dict = field(default_factory=dict)
    source_bounds: np.ndarray | None = None
    surface: MaterialAtlas | None = None

    def __post_init__(self) -> None:
        base = self.base
        if getattr(base, "uvs", None) is None:
            raise UsageError(f"{getattr(base, 'name', 'base')}: a displacement map needs a "
                             "base mesh with texture coordinates (uvs)")
        if len(base.indices) == 0:
            raise UsageError("a displacement map needs a base with at least one triangle")
        h = np.asarray(self.height)
        c = np.asarray(self.color)
        if h.ndim != 2 or min(h.shape) < 2:
            raise UsageError(f"displacement height must be (H, W) with H, W >= 2, got "
                             f"{h.shape}")
        if h.size > MAX_TEXELS:
            raise UsageError(f"displacement texture has at most {MAX_TEXELS} texels, got "
                             f"{h.shape}")
        if c.shape != (*h.shape, 4):
            raise UsageError(f"displacement colour must be {(*h.shape, 4)} (the height's "
                             f"size, RGBA), got {c.shape}")
        if not np.isfinite(h).all() or h.min() < 0 or h.max() > 1:
            raise UsageError("displacement heights must be finite and in [0, 1]")
        if not np.isfinite(c).all() or c.min() < 0 or c.max() > 1:
            raise UsageError("displacement colours must be finite and in [0, 1]")
        self.height = np.ascontiguousarray(h, np.float32)
        self.color = np.ascontiguousarray(c, np.float32)
        scale = self.scale
        if isinstance(scale, bool) or not isinstance(scale, int | float | np.floating) or not (
                np.isfinite(scale) and scale > 0):
            raise UsageError(f"displacement scale must be a positive number, got {scale!r}")
        self.scale = float(scale)
        tile = tuple(float(t) for t in self.tile)
        if len(tile) != 2 or not all(np.isfinite(t) and 0 < t <= MAX_TILE for t in tile):
            raise UsageError(f"tile must be two numbers in (0, {MAX_TILE:g}], got {self.tile!r}")
        self.tile = tile
        self.wrap = bool(self.wrap)
        self.source_bounds = source_box(self.source_bounds)
        n = np.asarray(base.normals, np.float64)
        if (np.linalg.norm(n, axis=1) < 1e-6).any():
            raise UsageError("the base mesh has zero-length vertex normals")
        if self.surface is not None and len(self.surface.rgba8) <= int(
                np.max(base.material, initial=0)):
            raise UsageError(f"a displacement map's surface has {len(self.surface.rgba8)} "
                             f"material layers, its base uses {int(np.max(base.material)) + 1}")

    # -- geometry --------------------------------------------------------------------------
    @property
    def bounds(self) -> np.ndarray:
        """(2, 3) world box of the displacement volume (base and top)."""
        p = self.base.world_positions
        top = p + self.scale * np.asarray(self.base.normals, np.float64)
        both = np.concatenate([p, top])
        return np.array([both.min(axis=0), both.max(axis=0)])

    @property
    def triangle_count(self) -> int:
        return int(len(self.base.indices))

    def volume(self) -> DisplacementVolume:
        """The prisms of the base split into tetrahedra (see the module docstring)."""
        return displacement_volume(self.base, self.scale)

    def one_polygon_box(self) -> np.ndarray | None:
        """The 4x4 box_to_world (u, v, h) -> world when the base is one flat polygon whose
        uvs are an affine image of it and whose normals are all the same (then the displaced
        surface is a heightfield on that box and `reliefkit.reference.heightfield` is its
        exact reference); None otherwise. Needs tile (1, 1)."""
        if self.tile != (1.0, 1.0):
            return None
        p = self.base.world_positions
        uv = np.asarray(self.base.uvs, np.float64)
        n = np.asarray(self.base.normals, np.float64)
        if not np.allclose(n, n[0], atol=1e-6):
            return None
        # p = o + U u + V v  (least squares), then check it is exact
        a = np.c_[np.ones(len(uv)), uv]
        coef, *_ = np.linalg.lstsq(a, p, rcond=None)
        extent = float(np.abs(p - p.mean(axis=0)).max()) or 1.0
        if np.abs(a @ coef - p).max() > 1e-6 * extent:
            return None
        o, du, dv = coef
        dh = self.scale * n[0]
        m = np.eye(4)
        m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = du, dv, dh, o
        if abs(np.linalg.det(m[:3, :3])) < 1e-12 * max(np.abs(m[:3, :3]).max(), 1e-300) ** 3:
            return None
        return m

    # -- the texture on the CPU ------------------------------------------------------------
    def sample_height(self, u, v) -> np.ndarray:
        """Height at base uvs (u, v) (arrays), bilinear between texel centres, clamped or
        wrapped as the shader samples it."""
        return bilinear(self.height, np.asarray(u, np.float64) * self.tile[0],
                        np.asarray(v, np.float64) * self.tile[1], self.wrap)

    def surface_layers(self) -> np.ndarray:
        """(F,) int64 the `surface` layer of each base triangle (its material; 0 without a
        surface)."""
        if self.surface is None:
            return np.zeros(self.triangle_count, np.int64)
        return np.asarray(self.base.material, np.int64)

    def tint(self, uv, triangle) -> np.ndarray:
        """(..., 3) the surface's linear colour at base uvs ``uv`` (..., 2) on base triangles
        ``triangle`` (...), as the renderer samples it; 1 without a surface."""
        uv = np.asarray(uv, np.float64)
        if self.surface is None:
            return np.ones((*uv.shape[:-1], 3))
        return linear_tint(self.surface, uv, self.surface_layers()[triangle])

    def sample_color(self, u, v) -> np.ndarray:
        u = np.asarray(u, np.float64) * self.tile[0]
        v = np.asarray(v, np.float64) * self.tile[1]
        return np.stack([bilinear(self.color[..., k], u, v, self.wrap) for k in range(4)],
                        axis=-1)

    def displaced_lattice(self, subdivisions: int) -> DisplacedLattice:
        """Every base triangle cut into ``subdivisions``^2 triangles, each lattice vertex
        moved by height(uv) * scale along the linearly interpolated normal (the volume's own
        parametrisation); vertices are not shared between base triangles."""
        n = int(subdivisions)
        if n < 1 or n > 256:
            raise UsageError(f"subdivisions must be in [1, 256], got {subdivisions!r}")
        base = self.base
        tris = np.asarray(base.indices, np.int64)
        p = base.world_positions[tris]
        nn = np.asarray(base.normals, np.float64)[tris]
        uv = np.asarray(base.uvs, np.float64)[tris]
        # barycentric lattice points of one triangle, and its small triangles
        ij = [(i, j) for i in range(n + 1) for j in range(n + 1 - i)]
        index = {k: m for m, k in enumerate(ij)}
        bary = np.array([(n - i - j, i, j) for i, j in ij], np.float64) / n
        small = []
        for i in range(n):
            for j in range(n - i):
                small.append((index[(i, j)], index[(i + 1, j)], index[(i, j + 1)]))
                if i + j < n - 1:
                    small.append((index[(i + 1, j)], index[(i + 1, j + 1)],
                                  index[(i, j + 1)]))
        small = np.array(small, np.int64)
        pts = np.einsum("kb,tbx->tkx", bary, p)
        nrm = np.einsum("kb,tbx->tkx", bary, nn)
        uvs = np.einsum("kb,tbx->tkx", bary, uv)
        hgt = self.sample_height(uvs[..., 0], uvs[..., 1])
        moved = (pts + (hgt * self.scale)[..., None] * nrm).reshape(-1, 3)
        count = len(bary)
        faces = (small[None, :, :] + count * np.arange(len(tris))[:, None, None]).reshape(-1, 3)
        return DisplacedLattice(moved, faces, uvs.reshape(-1, 2),
                                np.repeat(np.arange(len(tris)), count), pts.reshape(-1, 3))

    def lattice_colors(self, lattice: DisplacedLattice) -> np.ndarray:
        """(V, 4) linear RGBA at the lattice's vertices as the renderer colours them: the
        texture's colour tinted by the surface, alpha the texture's (below 0.5: nothing)."""
        uv = lattice.uvs
        colors = np.clip(self.sample_color(uv[:, 0], uv[:, 1]), 0, 1)
        colors[:, :3] *= self.tint(uv, lattice.triangle)
        return colors

    def displaced_mesh(self, subdivisions: int = 16):
        """The displaced surface as a fine RenderMesh (ground truth for coverage tests): the
        `displaced_lattice`, coloured from the colour texture."""
        lattice = self.displaced_lattice(subdivisions)
        colors = self.lattice_colors(lattice)
        colors[:, 3] = 1.0
        normals = vertex_normals(lattice.positions, lattice.faces)
        return RenderMesh(lattice.positions, lattice.faces, normals, colors.astype(np.float32),
                          lattice.uvs, name=f"{self.base.name} displaced")

    def fallback_mesh(self, triangles: int = 20_000) -> RenderMesh:
        """What a glTF viewer that knows nothing of reliefkit shows: the displaced surface,
        every base triangle cut as finely as ``triangles`` allows, coloured per vertex as the
        kind draws it. A base with more triangles than that keeps one per base triangle
        (`displacement_fallback`)."""
        return displacement_fallback(self, triangles)

    def bake_report(self) -> list[str]:
        h, w = self.height.shape
        lines = [f"displacement map: {self.triangle_count} base triangles, texture {w}x{h} "
                 f"'{self.params.get('texture', '?')}', scale {self.scale:.4g}, tile "
                 f"{self.tile[0]:g}x{self.tile[1]:g}{', wrapped' if self.wrap else ''}"]
        dropped, left_out = (self.params.get(k, 0) for k in ("dropped_triangles",
                                                              "materials_left_out"))
        if dropped:
            lines.append(f"warning: {dropped} triangles were left out of the base (no area in "
                         "space or in uv)")
        if self.surface is not None:
            lines.append(f"the surface's {len(self.surface.rgba8)} material(s) tint the "
                         "displacement")
        if left_out:
            lines.append(f"warning: the surface's {left_out} materials are left out (at most "
                         f"{MAX_MATERIALS} tint a displacement); it keeps the texture's "
                         "colours")
        return lines


def bilinear(image: np.ndarray, s, t, wrap: bool) -> np.ndarray:
    """``image`` (H, W) at texture coordinates (s, t): bilinear between texel centres,
    clamped at the border (as `reference.heightfield`) or wrapped."""
    hh, ww = image.shape
    x = np.asarray(s, np.float64) * ww - 0.5
    y = np.asarray(t, np.float64) * hh - 0.5
    if not wrap:
        x = np.clip(x, 0.0, ww - 1.0)
        y = np.clip(y, 0.0, hh - 1.0)
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = x - x0, y - y0
    x0, y0 = x0.astype(np.int64), y0.astype(np.int64)
    if wrap:
        x0, y0 = x0 % ww, y0 % hh
        x1, y1 = (x0 + 1) % ww, (y0 + 1) % hh
    else:
        x1, y1 = np.minimum(x0 + 1, ww - 1), np.minimum(y0 + 1, hh - 1)
    img = np.asarray(image, np.float64)
    top = img[y0, x0] * (1 - fx) + img[y0, x1] * fx
    bottom = img[y1, x0] * (1 - fx) + img[y1, x1] * fx
    return top * (1 - fy) + bottom * fy


@dataclass(frozen=True, eq=False)
class DisplacedLattice:
    """Points of the displaced surface over a lattice of each base triangle.

    positions : (V, 3) float64 world; faces : (F, 3) int64; uvs : (V, 2) float64 base uvs;
    triangle : (V,) int64 the base triangle of each vertex; base : (V, 3) float64 world, the
    point on the base each vertex was moved from.
    """

    positions: np.ndarray
    faces: np.ndarray
    uvs: np.ndarray
    triangle: np.ndarray
    base: np.ndarray


@dataclass(frozen=True, eq=False)
class DisplacementVolume:
    """The tetrahedra of a displacement volume.

    positions : (2V, 3) float64 world; vertex i < V is base vertex i, V + i its top.
    box : (2V, 3) float64 (u, v, h) of each volume vertex.
    tets : (3F, 4) int64 vertex indices, tetrahedra 3f .. 3f + 2 from base triangle f.
    jacobian : (3F, 3, 3) float64 d(world)/d(u, v, h) per tetrahedron (columns).
    prism_of : (3F,) int64 base triangle of each tetrahedron.
    """

    positions: np.ndarray
    box: np.ndarray
    tets: np.ndarray
    jacobian: np.ndarray
    prism_of: np.ndarray

    def total_volume(self) -> float:
        p = self.positions[self.tets]
        d = p[:, 1:] - p[:, :1]
        return float(np.abs(np.linalg.det(d)).sum() / 6.0)


def prism_tets(tris: np.ndarray, vertex_count: int) -> np.ndarray:
    """(3F, 4) tetrahedra of the prisms over ``tris`` (base vertex i, top vertex V + i).

    Each prism (a, b, c) is sorted so a < b < c; every side quad is then split along the
    diagonal from its lowest-index base vertex to the top of the other, which two prisms
    sharing that side choose alike: tetrahedra (a, b, c, c'), (a, b, b', c'), (a, a', b', c').
    """
    s = np.sort(np.asarray(tris, np.int64), axis=1)
    a, b, c = s[:, 0], s[:, 1], s[:, 2]
    at, bt, ct = a + vertex_count, b + vertex_count, c + vertex_count
    out = np.stack([np.stack([a, b, c, ct], 1), np.stack([a, b, bt, ct], 1),
                    np.stack([a, at, bt, ct], 1)], axis=1)
    return out.reshape(-1, 4)


def displacement_volume(base, scale: float) -> DisplacementVolume:
    p = base.world_positions
    n = np.asarray(base.normals, np.float64)
    uv = np.asarray(base.uvs, np.float64)
    count = len(p)
    positions = np.concatenate([p, p + scale * n])
    box = np.concatenate([np.c_[uv, np.zeros(count)], np.c_[uv, np.ones(count)]])
    tris = np.asarray(base.indices, np.int64)
    tets = prism_tets(tris, count)
    prism_of = np.repeat(np.arange(len(tris)), 3)
    dp = positions[tets[:, 1:]] - positions[tets[:, :1]]   # (T, 3 edges, 3)
    dq = box[tets[:, 1:]] - box[tets[:, :1]]
    # world = J q: dp^T = J dq^T  =>  J = dp^T inv(dq^T)
    det = np.linalg.det(dq)
    good = np.abs(det) > 1e-14
    jac = np.zeros((len(tets), 3, 3))
    if good.any():
        jac[good] = np.swapaxes(dp[good], 1, 2) @ np.linalg.inv(np.swapaxes(dq[good], 1, 2))
    return DisplacementVolume(positions, box, tets, jac, prism_of)
