"""Mesh -> 3D grid on the GPU: surface voxels (open geometry too) or solids (closed meshes).

The box is the unit cube (u, v, h) mapped to world by an affine ``box_to_world``; the grid
has W x H x D voxels along u, v, h and its arrays are indexed ``[h, v, u]`` (the 3D texture
contract: numpy C order = GL width u, height v, depth w). Voxel (k, j, i) is the box cell
``[i/W, (i+1)/W) x [j/H, (j+1)/H) x [k/D, (k+1)/D)``.

How it works. A voxel column is an axis-parallel *sample line*; with supersampling ``s``
each voxel is crossed by ``s x s`` lines along each of the three box axes. For each axis the
box is cut into slabs one voxel thick and the mesh is rasterized once per slab, looking
along the axis, at ``s`` pixels per voxel: a pixel is a line, and its fragments are the
surface crossings of that line inside the slab (half-open slab bounds, so a crossing is
counted in exactly one voxel). Additive blending sums colour, normal and the number of
crossings per line. Three axes are needed because a triangle seen edge-on from one axis
produces no fragments there; the other two see it.

Solid mode also counts, along the h lines, the surfaces above each of the ``s`` sub-points
of a voxel (+1 where the surface faces up, -1 where it faces down, by ``gl_FrontFacing``):
the sum is the winding number of the point, the ray-crossing test of a closed mesh.

Only triangles that reach a slab are drawn for it (triangles are bucketed per slab on the
CPU), so the cost grows with the mesh size plus the number of slabs, not their product.
"""

from __future__ import annotations

import operator
from dataclasses import dataclass, field

import numpy as np

from ..core.transforms import invert_box
from ..errors import GPUError, UsageError
from ..gl.context import bind_home_framebuffer, check_framebuffer_size, check_gl_error, get_context
from ..gl.shaders import program
from ..gl.textures import read_rgba, texture2d
from ..gl.uniforms import set_uniforms
from ..render.mesh import material_uniforms
from ..scene.mesh import RenderMesh

MODES = ("surface", "solid")
RULES = ("nonzero", "parity")
MAX_SUPERSAMPLE = 4          # solid mode has s + 1 <= 8 count channels (two attachments)
DEFAULT_SUPERSAMPLE = 2
MAX_VOXELS = 1 << 24         # 256^3; the grid's float arrays take 40 bytes per voxel
MAX_SLAB_ENTRIES = 1 << 24   # triangle-slab pairs bucketed; above this every slab draws all
_FAR = 1e30                  # an unused threshold channel (never reached)
_EDGE_EPS = 1e-4             # box units: widen a triangle's slab range against rounding
WHITE_TEXEL = np.full((1, 1, 4), 255, np.uint8)  # the texture of a material without an image

# For each sweep axis, the box axes that become the image's x', y' and the slab axis z'.
# Cyclic permutations keep the frame right-handed, so facing means the same in every sweep.
SWEEPS = {"h": (0, 1, 2), "u": (1, 2, 0), "v": (2, 0, 1)}


@dataclass(eq=False)
class VoxelGrid:
    """A mesh sampled on a W x H x D grid over an affine box; arrays indexed [h, v, u].

    Attributes
    ----------
    occupancy : (D, H, W) float32 in [0, 1]. ``surface`` in surface mode; in solid mode
        ``max(surface, inside)`` (the surface layer plus the interior).
    color : (D, H, W, 4) float32 linear straight-alpha base colour (vertex colour times
        texture): the alpha-weighted mean over the surface crossings inside the voxel; in
        solid mode interior voxels copy the nearest surface voxel. 0 where empty.
    normal : (D, H, W, 3) float32 world-space unit normal, the mean of the mesh's (shading)
        normals at those crossings; interior voxels copy the nearest surface voxel. 0 where
        empty, or where opposite normals cancel exactly (both sides of a thin sheet).
    box_to_world : (4, 4) affine map from the unit box (u, v, h) to world.
    surface : (D, H, W) float32 surface coverage: for each of the three axes, the fraction
        of the voxel's ``s x s`` sample lines along that axis that cross the surface inside
        the voxel; the maximum over the axes. It is the covered fraction of the voxel's face
        seen along the axis that sees the surface best, so 1 when a face crosses the whole
        voxel and > 0 exactly when some sample line meets the surface inside the voxel.
    inside : (D, H, W) float32 or None. Solid mode: the fraction of the voxel's ``s^3``
        sub-points (a regular grid at sub-cell centres) inside the mesh by ``params["rule"]``
        along +h: an estimate of the voxel's volume fraction inside. None in surface mode.
    params : how it was made (mode, supersample, rule, resolution).
    """

    occupancy: np.ndarray
    color: np.ndarray
    normal: np.ndarray
    box_to_world: np.ndarray
    surface: np.ndarray
    inside: np.ndarray | None = None
    params: dict = field(default_factory=dict)

    @property
    def resolution(self) -> tuple[int, int, int]:
        """(W, H, D): voxels along u, v, h."""
        d, h, w = self.occupancy.shape
        return w, h, d

    def centres(self) -> np.ndarray:
        """(D, H, W, 3) world-space voxel centres."""
        w, h, d = self.resolution
        k, j, i = np.meshgrid(*((np.arange(n) + 0.5) / n for n in (d, h, w)), indexing="ij")
        uvh = np.stack([i, j, k], -1)
        return uvh @ self.box_to_world[:3, :3].T + self.box_to_world[:3, 3]


