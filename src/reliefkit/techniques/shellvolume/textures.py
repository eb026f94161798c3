"""Procedural 3D textures of the semi-transparent 3D texture paper's Figure 1 (Dufort,
Leblanc & Poulin 2005): fur, clouds, ellipsoids, absorption, chain and rocks.

Conventions (docs/architecture.md, "3D textures"): ``rgba`` has shape (D, H, W, 4) indexed
[w, v, u], float32, straight linear RGB, and its alpha is opacity per unit of object-space
length: a segment of length L through a voxel has opacity ``1 - (1 - alpha)^L`` (the paper's
§4.3 correction). w = 0 is the base (the mesh surface), w = 1 the top of the shell.

The generators author alpha as the opacity of the shell's whole thickness (a medium of
alpha 0.3 dims what is below it by 30% seen straight down, whatever the shell's size);
`VolumeTexture.over_length` records that length once the thickness is known (the baker
does). Converting the alphas themselves to one unit of length would round dense media over a
thin shell to exactly 1 (solid) in float32.

``normal`` (D, H, W, 3) holds unit vectors with components (u, v, w), computed from the
density (alpha) gradient by central differences in voxel units, pointing from dense towards
empty (``-grad``); where the gradient vanishes the normal is +w.

Every maker is deterministic given ``seed``; noise is tileable in u and v (wrapped filters).
"""

from __future__ import annotations

import os
import stat
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...bake.voxelize import voxelize
from ...errors import FormatError, UsageError
from ...io.npy import npy_header

#: Largest voxel count ``load_texture_npy`` accepts (256^3 voxels).
MAX_VOXELS = 256**3


@dataclass(frozen=True, eq=False)
class VolumeTexture:
    """A 3D texture: ``rgba`` (D,H,W,4), ``normal`` (D,H,W,3), both float32; ``tile`` (U, V)
    repetitions over the base's uvs; optional ``glow`` (D,H,W) float32 >= 0, light emitted per
    unit of object-space length in units of the voxel's colour (the paper's glow, §5.3);
    ``length``: the object-space length alpha is the opacity of (1, the default per unit
    length, unless the texture was authored over a shell's thickness: `over_length`; alpha
    stays the authored float32 value, so a dense medium keeps its precision)."""

    rgba: np.ndarray
    normal: np.ndarray
    name: str
    tile: tuple[int, int] = (1, 1)
    glow: np.ndarray | None = None
    length: float = 1.0

    def __post_init__(self) -> None:
        if self.rgba.ndim != 4 or self.rgba.shape[3] != 4 or self.rgba.dtype != np.float32:
            got = f"{self.rgba.dtype} {self.rgba.shape}"
            raise UsageError(f"texture rgba must be float32 (D, H, W, 4), got {got}")
        if min(self.rgba.shape[:3]) < 1:
            raise UsageError(f"texture has {self.rgba.shape[:3]} (D, H, W) voxels; every "
                             "size must be at least 1")
        if self.normal.shape != self.rgba.shape[:3] + (3,) or self.normal.dtype != np.float32:
            got = f"{self.normal.dtype} {self.normal.shape}"
            raise UsageError(f"texture normal must be float32 (D, H, W, 3), got {got}")
        if self.glow is not None and (self.glow.shape != self.rgba.shape[:3]
                                      or self.glow.dtype != np.float32):
            got = f"{self.glow.dtype} {self.glow.shape}"
            raise UsageError(f"texture glow must be float32 (D, H, W), got {got}")
        if not (isinstance(self.length, int | float) and np.isfinite(self.length)
                and self.length > 0):
            raise UsageError(f"texture length must be a positive number, got {self.length!r}")
        tile = tuple(self.tile)
        if len(tile) != 2 or not all(isinstance(t, int | np.integer) and 1 <= t <= 4096
                                     for t in tile):
            raise UsageError(f"texture tile must be two whole numbers in 1..4096, got "
                             f"{self.tile!r}")

    @property
    def shape(self) -> tuple[int, int, int]:
        """(D, H, W)."""
        return self.rgba.shape[:3]

    @property
    def opaque(self) -> bool:
        """Every voxel empty (alpha 0) or solid (alpha 1), and nothing glows: drawn with
        the depth test, without sorting."""
        alpha = self.rgba[..., 3]
        return self.glow is None and bool(np.all((alpha == 0) | (alpha == 1)))

    def over_length(self, length: float) -> VolumeTexture:
        """This texture with its alpha read as the opacity over ``length`` of object space
        (the generators author it over the shell's whole thickness) and its glow as light
        over ``length`` (converted to light per unit length, ``glow / length``)."""
        from dataclasses import replace

        if not length > 0:
            raise UsageError(f"length must be > 0, got {length}")
        glow = None if self.glow is None else (self.glow / length).astype(np.float32)
        return replace(self, length=float(length), glow=glow)

    def tiled(self, tile) -> VolumeTexture:
        """The same texture repeated ``tile`` (U, V) times over the uvs."""
        from dataclasses import replace

        return replace(self, tile=tuple(int(t) for t in tile))


