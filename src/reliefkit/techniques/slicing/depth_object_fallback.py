"""What a glTF viewer that knows nothing of depth objects shows of one: the carved volume as a
triangle mesh (`DepthObject.fallback_mesh`, `VisualHull.fallback_mesh`).

**The volume.** The object is the intersection of the six images' volumes (reference.py,
nearest texel); a visual hull the intersection of its silhouettes' extrusions, as it draws.
It is sampled on a grid over the object's box as a field that is positive inside: per image,
the least of how far the point lies behind the image's depth (along the image's axis) and how
far inside its silhouette it lies (the silhouette's signed distance, bilinear between texel
centres); the object's field is the least over the six images. Marching cubes
(scikit-image) cuts its zero level, so a vertex lies where the field changes sign between
two grid points: exactly on a depth plane along an image's axis, within about a grid cell
across a silhouette's edge.

**The budget.** The triangle count of marching cubes grows as the square of the grid's
resolution; a trial on a coarse grid measures the object's count, and the grid is chosen
to give `OVERSAMPLE` times the budget, then decimated to it (fast_simplification's
quadric decimation keeps thin parts, a spider's legs, that a grid at the budget misses); a
visual hull's grid aims at the budget itself. Where decimation falls short, the grid is
coarsened until its own count fits. The grid is never finer than the images' texels (there
is no more to see); a budget below `MIN_TRIANGLES` is refused.

**Colour and normals.** Each vertex is textured as the renderer textures a point seen
straight on (render.py, §4.2, with the vertex normal as the view direction, so the
colour does not depend on a view): the three images whose faces are closest to the normal,
weighted by how much less than 90 degrees their angle is, among the images that see the
point (within `depth_images.VISIBLE_TEXELS` plus two grid cells of its first surface:
marching cubes and decimation each move it up to about a cell), each image's colour and
normal bilinear over its set texels. The blended normal shades it, as
the renderer lights with it; the surface's own normal where no image has one.
"""

from __future__ import annotations

import numpy as np

from ...bake.project import axis_frame
from ...core.transforms import transform_points
from ...errors import UsageError
from ...scene.mesh import RenderMesh, vertex_normals
from .depth_images import FACE_INDEX, visible_depth

#: The coarse trial grid's cells along the object's longest side.
TRIAL_CELLS = 24
#: The coarsest grid used (its mesh is decimated to a smaller budget).
MIN_CELLS = 6
#: The finest grid: cells along the longest side, at most (a 256^3 field is 128 MiB).
MAX_CELLS = 256
#: The smallest budget taken: below it, decimating the coarsest grid's mesh (its separate
#: parts, a tree's leaves) may not reach the count.
MIN_TRIANGLES = 100
#: Aim below the budget by this factor, so that one refinement usually fits.
AIM = 0.92
#: A depth object is carved on the grid that gives this many times the budget, then
#: decimated to it: thin parts that a coarser grid would miss are kept (measured on the
#: assimp spider at res 256: mask IoU with the object's own render 0.81-0.84 carved at the
#: budget, 0.89-0.92 at 2x, 0.91-0.93 at 4x in 3x the time; demo:vehicle 0.95 / 0.97 /
#: 0.98). A visual hull is carved at the budget: quadric decimation stops at 65-75% of its
#: meshes (its creases where silhouettes cross), after seconds.
OVERSAMPLE = 3.0
#: Grid points evaluated at once (bounds the field's temporaries to about 100 MiB).
SLAB_POINTS = 1 << 20


def fallback_mesh(rep, triangles: int = 20_000) -> RenderMesh:
    """The carved volume of depth object (or visual hull) ``rep`` as a closed triangle mesh of
    at most ``triangles`` triangles, in world coordinates, with vertex colours and normals
    (see the module docstring)."""
    if isinstance(triangles, bool) or not isinstance(triangles, int | np.integer) \
            or triangles < MIN_TRIANGLES:
        raise UsageError(f"a depth object's fallback mesh needs a whole number of at least "
                         f"{MIN_TRIANGLES} triangles, got {triangles!r}")
    images = rep.images
    field = CarvedField(images)
    lo, hi = _cube_box(rep)
    longest = float((hi - lo).max())
    finest = min(max(longest * images.resolution, MIN_CELLS), MAX_CELLS)
    cells = min(TRIAL_CELLS, finest)
    verts, faces, cell = _carve(field, lo, hi, longest / cells)
    if len(faces) == 0:
        raise UsageError("the depth images carve nothing: their object is empty, so it has "
                         "no fallback mesh")
    oversample = AIM if rep.hull else OVERSAMPLE
    cells = float(np.clip(cells * np.sqrt(oversample * triangles / len(faces)), MIN_CELLS,
                          finest))
    while True:
        verts, faces, cell = _carve(field, lo, hi, longest / cells)
        carved = len(faces)
        verts, faces = _decimated(verts, faces, triangles)
        if len(faces) <= triangles or cells <= MIN_CELLS:
            break
        # decimation fell short: the grid whose own count fits
        cells = max(MIN_CELLS, min(cells * np.sqrt(AIM * triangles / carved), cells - 1))
    if len(faces) > triangles:
        raise UsageError(f"the depth object's coarsest mesh could not be decimated to "
                         f"{triangles} triangles (left {len(faces)}); ask for more")
    world = transform_points(images.cube_to_world, verts)
    surface = vertex_normals(world.astype(np.float32), faces)
    colors, normals = _textured(field, verts, surface, 2 * cell)
    kind = "visual hull" if rep.hull else "depth object"
    return RenderMesh(world, faces, normals, colors, name=f"{kind} fallback")