def voxelize(mesh: RenderMesh, box_to_world, resolution, *, mode: str = "surface",
             supersample: int = DEFAULT_SUPERSAMPLE, rule: str = "nonzero",
             alpha_cutoff: float = 0.0, ctx=None, progress=None) -> VoxelGrid:
    """Voxelize ``mesh`` over the box ``box_to_world`` at ``resolution`` = (W, H, D).

    ``mode="surface"`` marks the voxels the surface passes through (open meshes, leaves,
    single quads); ``mode="solid"`` adds the interior of a closed mesh, by the winding number
    (``rule="nonzero"``: needs consistent orientation, lets closed parts overlap) or by
    crossing parity (``rule="parity"``: ignores orientation). ``supersample`` (1..4) is the
    number of sample lines per voxel side; see :class:`VoxelGrid` for what the numbers mean.
    Surface points whose base alpha is <= ``alpha_cutoff`` are holes (the transparent parts
    of cut-out leaves): they add no surface, colour or normal (the winding still counts
    them, so a closed mesh stays solid).
    ``progress(done, total)`` is called after each slab. Raises UsageError for bad arguments
    or when nothing of the mesh is found inside the box, GPUError for GL limits.
    """
    if not isinstance(mesh, RenderMesh):
        raise UsageError(f"voxelize needs a RenderMesh, got {type(mesh).__name__} "
                         "(load it with reliefkit.load_mesh)")
    if mode not in MODES:
        raise UsageError(f"voxelize mode must be one of {', '.join(MODES)}; got {mode!r}")
    if rule not in RULES:
        raise UsageError(f"voxelize rule must be one of {', '.join(RULES)}; got {rule!r}")
    box_to_world = _check_box(box_to_world)
    size = _check_resolution(resolution)
    s = _check_int(supersample, "supersample", 1, MAX_SUPERSAMPLE)
    if not (isinstance(alpha_cutoff, (int, float, np.floating)) and 0 <= alpha_cutoff < 1):
        raise UsageError(f"alpha_cutoff must be a number in [0, 1), got {alpha_cutoff!r}")
    ctx = ctx or get_context()
    _check_gl_limits(ctx, size, s)

    sweeps = _Sweeps(ctx, mesh, box_to_world, size, s, mode == "solid", rule,
                     float(alpha_cutoff), progress)
    surface, color_sum, normal_sum, count, inside = sweeps.run()

    occupancy = surface if inside is None else np.maximum(surface, inside)
    if not occupancy.any():
        w, h, d = size
        raise UsageError(f"{mesh.name}: no part of the mesh was found inside the "
                         f"{w}x{h}x{d} voxel box (or all of it is at or below alpha_cutoff); "
                         "check box_to_world, or raise the resolution or supersample for "
                         "geometry thinner than a voxel")
    color, normal = _resolve_attributes(color_sum, normal_sum, count)
    if inside is not None:
        _fill_interior(color, normal, occupancy, count > 0, box_to_world, size)
    params = {"mode": mode, "supersample": s, "rule": rule, "alpha_cutoff": float(alpha_cutoff),
              "resolution": list(size), "source": mesh.name}
    return VoxelGrid(occupancy=occupancy.astype(np.float32), color=color, normal=normal,
                     box_to_world=box_to_world, surface=surface.astype(np.float32),
                     inside=None if inside is None else inside.astype(np.float32),
                     params=params)