#: A solid voxel (alpha 1) is opaque over this fraction of the shell's thickness: the
#: optical density it is filtered and marched with (`optical_density`).
SOLID_LENGTH = 1e-4


def optical_density(alpha: np.ndarray, length: float, thickness: float) -> np.ndarray:
    """Optical density per unit length, -ln(1 - alpha) / ``length``, of alphas that are the
    opacity over ``length``: what the renderer and the CPU reference filter and march (a
    sample of length dt has opacity 1 - exp(-density dt), the §4.3 correction).
    Interpolating densities is exact for absorption (Beer-Lambert) and keeps its precision
    where alpha is close to 1, where interpolated alphas would not. Solid voxels (alpha 1)
    get a finite density that makes `SOLID_LENGTH` of the shell's ``thickness`` opaque
    (optical depth 50)."""
    a = np.clip(np.asarray(alpha, dtype=np.float64), 0.0, 1.0)
    solid = 50.0 / (SOLID_LENGTH * thickness)
    density = -np.log1p(-np.minimum(a, 1.0 - 1e-16)) / length
    return np.where(a >= 1.0, solid, np.minimum(density, solid)).astype(np.float32)


def marched_volume(rgba: np.ndarray, length: float, thickness: float) -> np.ndarray:
    """(D, H, W, 4) float32 what is filtered and marched: the optical density
    (`optical_density`) in alpha, and the colour premultiplied by it, so that filtering
    weights each voxel's colour by its extinction (between a solid voxel and a thin medium
    the solid's colour wins, as it should where the ray stops; empty voxels add almost
    nothing). A sample's colour is the filtered colour over the filtered weight, density
    plus `density_floor`."""
    rgba = np.asarray(rgba, dtype=np.float64)
    density = optical_density(rgba[..., 3], length, thickness).astype(np.float64)
    weight = density + density_floor(thickness)
    out = np.concatenate([rgba[..., :3] * weight[..., None], density[..., None]], axis=-1)
    return out.astype(np.float32)


def density_floor(thickness: float) -> float:
    """What colour weights add to the density (`marched_volume`): an optical depth of 1e-3
    over the shell's thickness, so a clear (glowing) medium keeps its colour."""
    return 1e-3 / thickness


def density_normals(alpha: np.ndarray) -> np.ndarray:
    """Unit normals (u, v, w components) of a (D,H,W) density: ``-grad / |grad|``, +w where 0."""
    alpha = np.asarray(alpha, dtype=np.float64)
    d, h, w = alpha.shape
    grads = []
    for axis, size in ((2, w), (1, h), (0, d)):
        if size < 2:
            grads.append(np.zeros_like(alpha))
        else:
            grads.append(np.gradient(alpha, axis=axis))
    n = -np.stack(grads, axis=-1)
    length = np.linalg.norm(n, axis=-1, keepdims=True)
    flat = length[..., 0] < 1e-9
    n = np.where(length > 1e-9, n / np.maximum(length, 1e-12), 0.0)
    n[flat] = (0.0, 0.0, 1.0)
    return n.astype(np.float32)


def _grid(size):
    """Texel-centre coordinates in [0,1]: (w, v, u) arrays of shape (D, H, W)."""
    width, height, depth = _check_size(size)
    w = (np.arange(depth) + 0.5) / depth
    v = (np.arange(height) + 0.5) / height
    u = (np.arange(width) + 0.5) / width
    return np.meshgrid(w, v, u, indexing="ij")


def _check_size(size):
    if len(size) != 3 or any(int(s) != s or s < 1 for s in size):
        raise UsageError(f"texture size must be three positive integers (W, H, D), got {size!r}")
    if np.prod([int(s) for s in size]) > MAX_VOXELS:
        raise UsageError(f"texture size {size!r} exceeds {MAX_VOXELS} voxels; use a smaller size")
    return tuple(int(s) for s in size)


