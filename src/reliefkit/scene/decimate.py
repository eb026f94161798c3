"""A mesh decimated to a byte budget, and its bytes as a GPU holds them.

Two ways to count a mesh's GPU memory (`gpu_bytes`), both with its material textures:

* **raw** — what reliefkit's mesh drawable uploads: float32 positions, normals and RGBA colours
  and, when the mesh has them, float32 uvs; uint32 indices; RGBA8 textures with their mips.
* **compact** — what an engine ships (the layout meshoptimizer recommends), every attribute
  4-byte aligned: positions as 16-bit unorm over the bounding box, padded to four components
  (8 bytes: three-component 16-bit formats are no vertex format on D3D and optional on
  Vulkan); normals octahedral in two 16-bit snorm (4 bytes; 8-bit would err by about a degree,
  which shading shows); uvs as two 16-bit unorm over their range (4 bytes); colours as RGBA8
  only when they vary per vertex (one colour is a uniform: 0 bytes); uint16 indices when the
  vertex count fits, else uint32; textures block-compressed with their mips, BC1 (half a byte a
  texel) when opaque, BC7 (one byte) when alpha varies.

`compact_mesh` applies the compact quantization to a mesh (and decodes it back to floats), so
a compact mesh is drawn with exactly the error it would ship with. `decimate_to_bytes` finds
the most triangles whose bytes fit a budget.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..compact.blocks import level_bytes
from ..compact.encodings import texture_bytes as raw_texture_bytes
from ..io.rk import array_bytes
from .mesh import RenderMesh, vertex_normals

POSITION_BITS = 16
NORMAL_BITS = 16
UV_BITS = 16
COLOR_BITS = 8
#: Compact bytes per vertex of each attribute (positions padded to four 16-bit components).
COMPACT_VERTEX_BYTES = {"positions": 8, "normals": 4, "uvs": 4, "colors": 4}
RAW_VERTEX_BYTES = {"positions": 12, "normals": 12, "uvs": 8, "colors": 16}
UINT16_VERTICES = 1 << 16
#: A decimated mesh whose textures do not fit gives them at most this share of the budget,
#: halving them until they do (what an artist trading texels for triangles would do).
TEXTURE_SHARE = 0.5
#: Bisection steps on the triangle count: 2^-18 of it is below one triangle for any mesh
#: the loaders take, so the search ends on the exact largest count that fits.
SEARCH_STEPS = 18


def mesh_bytes(mesh) -> int:
    """Bytes of the arrays a mesh's .rk file stores (uncompressed)."""
    return sum(array_bytes(mesh).values())


# -- bytes as a GPU holds them ------------------------------------------------------------

def varying_colors(mesh) -> bool:
    """Whether the vertex colours differ (else one colour, a uniform)."""
    colors = mesh.colors
    return len(colors) > 1 and bool((colors != colors[0]).any())


