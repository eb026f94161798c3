"""What a glTF viewer that knows nothing of relief textures shows: each heightfield as a mesh.

The heightfield is resampled on a grid of vertices over the rectangle its non-empty texels
span (out to the empty texels around them; the whole bottom face of a cube's part), bilinear
between texel centres and clamped at the border as the shader samples it, with as many
cells as the triangle budget allows (no more than the rectangle has texels); each
vertex (u, v, h) is mapped through ``box_to_world``, projective or not. A cell whose corners
all lie on empty texels (height 0 around them) is left out; a cell beside one keeps the ramp
down to the floor that the relief draws there too (its walls at the footprint's edge, which
are the solid's sides seen from below or the side; leaving out every cell with an empty
corner instead took a terrain block's IoU against its mesh from 0.976 / 0.974 / 0.972 to
0.516 / 0.514 / 0.935, the vehicle's from 0.861 / 0.881 / 0.942 to 0.816 / 0.769 / 0.948).
Where the surface stands on the grid's
border (a heightmap fills its box, a cube's part its face) walls go down from it to h = 0,
the box's sides that the relief draws there: a 96² heightmap's fallback against its relief,
mask IoU 0.797 / 0.799 / 0.980 without them, 0.999 / 0.999 / 1.000 with them.

A relief object's parts keep only the outermost surface along their rays and fill what lies
behind with steep walls (radial curtains, docs/relief.md). The fallback keeps them: leaving
out the triangles within 12 degrees of a part's rays lowered the blob cube's mask IoU
against its mesh from 0.937 / 0.945 / 0.812 to 0.879 / 0.907 / 0.695 (three views), as a
steep cut cannot tell a curtain from a surface every part sees at a grazing angle (the
blob's ring). Cutting only isolated steps (a radial jump over three times the lateral
spacing, three times its neighbours') did no better: 0.941 / 0.949 / 0.811 -> 0.938 /
0.963 / 0.725 on the blob's 128² cube.

Cut to ``clip_bounds``, the cut is left open: a bake's clip box lies around its mesh, where
only the floor's walls could reach it.

The result is open below (a relief texture knows only its top) and double-sided, so a viewer
shows the colour under it as the relief does from below.
"""

from __future__ import annotations

import numpy as np

from ...errors import UsageError
from ...scene.mesh import Material, RenderMesh, vertex_normals


def relief_fallback(relief, triangles: int) -> RenderMesh:
    """``relief``'s heightfield as at most ``triangles`` triangles, textured by its colour."""
    return _assembled([relief], [triangles], name="relief fallback")


def relief_object_fallback(obj, triangles: int) -> RenderMesh:
    """The parts of a relief object, ``triangles`` shared out by the parts' texels."""
    if triangles < 2 * len(obj.parts):
        raise UsageError(f"a fallback of a relief object's {len(obj.parts)} parts needs at "
                         f"least {2 * len(obj.parts)} triangles, got {triangles}")
    texels = np.array([p.height.size for p in obj.parts], np.float64)
    spare = triangles - 2 * len(obj.parts)  # two each, the rest by texels
    shares = 2 + np.floor(spare * texels / texels.sum()).astype(int)
    return _assembled(obj.parts, list(shares), name="relief object fallback")