def _noise(rng, shape, sigma, wrap_w=False):
    """Smooth noise in [0,1]: Gaussian-filtered white noise, wrapped in u and v."""
    from scipy import ndimage  # scipy: slow to import
    field = rng.random(shape)
    modes = ["wrap"] * field.ndim
    if field.ndim == 3 and not wrap_w:
        modes[0] = "reflect"
    field = ndimage.gaussian_filter(field, sigma, mode=modes)
    lo, hi = field.min(), field.max()
    return (field - lo) / (hi - lo) if hi > lo else np.zeros_like(field)


def _fbm(rng, shape, sigmas=(8.0, 4.0, 2.0, 1.0)):
    total = np.zeros(shape)
    weight = 0.0
    for k, s in enumerate(sigmas):
        amp = 0.5**k
        total += amp * _noise(rng, shape, [max(s * n / max(shape), 0.5) for n in shape])
        weight += amp
    return total / weight


def _wrapped(d):
    """Periodic difference in [-0.5, 0.5)."""
    return d - np.round(d)


def _make(name, rgb, alpha, tile=(1, 1)):
    rgba = np.concatenate([np.clip(rgb, 0, 1), np.clip(alpha, 0, 1)[..., None]], axis=-1)
    return VolumeTexture(rgba.astype(np.float32), density_normals(alpha), name, tile)


def make_fur(size=(32, 32, 16), seed=0) -> VolumeTexture:
    """Brown strands rising from a dark skin at w = 0, each thinning to nothing at w = 1,
    bending slightly."""
    rng = np.random.default_rng(seed)
    w, v, u = _grid(size)
    count = 140
    alpha = np.zeros(w.shape)
    rgb = np.zeros(w.shape + (3,))
    alpha[0], rgb[0] = 1.0, (0.18, 0.1, 0.05)
    base_radius = 0.04
    for _ in range(count):
        u0, v0 = rng.random(2)
        bend = rng.normal(0, 0.08, 2)
        shade = rng.uniform(0.7, 1.1)
        du = _wrapped(u - (u0 + bend[0] * w**2))
        dv = _wrapped(v - (v0 + bend[1] * w**2))
        inside = np.hypot(du, dv) < base_radius * (1.0 - w)
        alpha[inside] = 1.0
        rgb[inside] = np.array([0.45, 0.27, 0.12]) * shade
    return _make("fur", rgb, alpha)


def make_clouds(size=(32, 32, 16), seed=0) -> VolumeTexture:
    """An opaque Earth-like base at w = 0 (blue oceans, green-brown land) under fbm clouds."""
    rng = np.random.default_rng(seed)
    w, v, u = _grid(size)
    depth, height, width = w.shape
    land = _fbm(rng, (height, width))
    ocean = land < 0.5
    ground = np.where(ocean[..., None], [0.05, 0.15, 0.55],
                      np.where((land > 0.7)[..., None], [0.45, 0.35, 0.2], [0.15, 0.45, 0.12]))
    density = _fbm(rng, w.shape)
    profile = np.clip((w - 0.4) / 0.2, 0, 1) * np.clip((1.0 - w) / 0.15, 0, 1)
    alpha = np.clip((density - 0.55) * 6.0, 0, 0.97) * profile  # puffs over a third
    rgb = np.full(w.shape + (3,), 0.95)
    alpha[0] = 1.0
    rgb[0] = ground
    return _make("clouds", rgb, alpha)


def make_ellipsoids(size=(32, 32, 16), seed=0) -> VolumeTexture:
    """A few opaque coloured ellipsoids in a red semi-transparent medium (alpha 0.3)."""
    rng = np.random.default_rng(seed)
    w, v, u = _grid(size)
    alpha = np.full(w.shape, 0.3)
    rgb = np.zeros(w.shape + (3,))
    rgb[...] = (0.8, 0.1, 0.1)
    for _ in range(4):
        c = rng.uniform([0, 0, 0.3], [1, 1, 0.7])
        axes = rng.uniform([0.1, 0.1, 0.15], [0.2, 0.2, 0.3])
        r2 = (_wrapped(u - c[0]) / axes[0]) ** 2 + (_wrapped(v - c[1]) / axes[1]) ** 2
        r2 = r2 + ((w - c[2]) / axes[2]) ** 2
        inside = r2 < 1.0
        alpha[inside] = 1.0
        rgb[inside] = rng.uniform(0.2, 0.9, 3)
    return _make("ellipsoids", rgb, alpha)