# -- validation -------------------------------------------------------------------------

def _check_int(value, label: str, lo: int, hi: int) -> int:
    if isinstance(value, bool):
        raise UsageError(f"{label} must be an integer, got {value!r}")
    try:
        n = operator.index(value)
    except TypeError:
        if isinstance(value, float) and value.is_integer():
            n = int(value)
        else:
            raise UsageError(f"{label} must be an integer, got {value!r}") from None
    if not lo <= n <= hi:
        raise UsageError(f"{label} must be between {lo} and {hi}, got {n}")
    return n


def _check_resolution(resolution) -> tuple[int, int, int]:
    """(W, H, D) ints >= 1 (a single int means a cube), capped by MAX_VOXELS."""
    if isinstance(resolution, (int, np.integer)) and not isinstance(resolution, bool):
        resolution = (resolution,) * 3
    try:
        items = list(resolution)
    except TypeError:
        raise UsageError(f"resolution must be (W, H, D) voxel counts, got {resolution!r}") \
            from None
    if len(items) != 3:
        raise UsageError(f"resolution must be (W, H, D) voxel counts, got {resolution!r}")
    size = tuple(_check_int(n, "each resolution side", 1, MAX_VOXELS) for n in items)
    if size[0] * size[1] * size[2] > MAX_VOXELS:
        raise UsageError(f"a {size[0]}x{size[1]}x{size[2]} grid has more than {MAX_VOXELS} "
                         "voxels; use a smaller resolution")
    return size


def _check_box(box_to_world) -> np.ndarray:
    """An invertible affine 4x4 (float64); projective boxes are refused."""
    try:
        m = np.array(box_to_world, dtype=np.float64)
    except (TypeError, ValueError):
        raise UsageError("box_to_world must be a 4x4 numeric matrix") from None
    if m.shape != (4, 4):
        raise UsageError(f"box_to_world must be a 4x4 matrix, got shape {m.shape}")
    if not np.isfinite(m).all():
        raise UsageError("box_to_world contains NaN or Inf")
    if np.abs(m[3] - [0.0, 0.0, 0.0, 1.0]).max() > 1e-12:
        raise UsageError("box_to_world is projective (bottom row is not 0 0 0 1); voxelize "
                         "needs an affine box, e.g. the bounding box of the mesh")
    axes = m[:3, :3]
    scale = np.prod(np.linalg.norm(axes, axis=0))
    if scale == 0 or abs(np.linalg.det(axes)) <= 1e-9 * scale:
        raise UsageError("box_to_world is singular (its three axes do not span a volume)")
    return m


def _check_gl_limits(ctx, size, s: int) -> None:
    """The grid must fit a 3D texture, and each sweep's image (s pixels per voxel) a
    framebuffer; both are GL limits, so GPUError."""
    limit = int(ctx.info["GL_MAX_3D_TEXTURE_SIZE"])
    if max(size) > limit:
        raise GPUError(f"a {size[0]}x{size[1]}x{size[2]} voxel grid exceeds this GPU's 3D "
                       f"texture limit of {limit} per side; use a smaller resolution")
    for x, y, _ in (tuple(size[a] for a in perm) for perm in SWEEPS.values()):
        check_framebuffer_size(ctx, x * s, y * s)
    attachments = int(ctx.info["GL_MAX_COLOR_ATTACHMENTS"])
    if attachments < 4:
        raise GPUError(f"voxelize needs 4 colour attachments; this GPU has {attachments}")


# -- the GPU sweeps ---------------------------------------------------------------------