def _decimated(verts: np.ndarray, faces: np.ndarray, triangles: int):
    """``verts``, ``faces`` simplified towards ``triangles`` by quadric decimation (which may
    stop short); as they are when already within it."""
    if len(faces) > triangles:
        import fast_simplification  # compiled extension: loaded only here

        verts, faces = fast_simplification.simplify(verts, faces, target_count=triangles)
    return verts, faces.astype(np.int64)


class CarvedField:
    """The signed field of the six images' intersection (positive inside, cube units): the
    least over images of min(distance behind the depth, signed distance into the
    silhouette)."""

    def __init__(self, images) -> None:
        from scipy.ndimage import distance_transform_edt  # scipy: slow to import

        self.images = images
        n = images.resolution
        self.to_face = np.stack([np.linalg.inv(images.box_to_world[k]) @ images.cube_to_world
                                 for k in range(6)])
        # per face: distance to the nearest texel on the other side, from texel centres,
        # minus half a texel to reach the edge between them
        self.silhouette = np.empty((6, n, n), np.float32)
        for k in range(6):
            mask = images.mask[k]
            if mask.all() or not mask.any():
                self.silhouette[k] = 1.0 if mask.any() else -1.0
                continue
            inside = distance_transform_edt(mask)
            outside = distance_transform_edt(~mask)
            self.silhouette[k] = np.where(mask, inside - 0.5, 0.5 - outside) / n

    def face_coords(self, k: int, q: np.ndarray) -> np.ndarray:
        """(..., 3) (u, v, h) of cube points q in image k's box."""
        return transform_points(self.to_face[k], q)

    def texel(self, f: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Column i and row j of the texel under face coordinates f (nearest, clamped)."""
        n = self.images.resolution
        i = np.clip(np.floor(f[..., 0] * n), 0, n - 1).astype(np.intp)
        j = np.clip(np.floor(f[..., 1] * n), 0, n - 1).astype(np.intp)
        return i, j

    def __call__(self, q: np.ndarray) -> np.ndarray:
        images = self.images
        out = np.full(q.shape[:-1], np.inf)
        for k in range(6):
            f = self.face_coords(k, q)
            i, j = self.texel(f)
            behind = 1.0 - f[..., 2] - images.depth[k][j, i]
            silhouette = _bilinear(self.silhouette[k], f[..., 0], f[..., 1])
            np.minimum(out, np.minimum(behind, silhouette), out=out)
        return out


def _cube_box(rep) -> tuple[np.ndarray, np.ndarray]:
    """The object's box in cube coordinates."""
    to_cube = np.linalg.inv(rep.images.cube_to_world)
    corners = transform_points(to_cube, rep.bounds)
    return corners.min(axis=0), corners.max(axis=0)


def _carve(field: CarvedField, lo, hi, cell: float):
    """Marching cubes of ``field`` on a grid of ``cell`` over [lo, hi] (cube units), padded
    with outside values so the surface closes: (V, 3) cube points, (F, 3) faces facing out,
    the cell."""
    from skimage.measure import marching_cubes  # scikit-image: slow to import

    counts = np.maximum(np.ceil((hi - lo) / cell).astype(int), 1) + 1
    start = (lo + hi) / 2 - (counts - 1) * cell / 2
    axes = [start[a] + cell * np.arange(counts[a]) for a in range(3)]
    values = np.empty(tuple(counts))
    step = max(1, SLAB_POINTS // int(counts[1] * counts[2]))
    for i in range(0, counts[0], step):
        x, y, z = np.meshgrid(axes[0][i:i + step], axes[1], axes[2], indexing="ij")
        values[i:i + step] = field(np.stack([x, y, z], axis=-1))
    padded = np.pad(values, 1, constant_values=-1.0)
    if padded.max() <= 0:
        return np.zeros((0, 3)), np.zeros((0, 3), np.int64), cell
    verts, faces, _, _ = marching_cubes(padded, level=0.0, spacing=(cell, cell, cell))
    verts = verts + (start - cell)
    faces = faces.astype(np.int64)
    corners = verts[faces]
    volume = np.einsum("ij,ij->i", corners[:, 0], np.cross(corners[:, 1], corners[:, 2])).sum()
    if volume < 0:
        faces = faces[:, ::-1]
    return verts, faces, cell


def _bilinear(values: np.ndarray, u, v) -> np.ndarray:
    """(N, N) ``values`` at texel centres, bilinear at (u, v) in [0, 1], clamped to the
    edge."""
    n = values.shape[0]
    x = np.clip(np.asarray(u) * n - 0.5, 0.0, n - 1.0)
    y = np.clip(np.asarray(v) * n - 0.5, 0.0, n - 1.0)
    x0, y0 = np.floor(x).astype(np.intp), np.floor(y).astype(np.intp)
    x1, y1 = np.minimum(x0 + 1, n - 1), np.minimum(y0 + 1, n - 1)
    fx, fy = x - x0, y - y0
    top = values[y0, x0] * (1 - fx) + values[y0, x1] * fx
    bottom = values[y1, x0] * (1 - fx) + values[y1, x1] * fx
    return top * (1 - fy) + bottom * fy


def _masked_bilinear(images, k: int, u, v) -> tuple[np.ndarray, np.ndarray]:
    """Image k's premultiplied colour (P, 4) and normal (P, 3) at (u, v), bilinear over its
    four nearest texels, each weighted by whether its column is set (texturing.glsl's
    masked_bilinear)."""
    n = images.resolution
    x = np.clip(u, 0.0, 1.0) * n - 0.5
    y = np.clip(v, 0.0, 1.0) * n - 0.5
    x0, y0 = np.floor(x).astype(np.intp), np.floor(y).astype(np.intp)
    fx, fy = x - x0, y - y0
    color = np.zeros(np.shape(u) + (4,))
    normal = np.zeros(np.shape(u) + (3,))
    for dx, dy in ((0, 0), (1, 0), (0, 1), (1, 1)):
        i = np.clip(x0 + dx, 0, n - 1)
        j = np.clip(y0 + dy, 0, n - 1)
        w = (fx if dx else 1 - fx) * (fy if dy else 1 - fy) * images.mask[k][j, i]
        c = images.color[k][j, i].astype(np.float64)
        color += w[:, None] * np.concatenate([c[:, :3] * c[:, 3:], c[:, 3:]], axis=1)
        normal += w[:, None] * images.normal[k][j, i]
    return color, normal


def _textured(field: CarvedField, q: np.ndarray, surface: np.ndarray, slack: float):
    """Vertex colours (V, 4) and normals (V, 3) of cube points ``q`` whose surface normal is
    ``surface``: the renderer's texturing seen along the normal (module docstring), a point
    seen by an image within ``slack`` more than the renderer's."""
    images = field.images
    n = images.resolution
    faces = sorted(FACE_INDEX, key=FACE_INDEX.get)
    outward = np.array([axis_frame(face)[2] for face in faces])  # (6, 3) world axes
    cosines = np.asarray(surface, np.float64) @ outward.T  # (V, 6)
    coords, sees = [], []
    for k in range(6):
        f = field.face_coords(k, q)
        i, j = field.texel(f)
        d = np.where(images.mask[k][j, i], images.depth[k][j, i], 2.0)
        coords.append(f)
        sees.append((d <= 1.0) & (1.0 - f[:, 2] - d <= visible_depth(n, slack)))
    facing = cosines > 0
    sees = np.stack(sees, axis=1) & facing
    usable = facing & (sees | ~sees.any(axis=1, keepdims=True))
    weights = np.where(usable, np.pi / 2 - np.arccos(np.clip(cosines, -1.0, 1.0)), 0.0)
    total = weights.sum(axis=1, keepdims=True)
    edge_on = total[:, 0] <= 0  # the nearest face only
    weights[edge_on] = np.eye(6)[np.argmax(cosines[edge_on], axis=1)]
    weights /= np.maximum(weights.sum(axis=1, keepdims=True), 1e-300)

    color = np.zeros((len(q), 4))
    normal = np.zeros((len(q), 3))
    for k in range(6):
        w = weights[:, k]
        some = w > 0
        if not some.any():
            continue
        c, nk = _masked_bilinear(images, k, coords[k][some, 0], coords[k][some, 1])
        color[some] += w[some, None] * c
        normal[some] += w[some, None] * nk
    straight = np.full((len(q), 4), 0.5)
    covered = color[:, 3] > 0
    straight[covered, :3] = color[covered, :3] / color[covered, 3:]
    straight[:, 3] = 1.0
    length = np.linalg.norm(normal, axis=1, keepdims=True)
    normals = np.where(length > 1e-6, normal / np.maximum(length, 1e-12), surface)
    return np.clip(straight, 0.0, 1.0).astype(np.float32), normals.astype(np.float32)