def make_absorption(size=(32, 32, 16), seed=0) -> VolumeTexture:
    """A uniform green absorbing medium of constant opacity (alpha 0.5 per unit length)."""
    w, _, _ = _grid(size)
    rgb = np.broadcast_to(np.array([0.1, 0.7, 0.2]), w.shape + (3,))
    return _make("absorption", rgb, np.full(w.shape, 0.5))


def make_chain(size=(32, 32, 16), seed=0) -> VolumeTexture:
    """An opaque metal chain along u: interlocking tori, alternately in the u-w and u-v planes.

    The geometry is measured in voxels (so tori stay round); the chain wraps around u.
    ``seed`` only varies the metal's shade.
    """
    rng = np.random.default_rng(seed)
    width, height, depth = _check_size(size)
    z, y, x = np.meshgrid(np.arange(depth) + 0.5, np.arange(height) + 0.5,
                          np.arange(width) + 0.5, indexing="ij")
    links = 4
    pitch = width / links
    major = 0.55 * pitch
    minor = min(0.16 * pitch, 0.2 * depth)
    major = min(major, depth / 2 - minor - 0.5)
    alpha = np.zeros(x.shape)
    for k in range(links):
        dx = (x - (k + 0.5) * pitch + width / 2) % width - width / 2
        dy, dz = y - height / 2, z - depth / 2
        a, b, axis = (dx, dz, dy) if k % 2 == 0 else (dx, dy, dz)
        ring = np.hypot(np.hypot(a, b) - major, axis)
        alpha[ring < minor] = 1.0
    shade = rng.uniform(0.6, 0.8)
    rgb = np.broadcast_to(np.array([shade, shade, shade * 1.05]), x.shape + (3,))
    return _make("chain", rgb, alpha)


def make_rocks(size=(32, 32, 16), seed=0) -> VolumeTexture:
    """Opaque bumpy grey rocks on an opaque brown ground of noisy height."""
    rng = np.random.default_rng(seed)
    w, v, u = _grid(size)
    depth, height, width = w.shape
    ground_h = 0.08 + 0.12 * _fbm(rng, (height, width))
    ground = w < ground_h
    bumps = _fbm(rng, w.shape, sigmas=(2.0, 1.0))
    alpha = ground.astype(float)
    rgb = np.zeros(w.shape + (3,))
    rgb[ground] = (0.35, 0.25, 0.15)
    for _ in range(5):
        c = rng.uniform([0, 0, 0.1], [1, 1, 0.25])
        r = rng.uniform(0.12, 0.22)
        dist = np.sqrt(_wrapped(u - c[0]) ** 2 + _wrapped(v - c[1]) ** 2 + ((w - c[2]) * 0.8) ** 2)
        inside = dist / r + 0.5 * (bumps - 0.5) < 1.0
        alpha[inside] = 1.0
        rgb[inside] = rng.uniform(0.4, 0.6) * np.array([1.0, 0.97, 0.92])
    return _make("rocks", rgb, alpha)


def make_glow(size=(32, 32, 16), seed=0) -> VolumeTexture:
    """Glowing embers in a thin grey smoke over a dark opaque floor: the paper's glow
    (Color plate G), light added where the voxels' ``glow`` is set."""
    rng = np.random.default_rng(seed)
    w, v, u = _grid(size)
    alpha = np.full(w.shape, 0.15)
    rgb = np.broadcast_to(np.array([0.5, 0.5, 0.55]), w.shape + (3,)).copy()
    glow = np.zeros(w.shape)
    for _ in range(10):
        c = rng.uniform([0, 0, 0.25], [1, 1, 0.8])
        r2 = (_wrapped(u - c[0]) ** 2 + _wrapped(v - c[1]) ** 2 + (w - c[2]) ** 2) / 0.06 ** 2
        with np.errstate(under="ignore"):
            ember = np.where(r2 < 80.0, np.exp(-np.minimum(r2, 80.0)), 0.0)
        glow = np.maximum(glow, 3.0 * ember)
        rgb = np.where((ember > 0.2)[..., None], [1.0, 0.45, 0.1], rgb)
    alpha[0], rgb[0] = 1.0, (0.05, 0.04, 0.04)
    texture = _make("glow", rgb, alpha)
    from dataclasses import replace

    return replace(texture, glow=glow.astype(np.float32))