class _Sweeps:
    """One voxelization: GPU buffers, the three sweeps, and the per-voxel sums."""

    def __init__(self, ctx, mesh, box_to_world, size, s, solid, rule, alpha_cutoff, progress):
        self.ctx, self.mesh, self.size, self.s = ctx, mesh, size, s
        self.solid, self.signed = solid, rule == "nonzero"
        self.alpha_cutoff, self.progress = alpha_cutoff, progress
        self.world_to_box = invert_box(box_to_world)
        # box coordinates in float64 here, uploaded instead of world positions: float32
        # world coordinates far from the origin would blur the slab bounds
        pos = mesh.world_positions
        self.box_pos = pos @ self.world_to_box[:3, :3].T + self.world_to_box[:3, 3]
        self.objects: list = []

    def run(self):
        import moderngl

        ctx = self.ctx
        w, h, d = self.size
        # per voxel: premultiplied colour sum (4), normal sum (3), crossings, coverage (max)
        acc = np.zeros((d, h, w, 9), np.float32)
        inside = np.zeros((d, h, w), np.float32) if self.solid else None
        buckets = {name: self._buckets(perm) for name, perm in SWEEPS.items()}
        total = sum(len(b[2]) - 1 for b in buckets.values()) + (1 if self.solid else 0)
        self.done, self.total = 0, total
        try:
            self._upload()
            ctx.enable_only(moderngl.BLEND)
            ctx.blend_equation = moderngl.FUNC_ADD
            ctx.blend_func = moderngl.ONE, moderngl.ONE
            for name, perm in SWEEPS.items():
                winding = self.solid and name == "h"  # the h sweep has perm (0, 1, 2)
                view = acc.transpose(_sweep_axes(perm) + (3,))  # indexed [z', y', x', c]
                self._sweep(perm, buckets[name], view, inside if winding else None)
        finally:
            bind_home_framebuffer(ctx)
            ctx.blend_func = moderngl.DEFAULT_BLENDING
            ctx.enable_only(moderngl.NOTHING)
            for obj in reversed(self.objects):
                obj.release()
            self.objects.clear()
        return acc[..., 8], acc[..., :4], acc[..., 4:7], acc[..., 7], inside

    def _upload(self) -> None:
        """Vertex buffer and one texture per material, shared by all sweeps (a material
        without an image gets a white texel when others have one: one program for all)."""
        ctx, mesh = self.ctx, self.mesh
        uvs = mesh.uvs if mesh.uvs is not None else np.zeros((len(mesh.positions), 2))
        data = np.hstack([self.box_pos, mesh.normals, mesh.colors, uvs]).astype(np.float32)
        self.vbo = ctx.buffer(data.tobytes())
        self.objects.append(self.vbo)
        self.textured = mesh.textured
        self.textures = []
        uploaded = {}
        for material in mesh.materials:
            image = material.texture if material.texture is not None else WHITE_TEXEL
            if self.textured and id(image) not in uploaded:
                uploaded[id(image)] = texture2d(ctx, image, what=f"{mesh.name} texture",
                                                srgb=True, mipmaps=True, repeat=True)
                self.objects.append(uploaded[id(image)])
            self.textures.append(uploaded.get(id(image)))
        check_gl_error(ctx, f"uploading {mesh.name} for voxelization")

    def _buckets(self, perm):
        """Triangle corners grouped by the slabs (along z' = box axis perm[2]) they reach,
        and by material inside each slab.

        Returns (indices, materials, offsets, above, above_materials): the corners of slab k
        are ``indices[offsets[k]:offsets[k+1]]`` (in triangles), ``materials`` each entry's
        material, ``above`` the triangles that reach z' >= 1 (only the winding count of the
        h sweep needs those).
        """
        n = self.size[perm[2]]
        material = self.mesh.material
        z = self.box_pos[:, perm[2]][self.mesh.indices.astype(np.int64)]  # (F, 3)
        zmin, zmax = z.min(axis=1), z.max(axis=1)
        kmin = np.clip(np.floor((zmin - _EDGE_EPS) * n), 0, n - 1).astype(np.int64)
        kmax = np.clip(np.floor((zmax + _EDGE_EPS) * n), 0, n - 1).astype(np.int64)
        hit = (zmax >= -_EDGE_EPS) & (zmin < 1 + _EDGE_EPS)
        tri = np.nonzero(hit)[0]
        span = kmax[tri] - kmin[tri] + 1
        above = np.nonzero(zmax >= 1 - _EDGE_EPS)[0]
        above = above[np.argsort(material[above], kind="stable")]
        above_part = (self.mesh.indices[above], material[above])
        if span.sum() > MAX_SLAB_ENTRIES:  # too many big triangles: draw all of them per slab
            tri = tri[np.argsort(material[tri], kind="stable")]
            offsets = np.zeros(n + 1, np.int64)
            return self.mesh.indices[tri], material[tri], offsets, *above_part
        rep = np.repeat(tri, span)
        first = np.repeat(np.cumsum(span) - span, span)
        slab = np.repeat(kmin[tri], span) + (np.arange(len(rep)) - first)
        order = np.lexsort((material[rep], slab))
        offsets = np.concatenate([[0], np.cumsum(np.bincount(slab, minlength=n))])
        entries = rep[order]
        return self.mesh.indices[entries], material[entries], offsets, *above_part

    def _sweep(self, perm, buckets, acc, inside):
        """Rasterize every slab along z' = box axis perm[2], adding to ``acc`` (a view
        indexed [z', y', x', channel]); with ``inside`` given, also count the winding."""
        import moderngl

        ctx, s = self.ctx, self.s
        winding = inside is not None
        nx, ny, nz = (self.size[a] for a in perm)
        indices, materials, offsets, above, above_materials = buckets
        draw_all = offsets[-1] == 0  # the bucketing cap was hit
        defines = {"HAS_TEXTURE": self.textured, "WINDING": winding}
        prog = program(ctx, "voxelize.glsl", defines)
        to_slab = np.eye(4)[list(perm) + [3]]  # (u, v, h) -> (x', y', z')
        set_uniforms(prog, {"u_box_to_slab": to_slab, "u_signed": self.signed,
                            "u_hole_alpha": self.alpha_cutoff})
        vao, _ = self._vao(prog, indices)
        attachments = 4 if winding else 2
        fbo = self._target(nx * s, ny * s, attachments)

        def draw(vao, lo, hi, clip, tris, mats):
            first, n = tris
            fbo.use()
            fbo.clear(0.0, 0.0, 0.0, 0.0)
            thresholds = [lo + (t + 0.5) * (hi - lo) / s for t in range(s)] + [lo]
            thresholds += [_FAR] * (8 - len(thresholds))
            set_uniforms(prog, {"u_slab": (lo, hi), "u_clip_z": clip,
                                "u_threshold_a": tuple(thresholds[:4]),
                                "u_threshold_b": tuple(thresholds[4:])})
            for start, count, m in _runs(mats[first:first + n]):  # one draw per material
                set_uniforms(prog, material_uniforms(self.mesh.materials[m]))
                if self.textures[m] is not None:
                    self.textures[m].use(0)
                vao.render(moderngl.TRIANGLES, vertices=3 * count, first=3 * (first + start))
            check_gl_error(ctx, "voxelizing a slab")
            return [read_rgba(fbo, i, top_row_first=False) for i in range(attachments)]

        above_count = np.zeros((ny * s, nx * s))  # winding of the surfaces above the slab
        if winding and len(above):
            top = float(self.box_pos[np.unique(above), perm[2]].max())
            above_vao, _ = self._vao(prog, above)
            counts = draw(above_vao, 1.0, _FAR, (1.0 - 0.5 / nz, top + 0.5 / nz),
                          (0, len(above)), above_materials)
            above_count = _channels(counts)[..., s]
        if winding:
            self._advance()
        margin = 0.5 / nz
        for k in reversed(range(nz)):  # top down: the winding count accumulates from above
            lo, hi = k / nz, (k + 1) / nz
            tris = (0, len(indices)) if draw_all else (offsets[k], offsets[k + 1] - offsets[k])
            if tris[1] == 0:
                if winding:
                    inside[k] = _inside(np.repeat(above_count[..., None], s, -1), s,
                                        self.signed)
                self._advance()
                continue
            images = draw(vao, lo, hi, (lo - margin, hi + margin), tris, materials)
            hit = images[1][..., 3:4] > 0  # the line crosses the surface in this voxel
            sums = _voxel_sums(np.concatenate([images[0], images[1], hit], -1), s)
            acc[k, ..., :8] += sums[..., :8]
            np.maximum(acc[k, ..., 8], sums[..., 8] / (s * s), out=acc[k, ..., 8])
            if winding:
                ch = _channels(images)
                inside[k] = _inside(ch[..., :s] + above_count[..., None], s, self.signed)
                above_count = above_count + ch[..., s]
            self._advance()

    def _vao(self, prog, indices):
        ctx = self.ctx
        ibo = ctx.buffer(np.ascontiguousarray(indices, dtype=np.uint32).tobytes()
                         if len(indices) else b"\0" * 12)
        self.objects.append(ibo)
        layout = (("in_box", 3), ("in_normal", 3), ("in_color", 4), ("in_uv", 2))
        attributes = [name for name, _ in layout if name in prog]
        fmt = " ".join(f"{n}f" if name in prog else f"{n}x4" for name, n in layout)
        vao = ctx.vertex_array(prog, [(self.vbo, fmt, *attributes)], ibo,
                               index_element_size=4)
        self.objects.append(vao)
        return vao, ibo

    def _target(self, width: int, height: int, attachments: int):
        ctx = self.ctx
        colors = []
        for _ in range(attachments):
            colors.append(ctx.texture((width, height), 4, dtype="f4"))
            self.objects.append(colors[-1])
        fbo = ctx.framebuffer(color_attachments=colors)
        self.objects.append(fbo)
        check_gl_error(ctx, f"creating a {width}x{height} voxelization target")
        return fbo

    def _advance(self) -> None:
        self.done += 1
        if self.progress is not None:
            self.progress(self.done, self.total)


