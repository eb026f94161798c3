"""What a glTF viewer that knows nothing of displacement maps shows: the displaced surface.

Every base triangle is cut into n^2 triangles, n the largest that keeps the whole within
the triangle budget, and each lattice vertex is moved as the volume's parametrisation moves
it (`DisplacementMap.displaced_lattice`). Colours are per vertex, as the slices colour the
surface: the texture's colour tinted by the base's own surface. Where the texture's alpha
is below 0.5 the kind draws nothing (a projected mesh's background): a triangle whose
corners' mean alpha is below 0.5 is left out. A base with more triangles than the budget
keeps one triangle per base triangle (the count is then the base's).

The surface is open (the volume's base and sides are not drawn as surfaces here) and
double-sided, so a viewer shows it from below too.
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
    """``displacement``'s displaced surface as at most ``triangles`` triangles (or the base's
    count, when that is more), coloured per vertex."""
    lattice = displacement.displaced_lattice(
        subdivisions_within(displacement.triangle_count, triangles))
    colors = displacement.lattice_colors(lattice)
    shown = colors[lattice.faces, 3].mean(axis=1) >= 0.5
    if not shown.any():
        raise UsageError("the displacement map's texture is transparent everywhere: its "
                         "fallback has no triangle")
    used = np.unique(lattice.faces[shown])
    remap = np.zeros(len(lattice.positions), np.int64)
    remap[used] = np.arange(len(used))
    positions, faces = lattice.positions[used], remap[lattice.faces[shown]]
    colors = colors[used]
    colors[:, 3] = 1.0
    return RenderMesh(positions, faces, vertex_normals(positions, faces),
                      colors.astype(np.float32), name="displacement fallback",
                      materials=[Material(name="displacement fallback", double_sided=True)])