def texture_from_mesh(mesh, size=(32, 32, 16), progress=None) -> VolumeTexture:
    """A mesh voxelized by the core voxelizer into an opaque texture (the paper's "texture of
    a tree", Color plate E): its box fills the tile, x along u, -z along v, +y up along w
    (a right-handed frame, so the voxelizer's facing keeps its sign).

    Voxels the surface (or, for a closed mesh, the interior) covers at least half are solid
    (alpha 1) with the mesh's colour; normals are the mesh's, in voxel units.
    """
    width, height, depth = _check_size(size)
    lo, hi = (np.asarray(b, np.float64) for b in mesh.bounds)
    extent = np.maximum(hi - lo, 1e-9 * max(float(np.max(hi - lo)), 1e-30))
    box = np.eye(4)
    box[:3, 0] = (extent[0], 0, 0)   # u <- x
    box[:3, 1] = (0, 0, -extent[2])  # v <- -z
    box[:3, 2] = (0, extent[1], 0)   # w <- y (up)
    box[:3, 3] = (lo[0], lo[1], hi[2])
    closed = all(part.get("closed") for part in mesh.extra.get("parts", [])) and \
        bool(mesh.extra.get("parts"))
    grid = voxelize(mesh, box, (width, height, depth), mode="solid" if closed else "surface",
                    progress=progress)
    solid = grid.occupancy >= 0.5
    rgb = np.where(solid[..., None], np.nan_to_num(grid.color[..., :3]), 0.0)
    world = np.nan_to_num(grid.normal)
    voxel = extent[[0, 2, 1]] / (width, height, depth)
    n = world[..., [0, 2, 1]] * (1.0, -1.0, 1.0) * voxel  # components in voxel units
    length = np.linalg.norm(n, axis=-1, keepdims=True)
    n = np.where(length > 1e-12, n / np.maximum(length, 1e-12), (0.0, 0.0, 1.0))
    rgba = np.concatenate([rgb, solid[..., None]], axis=-1).astype(np.float32)
    return VolumeTexture(rgba, n.astype(np.float32), mesh.name)


TEXTURES = {
    "fur": make_fur,
    "clouds": make_clouds,
    "ellipsoids": make_ellipsoids,
    "absorption": make_absorption,
    "chain": make_chain,
    "rocks": make_rocks,
    "glow": make_glow,
}


def load_texture_npy(path, name: str | None = None) -> VolumeTexture:
    """Read a (D, H, W, 4) float RGBA volume from an .npy file (no pickles), validated.

    The header is checked before any array memory is allocated: a regular file, a 4-D shape
    ending in 4 of at most ``MAX_VOXELS`` voxels, float32/float64, C order, and a file size
    that matches. Values must be finite, colour >= 0, alpha in [0, 1].
    """
    path = Path(path)
    # a symlink is followed (fstat checks what it points to); O_NONBLOCK: a FIFO never blocks
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0)
    try:
        fd = os.open(path, flags)
    except OSError as exc:
        reason = exc.strerror
        raise FormatError(f"cannot open texture {path}: {reason}; use a regular .npy") from None
    info = os.fstat(fd)
    if not stat.S_ISREG(info.st_mode):
        os.close(fd)
        raise FormatError(f"texture {path} is not a regular file; give a .npy file")
    with os.fdopen(fd, "rb") as f:
        try:
            shape, fortran, dtype = npy_header(f)
        except ValueError as exc:
            raise FormatError(f"texture {path} is not a valid .npy file ({exc})") from None
        if len(shape) != 4 or shape[3] != 4 or min(shape) < 1:
            raise FormatError(f"texture {path} has shape {shape}; expected (D, H, W, 4)")
        voxels = int(shape[0]) * int(shape[1]) * int(shape[2])
        if voxels > MAX_VOXELS:
            raise FormatError(f"texture {path} claims {voxels} voxels, over the {MAX_VOXELS} limit")
        if dtype not in (np.dtype("<f4"), np.dtype("<f8")) or fortran:
            order = " (Fortran order)" if fortran else ""
            raise FormatError(f"texture {path} has dtype {dtype}{order}; "
                             "expected little-endian float32/float64 in C order")
        count = voxels * 4
        if info.st_size - f.tell() != count * dtype.itemsize:
            raise FormatError(f"texture {path} is truncated or has trailing data for shape {shape}")
        data = np.fromfile(f, dtype=dtype, count=count)
    rgba = data.reshape(shape).astype(np.float32)
    if not np.isfinite(rgba).all():
        raise FormatError(f"texture {path} contains NaN or Inf values")
    if (rgba[..., 3] < 0).any() or (rgba[..., 3] > 1).any():
        raise FormatError(f"texture {path} has alpha outside [0, 1]")
    if (rgba[..., :3] < 0).any():
        raise FormatError(f"texture {path} has negative colour values")
    return VolumeTexture(rgba, density_normals(rgba[..., 3]), name or path.stem)