def _runs(values: np.ndarray):
    """(start, length, value) of each run of equal values."""
    if len(values) == 0:
        return []
    change = np.flatnonzero(np.diff(values)) + 1
    starts = np.concatenate([[0], change])
    ends = np.concatenate([change, [len(values)]])
    return [(int(a), int(b - a), int(values[a])) for a, b in zip(starts, ends, strict=True)]


def _channels(images) -> np.ndarray:
    """The 8 crossing-count channels (attachments 2 and 3) as one (rows, cols, 8) array."""
    return np.concatenate([images[2], images[3]], axis=-1)


def _inside(winding: np.ndarray, s: int, signed: bool) -> np.ndarray:
    """Per voxel, the fraction of its s^3 sub-points (lines x s depths) inside the mesh."""
    w = np.rint(winding)
    inside = (w != 0) if signed else (np.mod(w, 2) == 1)
    return _blocks(inside, s).mean(axis=(1, 3, 4))


def _voxel_sums(lines: np.ndarray, s: int) -> np.ndarray:
    """(ny*s, nx*s, C) per line -> (ny, nx, C) sums over each voxel's s x s lines."""
    rows, cols, c = lines.shape
    x = lines.reshape(rows // s, s, cols // s, s * c)
    y = x[:, 0].copy()
    for i in range(1, s):  # sequential adds: much faster than a multi-axis reduction
        y += x[:, i]
    return y.reshape(rows // s, cols // s, s, c).sum(axis=2)


def _blocks(image: np.ndarray, s: int) -> np.ndarray:
    """(ny*s, nx*s, ...) -> (ny, s, nx, s, ...): the s x s lines of each voxel."""
    rows, cols = image.shape[:2]
    return image.reshape(rows // s, s, cols // s, s, *image.shape[2:])


def _sweep_axes(perm) -> tuple[int, int, int]:
    """Transpose making an [h, v, u] array read [z', y', x'] for the sweep ``perm``."""
    layout = (perm[2], perm[1], perm[0])  # box axis of each sweep array axis
    return tuple(2 - axis for axis in layout)  # array axis m of [h, v, u] is box axis 2 - m


# -- attributes -------------------------------------------------------------------------

def _resolve_attributes(color_sum, normal_sum, count):
    """Straight-alpha mean colour and unit mean normal of the crossings in each voxel."""
    crossings = count[..., None]
    alpha_sum = color_sum[..., 3:4]
    rgb = np.divide(color_sum[..., :3], alpha_sum, out=np.zeros_like(color_sum[..., :3]),
                    where=alpha_sum > 0)
    alpha = np.divide(alpha_sum, crossings, out=np.zeros_like(alpha_sum), where=crossings > 0)
    color = np.concatenate([rgb, alpha], -1).astype(np.float32)
    length = np.linalg.norm(normal_sum, axis=-1, keepdims=True)
    ok = length > 1e-6 * np.maximum(crossings, 1)
    normal = np.divide(normal_sum, length, out=np.zeros_like(normal_sum), where=ok)
    return color, normal.astype(np.float32)


def _fill_interior(color, normal, occupancy, has_surface, box_to_world, size) -> None:
    """Interior voxels (no crossing of their own) copy the nearest surface voxel, in world
    distance; without any surface voxel in the grid they keep 0."""
    from scipy.ndimage import distance_transform_edt

    need = (occupancy > 0) & ~has_surface
    if not need.any() or not has_surface.any():
        return
    w, h, d = size
    lengths = np.linalg.norm(box_to_world[:3, :3], axis=0)  # world length of u, v, h
    sampling = (lengths[2] / d, lengths[1] / h, lengths[0] / w)
    nearest = distance_transform_edt(~has_surface, sampling=sampling, return_distances=False,
                                     return_indices=True)
    src = tuple(idx[need] for idx in nearest)
    color[need] = color[src]
    normal[need] = normal[src]