def mip_chain(width: int, height: int) -> list[tuple[int, int]]:
    """Every mip level's size, the image's own first, down to 1 x 1."""
    levels = [(width, height)]
    while levels[-1] != (1, 1):
        w, h = levels[-1]
        levels.append((max(w // 2, 1), max(h // 2, 1)))
    return levels


def texture_bytes(image, *, compact: bool) -> int:
    """An (h, w, 4) uint8 texture with its mips: RGBA8, or BC1 / BC7 blocks (BC7 when its alpha
    is not all opaque), counted as `reliefkit.compact` stores them."""
    if not compact:
        return raw_texture_bytes(image, mipmaps=True)
    h, w = image.shape[:2]
    fmt = "bc1" if bool((np.asarray(image)[..., 3] == 255).all()) else "bc7"
    return sum(level_bytes(fmt, lh, lw) for lw, lh in mip_chain(w, h))


def gpu_bytes(mesh, *, compact: bool = False) -> dict[str, int]:
    """Bytes of ``vertices``, ``indices`` and ``textures`` (each distinct image once) as a GPU
    holds them, raw or compact (the module's docstring says which formats), and the ``total``."""
    per_vertex = COMPACT_VERTEX_BYTES if compact else RAW_VERTEX_BYTES
    vertex = per_vertex["positions"] + per_vertex["normals"]
    if mesh.uvs is not None:
        vertex += per_vertex["uvs"]
    if not compact or varying_colors(mesh):
        vertex += per_vertex["colors"]
    vertices = len(mesh.positions)
    index = 2 if compact and vertices <= UINT16_VERTICES else 4
    images = {id(m.texture): m.texture for m in mesh.materials if m.texture is not None}
    out = {"vertices": vertices * vertex, "indices": mesh.indices.size * index,
           "textures": sum(texture_bytes(t, compact=compact) for t in images.values())}
    return out | {"total": sum(out.values())}


# -- quantization -------------------------------------------------------------------------

def quantize(values: np.ndarray, lo, hi, bits: int) -> np.ndarray:
    """``values`` in [lo, hi] rounded to the nearest of 2^bits evenly spaced levels (floats:
    the quantized value decoded back); a flat range keeps its one value."""
    lo, hi = np.asarray(lo, np.float64), np.asarray(hi, np.float64)
    span = np.where(hi > lo, hi - lo, 1.0)
    steps = (1 << bits) - 1
    codes = np.rint((np.asarray(values, np.float64) - lo) / span * steps)
    return lo + np.clip(codes, 0, steps) / steps * span


def _fold(xy: np.ndarray) -> np.ndarray:
    """The octahedron's lower half folded over the upper one's diagonals (its own inverse)."""
    return (1.0 - np.abs(xy[:, ::-1])) * np.where(xy >= 0, 1.0, -1.0)


def octahedral_normals(normals: np.ndarray, bits: int = NORMAL_BITS) -> np.ndarray:
    """Unit normals through the octahedral encoding with two ``bits``-bit snorm components,
    decoded back to unit vectors."""
    n = np.asarray(normals, np.float64)
    n = n / np.maximum(np.abs(n).sum(axis=1, keepdims=True), 1e-30)
    xy = n[:, :2].copy()
    lower = n[:, 2] < 0
    xy[lower] = _fold(xy[lower])
    xy = quantize(xy, -1.0, 1.0, bits)
    z = 1.0 - np.abs(xy).sum(axis=1)
    under = z < 0
    xy[under] = _fold(xy[under])
    out = np.column_stack([xy, z])
    return out / np.linalg.norm(out, axis=1, keepdims=True)


def compact_mesh(mesh) -> RenderMesh:
    """``mesh`` with its attributes quantized as `gpu_bytes` counts them compact, decoded back
    to floats: what an engine shipping the compact layout would draw."""
    points = mesh.world_positions
    bounds = mesh.bounds
    positions = quantize(points, bounds[0], bounds[1], POSITION_BITS)
    uvs = None
    if mesh.uvs is not None:
        uvs = quantize(mesh.uvs, mesh.uvs.min(axis=0), mesh.uvs.max(axis=0), UV_BITS)
    colors = mesh.colors
    if varying_colors(mesh):
        colors = quantize(colors, 0.0, 1.0, COLOR_BITS)
    return RenderMesh(positions, mesh.indices, octahedral_normals(mesh.normals), colors, uvs,
                      name=mesh.name, extra=dict(mesh.extra), materials=mesh.materials,
                      material=mesh.material)


# -- decimation ---------------------------------------------------------------------------

def simplified(mesh, triangles: int) -> RenderMesh | None:
    """``mesh`` reduced to about ``triangles`` by quadric decimation (fast_simplification);
    colours and uvs come from the nearest original vertex, the material from the nearest
    original face. None when nothing is left or the package is missing."""
    try:
        import fast_simplification  # optional dependency
    except ImportError:
        return None
    from scipy.spatial import cKDTree  # scipy: slow to import

    if triangles >= mesh.triangle_count:
        return mesh
    points = mesh.world_positions
    new_points, faces = fast_simplification.simplify(points, mesh.indices.astype(np.int64),
                                                     target_count=max(int(triangles), 1))
    if len(faces) == 0:
        return None
    near = cKDTree(points).query(new_points)[1]
    centroids = points[mesh.indices].mean(axis=1)
    face_near = cKDTree(centroids).query(new_points[faces].mean(axis=1))[1]
    faces = faces.astype(np.uint32)
    return RenderMesh(new_points, faces, vertex_normals(new_points.astype(np.float32), faces),
                      mesh.colors[near], None if mesh.uvs is None else mesh.uvs[near],
                      name=f"{mesh.name} decimated", materials=mesh.materials,
                      material=mesh.material[face_near])


def decimated(mesh, target_bytes: int) -> RenderMesh | None:
    """``mesh`` simplified to about ``target_bytes`` of .rk arrays (`mesh_bytes`; None when
    fast_simplification is missing; the mesh itself when it is already that small)."""
    full = mesh_bytes(mesh)
    if target_bytes >= full:
        return mesh
    reduction = min(1.0 - target_bytes / full, 0.999)
    return simplified(mesh, round(mesh.triangle_count * (1.0 - reduction)))


def halved(image: np.ndarray) -> np.ndarray:
    """An (h, w, 4) uint8 image at half its size in each direction longer than one texel
    (means of 2 x 2 texels; an odd last row or column dropped)."""
    h, w = image.shape[:2]
    fy, fx = (2 if h > 1 else 1), (2 if w > 1 else 1)
    blocks = image[:h // fy * fy, :w // fx * fx].reshape(h // fy, fy, w // fx, fx, -1)
    return np.rint(blocks.astype(np.float32).mean(axis=(1, 3))).astype(np.uint8)


def textures_within(mesh, budget: int, *, compact: bool = True) -> RenderMesh:
    """``mesh`` with its textures halved until they take at most ``budget`` bytes (or are
    1 x 1); the mesh itself when they already do."""
    def texture_total(m) -> int:
        return gpu_bytes(m, compact=compact)["textures"]

    while texture_total(mesh) > budget and any(
            m.texture is not None and m.texture.size > 4 for m in mesh.materials):
        smaller = {}
        for m in mesh.materials:
            if m.texture is not None and id(m.texture) not in smaller:
                smaller[id(m.texture)] = halved(m.texture)
        materials = [m if m.texture is None else dataclasses.replace(
            m, texture=smaller[id(m.texture)]) for m in mesh.materials]
        mesh = RenderMesh(mesh.world_positions, mesh.indices, mesh.normals, mesh.colors,
                          mesh.uvs, name=mesh.name, extra=dict(mesh.extra),
                          materials=materials, material=mesh.material)
    return mesh


def decimate_to_bytes(mesh, budget: int, *, compact: bool = True) -> RenderMesh | None:
    """The mesh with the most triangles whose `gpu_bytes` (compact or raw) fit ``budget``, found
    by bisection on the target triangle count (deterministic); compact, it is returned
    quantized (`compact_mesh`). When the whole mesh does not fit, its textures are first
    halved until they take at most `TEXTURE_SHARE` of the budget. None when not even one
    triangle fits or fast_simplification is missing."""
    whole = gpu_bytes(mesh, compact=compact)["total"] <= budget
    if not whole:
        mesh = textures_within(mesh, int(budget * TEXTURE_SHARE), compact=compact)

    def fitted(triangles: int):
        candidate = simplified(mesh, triangles)
        if candidate is None:
            return None
        if gpu_bytes(candidate, compact=compact)["total"] > budget:
            return None
        return compact_mesh(candidate) if compact else candidate

    best = fitted(mesh.triangle_count)
    if best is not None:
        return best
    lo, hi = 0, mesh.triangle_count  # hi never fits; lo is the best count that did
    for _ in range(SEARCH_STEPS):
        if hi - lo <= 1:
            break
        mid = (lo + hi) // 2
        found = fitted(mid)
        if found is None:
            hi = mid
        else:
            lo, best = mid, found
    return best