def grid_cells(width: int, height: int, triangles: int) -> tuple[int, int]:
    """(cells along u, cells along v): two triangles a cell, at most ``triangles`` in all,
    the cells as square in texels as the budget allows and no more cells than texels."""
    if triangles < 2:
        raise UsageError(f"a heightfield's fallback needs at least 2 triangles, got "
                         f"{triangles}")
    cells = triangles // 2
    scale = np.sqrt(cells / (width * height))
    across = int(np.clip(np.floor(width * scale), 1, width))
    down = int(np.clip(cells // across, 1, height))
    return across, down


def footprint(height: np.ndarray) -> tuple[np.ndarray, tuple[int, int]]:
    """((2, 2) box coordinates [[u0, v0], [u1, v1]] of the rectangle the surface spans, (its
    texels across, down)): the covered texels' rectangle out to the centres of the empty
    texels around it, where the ramps down to the floor end, within [0, 1]."""
    h, w = height.shape
    columns = np.flatnonzero(height.any(axis=0))
    rows = np.flatnonzero(height.any(axis=1))
    lo = np.array([columns[0], rows[0]]) - 0.5   # texel coordinates of the empty centres
    hi = np.array([columns[-1], rows[-1]]) + 1.5
    size = np.array([w, h])
    span = np.stack([np.maximum(lo, 0.0), np.minimum(hi, size)]) / size
    return span, tuple(int(n) for n in np.minimum(hi - lo, size).round())


def surface_grid(relief, span, across: int, down: int) -> tuple[np.ndarray, np.ndarray]:
    """((down + 1, across + 1, 3) box coordinates (u, v, h) of a grid's vertices over
    ``span`` (`footprint`), (F, 3) corners of the triangles of its cells that touch a
    non-empty texel), vertex j * (across + 1) + i at the grid's i-th u and j-th v."""
    from ...reference.heightfield import surface_height  # numba: slow to import

    w, h = relief.depth_resolution
    u = np.linspace(span[0][0], span[1][0], across + 1)
    v = np.linspace(span[0][1], span[1][1], down + 1)
    uu, vv = np.meshgrid(u, v)
    heights = surface_height(relief.height, uu * w, vv * h)
    uvh = np.stack([uu, vv, heights], axis=-1)
    corner = (np.arange(down)[:, None] * (across + 1) + np.arange(across)[None, :]).ravel()
    # counter-clockwise seen from +h in box coordinates
    quads = np.stack([corner, corner + 1, corner + across + 2, corner + across + 1], axis=1)
    faces = np.concatenate([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])
    flat = heights.ravel()
    return uvh, faces[(flat[faces] > 0.0).any(axis=1)]


def side_walls(grid: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """((4K, 3) box coordinates, (2K, 3) corners) of the walls from a grid's border down to
    h = 0, where the surface stands on the border (a field that fills its box, a cube's
    part): the sides of the box that the relief draws there. Each wall has its own four
    corners and faces out of the grid."""
    # the border once around, counter-clockwise seen from +h: the inside on the left
    loop = np.concatenate([grid[0, :-1], grid[:-1, -1], grid[-1, ::-1][:-1],
                           grid[::-1, 0][:-1]])
    a, b = loop, np.roll(loop, -1, axis=0)
    standing = (a[:, 2] > 0.0) | (b[:, 2] > 0.0)
    a, b = a[standing], b[standing]
    floor = np.array([1.0, 1.0, 0.0])
    corners = np.stack([b, a, a * floor, b * floor], axis=1).reshape(-1, 3)
    k = 4 * np.arange(len(a))[:, None]
    return corners, np.concatenate([np.concatenate([k, k + 1, k + 2], 1),
                                    np.concatenate([k, k + 2, k + 3], 1)])


def part_mesh(relief, triangles: int):
    """(world positions (V, 3) float64, uvs (V, 2), faces (F, 3)) of one heightfield within
    ``triangles``, cut to its ``clip_bounds``, front faces towards +h."""
    span, texels = footprint(relief.height)
    across, down = grid_cells(*texels, triangles)
    while True:
        grid, faces = surface_grid(relief, span, across, down)
        wall_uvh, wall_faces = side_walls(grid)
        uvh = np.concatenate([grid.reshape(-1, 3), wall_uvh])
        faces = np.concatenate([faces, wall_faces + grid.shape[0] * grid.shape[1]])
        positions = relief.to_world(uvh)
        if np.linalg.det(relief.box_to_world) < 0:  # a mirroring map turns the winding over
            faces = faces[:, ::-1]
        uvs = uvh[:, :2]
        if relief.clip_bounds is not None:
            positions, uvs, faces = clipped(positions, uvs, faces, relief.clip_bounds)
        if len(faces) <= triangles or (across == 1 and down == 1):
            return positions, uvs, faces
        # the walls, and clipping's triangles cut in two: a coarser grid leaves room
        shrink = np.sqrt(triangles / len(faces))
        across, down = max(1, int(across * shrink)), max(1, int(down * shrink))


def clipped(positions, uvs, faces, bounds):
    """Triangles cut to the world box ``bounds`` (2, 3), one plane at a time; the corners a
    cut makes are interpolated along the edge it crosses (uvs are affine in world on a
    triangle)."""
    positions, uvs, faces = np.asarray(positions, np.float64), np.asarray(uvs), faces
    for axis in range(3):
        for sign, limit in ((1.0, bounds[0][axis]), (-1.0, bounds[1][axis])):
            positions, uvs, faces = _cut(positions, uvs, faces,
                                         sign * (positions[:, axis] - limit))
    used = np.unique(faces)
    remap = np.zeros(len(positions), np.int64)
    remap[used] = np.arange(len(used))
    return positions[used], uvs[used], remap[faces]


def _cut(positions, uvs, faces, distance):
    """Keep the part of each triangle where ``distance`` (per vertex) >= 0."""
    inside = distance[faces] >= 0.0
    count = inside.sum(axis=1)
    kept = [faces[count == 3]]
    new_points, new_uvs = [], []
    base = len(positions)

    def edge_points(a, b):  # where a's edge to b crosses the plane, both sides ordered alike
        lo, hi = np.minimum(a, b), np.maximum(a, b)
        t = (distance[lo] / (distance[lo] - distance[hi]))[:, None]
        nonlocal base
        index = base + np.arange(len(a))
        base += len(a)
        new_points.append(positions[lo] + t * (positions[hi] - positions[lo]))
        new_uvs.append(uvs[lo] + t * (uvs[hi] - uvs[lo]))
        return index

    for inside_count in (1, 2):
        tris = faces[count == inside_count]
        if not len(tris):
            continue
        # rotate each triangle so that its lone vertex (inside for 1, outside for 2) is first
        lone = np.argmax(inside[count == inside_count] == (inside_count == 1), axis=1)
        order = (lone[:, None] + np.arange(3)) % 3
        a, b, c = (np.take_along_axis(tris, order, axis=1)[:, k] for k in range(3))
        ab, ac = edge_points(a, b), edge_points(a, c)
        if inside_count == 1:
            kept.append(np.stack([a, ab, ac], axis=1))
        else:
            kept.append(np.stack([ab, b, c], axis=1))
            kept.append(np.stack([ab, c, ac], axis=1))
    positions = np.concatenate([positions, *new_points])
    uvs = np.concatenate([uvs, *new_uvs])
    return positions, uvs, np.concatenate(kept).astype(np.int64)


def _assembled(parts, budgets, name: str) -> RenderMesh:
    """One mesh of the parts' meshes, one double-sided material per part's colour."""
    positions, uvs, faces, material = [], [], [], []
    offset = 0
    for k, (relief, budget) in enumerate(zip(parts, budgets, strict=True)):
        p, uv, f = part_mesh(relief, budget)
        positions.append(p)
        uvs.append(uv)
        faces.append(f + offset)
        material.append(np.full(len(f), k, np.uint16))
        offset += len(p)
    positions = np.concatenate(positions)
    faces = np.concatenate(faces)
    if not len(faces):
        raise UsageError(f"a fallback of {sum(budgets)} triangles leaves none of the "
                         "heightfield (its grid's corners all fall on empty texels, or the "
                         "clip box cuts it away): allow more triangles")
    materials = [Material(name=f"{name} {k}", texture=relief.color, double_sided=True)
                 for k, relief in enumerate(parts)]
    return RenderMesh(positions, faces, vertex_normals(positions, faces),
                      np.ones((len(positions), 4), np.float32), np.concatenate(uvs),
                      name=name, materials=materials, material=np.concatenate(material))

