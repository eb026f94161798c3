"""What a glTF viewer that knows nothing of displacement maps shows: the displaced surface.

Every base triangle is cut into n^2 triangles, n the largest that keeps the whole within
the triangle budget, and each lattice vertex is moved as the volume's parametrisation moves
it (`DisplacementMap.displaced_lattice`); the lattices of neighbouring base triangles are
welded where their points coincide. Colours are per vertex, as the slices colour the
surface: the texture's colour tinted by the base's own surface. Where the texture's alpha
is below 0.5 the kind draws nothing (a projected mesh's background): a triangle whose
corners' mean alpha is below 0.5 is left out. The slices fill the volume between the base
and the surface, so wherever the surface ends (an open base's border, the edge of the
opaque part, a seam of the uv map) a wall goes down to the base, as the volume's side
shows there. A base with more triangles than the budget keeps one triangle per base
triangle, and its walls (the count is then the base's and theirs).

The surface is open below (the base is not drawn) and double-sided, so a viewer shows it
from below too.
"""

from __future__ import annotations

import numpy as np

from ...errors import UsageError
from ...scene.mesh import Material, RenderMesh, vertex_normals

#: `DisplacementMap.displaced_lattice`'s finest lattice.
MAX_SUBDIVISIONS = 256


def subdivisions_within(base_triangles: int, triangles: int) -> int:
    """The largest n with base_triangles * n^2 <= triangles (at least 1)."""
    if triangles < 1:
        raise UsageError(f"a displacement map's fallback needs at least 1 triangle, got "
                         f"{triangles}")
    n = int(np.sqrt(triangles / base_triangles))
    while base_triangles * n * n > triangles:  # the square root's rounding
        n -= 1
    return int(np.clip(n, 1, MAX_SUBDIVISIONS))


def displacement_fallback(displacement, triangles: int) -> RenderMesh:
    """``displacement``'s displaced surface and its walls as at most ``triangles`` triangles
    (or the base's count and its walls, when that is more), coloured per vertex."""
    n = subdivisions_within(displacement.triangle_count, triangles)
    while True:
        positions, colors, faces = _displaced(displacement, n)
        if len(faces) <= triangles or n == 1:
            break
        n -= 1  # the walls took the room
    colors[:, 3] = 1.0
    return RenderMesh(positions, faces, vertex_normals(positions, faces),
                      colors.astype(np.float32), name="displacement fallback",
                      materials=[Material(name="displacement fallback", double_sided=True)])


def _displaced(displacement, subdivisions: int):
    """(positions, colours, faces) of the welded, shown lattice and its walls."""
    lattice = displacement.displaced_lattice(subdivisions)
    colors = displacement.lattice_colors(lattice)
    shown = colors[lattice.faces, 3].mean(axis=1) >= 0.5
    if not shown.any():
        raise UsageError("the displacement map's texture is transparent everywhere: its "
                         "fallback has no triangle")
    # one vertex per displaced point and its base point (a uv seam keeps two)
    both = np.concatenate([lattice.positions, lattice.base], axis=1)
    quantum = 1e-9 * max(float(np.ptp(both, axis=0).max()), 1e-300)
    _, first, weld = np.unique(np.round(both / quantum), axis=0, return_index=True,
                               return_inverse=True)
    faces = weld.reshape(-1)[lattice.faces[shown]]
    used = np.unique(faces)
    remap = np.zeros(len(first), np.int64)
    remap[used] = np.arange(len(used))
    kept = first[used]
    top, base, colors = lattice.positions[kept], lattice.base[kept], colors[kept]
    faces = remap[faces]
    a, b = _border(faces)
    lifted = (np.abs(top[a] - base[a]).max(axis=1) > quantum) | (
        np.abs(top[b] - base[b]).max(axis=1) > quantum)
    a, b = a[lifted], b[lifted]
    # each wall its own four corners (crisp normals): b, a on top, a', b' on the base,
    # facing away from the surface triangle the edge a -> b belongs to
    count = len(top)
    corners = np.concatenate([np.stack([b, a], 1), np.stack([a, b], 1)], axis=1)
    wall_points = np.concatenate([top[corners[:, :2]], base[corners[:, 2:]]], axis=1)
    k = count + 4 * np.arange(len(a))[:, None]
    wall_faces = np.concatenate([np.concatenate([k, k + 1, k + 2], 1),
                                 np.concatenate([k, k + 2, k + 3], 1)])
    return (np.concatenate([top, wall_points.reshape(-1, 3)]),
            np.concatenate([colors, colors[corners].reshape(-1, 4)]),
            np.concatenate([faces, wall_faces]))


def _border(faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(a, b): the edges a -> b that one triangle alone has, as that triangle orders them."""
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    _, inverse, counts = np.unique(np.sort(edges, axis=1), axis=0, return_inverse=True,
                                   return_counts=True)
    alone = edges[counts[inverse.reshape(-1)] == 1]
    return alone[:, 0], alone[:, 1]
