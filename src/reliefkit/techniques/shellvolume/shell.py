"""The shell of a shell volume: every triangle of a mesh extruded along its vertex normals
into a prism, every prism split into three tetrahedra (Dufort, Leblanc & Poulin 2005, §3).

The renderer draws one tetrahedron per primitive: it enters through a front face, leaves
through one of the other three planes and maps both points to the 3D texture with the
tetrahedron's affine object-to-texture matrix. So each tetrahedron carries its vertices'
(u, v, w), its four face planes and its matrix, and the visibility sort walks the face
adjacency. All of it is pure numpy, in float64 world coordinates.

**The split.** The three tetrahedra of neighbouring prisms must meet face to face: a side
quad shared by two prisms has to be cut by the same diagonal on both sides, or the shell has
cracks and overlaps. The rule only looks at global vertex indices, which both prisms agree
on (welded: the copies of a vertex that a uv seam splits count as the lowest of them, so the
prisms on both sides of a seam agree too, and become neighbours): a side quad over the base
edge (p, q) with p < q is cut by the diagonal from p's base vertex to q's top vertex. With
the triangle's indices sorted, i < j < k, the tetrahedra

    (i, j, k, k'),  (i, j, j', k'),  (i, i', j', k')

contain exactly those diagonals: i-j' (quad ij: halves (i, j, j') and (i, i', j')), j-k'
(quad jk: (j, k, k') and (j, j', k')) and i-k' (quad ik: (i, k, k') and (i, i', k')). Their
two inner faces, (i, j, k') and (i, j', k'), are the only faces the three share.

**Inverted.** The intended orientation of a prism is the ideal one: its base triangle with
the tops on the side the extrusion goes to (the side of the triangle's plane that the sum of
its three extrusion offsets points to), as a straight prism over it would be. Each
tetrahedron is stored in the vertex order that gives it a positive volume in that ideal
prism, so neither the triangle's winding nor the sorting by index can make one look
inverted. A tetrahedron is *inverted* when its real signed volume in that order is not
positive (below a tolerance relative to its size): its prism folded over, as a too thick
shell does over a concave region. Two tetrahedra on the same side of the face they share
(prisms that fold onto each other) are refused the same way. Intersections between prisms
that are not neighbours are not looked for.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import UsageError

#: Extrusion directions `build_shell` knows.
DIRECTIONS = ("normals",)

#: A tetrahedron whose 6 x volume is at most this times its longest edge cubed is flat.
FLAT = 1e-9

# The three tetrahedra of a prism, as positions in (i, j, k, i', j', k') with i < j < k.
_SPLIT = np.array([[0, 1, 2, 5], [0, 1, 4, 5], [0, 3, 4, 5]])


@dataclass(frozen=True, eq=False)
class ShellVolume:
    """A shell of tetrahedra over a mesh: base vertices 0..V-1 (w = 0), tops V..2V-1 (w = 1).

    Attributes
    ----------
    positions : (2V, 3) float64 world positions: the base vertices, then their tops.
    uvw : (2V, 3) float64 texture coordinates: the mesh's (u, v), w = 0 or 1.
    normals, tangents, bitangents : (2V, 3) float64 unit local frame per vertex for shading
        (normal = extrusion direction; tangent and bitangent follow u and v).
    tets : (T, 4) int32 shell-vertex indices, each tetrahedron with positive volume.
    object_to_texture : (T, 4, 4) float64 affine M with M @ (x, y, z, 1) = (u, v, w, 1).
    planes : (T, 4, 4) float64 (a, b, c, d) of face f (opposite vertex f): outward unit
        normal (a, b, c), the inside where plane @ (x, y, z, 1) <= 0.
    neighbors : (T, 4) int32 tetrahedron across face f, -1 on the shell's boundary.
    neighbor_faces : (T, 4) int8 which face of that neighbour it is, -1 on the boundary.
    thickness : (V,) float64 extrusion length per base vertex.
    """

    positions: np.ndarray
    uvw: np.ndarray
    normals: np.ndarray
    tangents: np.ndarray
    bitangents: np.ndarray
    tets: np.ndarray
    object_to_texture: np.ndarray
    planes: np.ndarray
    neighbors: np.ndarray
    neighbor_faces: np.ndarray
    thickness: np.ndarray

    def tetrahedra(self) -> np.ndarray:
        """(T, 4, 3) float64 world positions of every tetrahedron's vertices."""
        return self.positions[self.tets]

    def boundary_faces(self) -> np.ndarray:
        """(N, 2) int64 (tetrahedron, face) of every face on the shell's boundary."""
        return np.argwhere(self.neighbors < 0)

    def volumes(self) -> np.ndarray:
        """(T,) float64 volume of every tetrahedron (all positive)."""
        return _signed_volumes(self.tetrahedra())

    def summary(self) -> dict:
        """Counts and sizes, for messages and reports."""
        boundary = int((self.neighbors < 0).sum())
        return {"base_vertices": len(self.thickness), "vertices": len(self.positions),
                "prisms": len(self.tets) // 3, "tetrahedra": len(self.tets),
                "interior_faces": (self.neighbors.size - boundary) // 2,
                "boundary_faces": boundary, "volume": float(self.volumes().sum()),
                "thickness": (float(self.thickness.min()), float(self.thickness.max()))}


def build_shell(mesh, thickness, direction: str = "normals") -> ShellVolume:
    """Extrude `mesh` (a RenderMesh with uvs) by `thickness` along `direction` into a shell.

    thickness: a positive number (world units) or (V,) positive numbers, one per vertex.
    direction: "normals", the mesh's vertex normals (normalized).
    Raises UsageError for bad arguments, a mesh without uvs, degenerate triangles or texture
    mappings, inverted tetrahedra (a too thick shell) and non-manifold input.
    """
    if mesh.uvs is None:
        raise UsageError(f"{mesh.name}: a shell volume needs texture coordinates (uvs)")
    base = mesh.world_positions
    faces = np.asarray(mesh.indices, dtype=np.int64)
    count = len(base)
    offsets_len = _thickness(thickness, count)
    normals = _directions(mesh, direction)
    _check_triangles(base, faces)
    positions = np.concatenate([base, base + offsets_len[:, None] * normals])
    uv = np.asarray(mesh.uvs, dtype=np.float64)
    uvw = np.concatenate([np.column_stack([uv, np.zeros(count)]),
                          np.column_stack([uv, np.ones(count)])])
    welded = _welded(positions, count)
    tets = _split_prisms(positions, faces, count, welded)
    corners = positions[tets]
    planes = _face_planes(corners)
    neighbors, neighbor_faces = _shell_adjacency(tets, welded)
    _check_folds(planes, neighbors, neighbor_faces)
    tangents, bitangents = _tangent_frames(base, uv, faces, normals)
    return ShellVolume(
        positions=positions, uvw=uvw, normals=np.concatenate([normals, normals]),
        tangents=np.concatenate([tangents, tangents]),
        bitangents=np.concatenate([bitangents, bitangents]),
        tets=tets.astype(np.int32), object_to_texture=_object_to_texture(corners, uvw[tets]),
        planes=planes, neighbors=neighbors, neighbor_faces=neighbor_faces,
        thickness=offsets_len)


#: A triangle whose vertex normal makes a smaller cosine than this with its own normal is
#: no use for a shell: its prism is inverted (or flat) at any thickness.
MIN_NORMAL_COSINE = 0.05


def unusable_triangles(mesh) -> np.ndarray:
    """(F,) bool: triangles whose prism would have no volume or no texture mapping (no area
    in space or in uv, or a vertex normal pointing along or behind the triangle); a baker may
    leave them out of the shell."""
    faces = np.asarray(mesh.indices, dtype=np.int64)
    flat, unit = _flat_triangles(mesh.world_positions, faces)
    normals = np.asarray(mesh.normals, dtype=np.float64)
    normals = normals / np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-30)
    cosines = np.einsum("fi,fki->fk", unit, normals[faces])
    flat |= (cosines < MIN_NORMAL_COSINE).any(axis=1)
    if mesh.uvs is None:
        return flat
    uv = np.asarray(mesh.uvs, dtype=np.float64)[faces]
    du, dv = uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0]
    uv_edge = np.max(np.linalg.norm(uv - np.roll(uv, 1, axis=1), axis=2), axis=1)
    no_uv = np.abs(du[:, 0] * dv[:, 1] - du[:, 1] * dv[:, 0]) <= FLAT * uv_edge ** 2
    return flat | no_uv


def fitted_thickness(mesh, thickness, direction: str = "normals",
                     halvings: int = 12) -> np.ndarray:
    """(V,) per-vertex thickness: ``thickness`` everywhere the shell does not fold, halved
    (repeatedly, up to ``halvings`` times) at the vertices of the tetrahedra that would be
    inverted or folded onto a neighbour — so a shell over a detailed mesh gets thinner only
    in its tight concave places instead of being refused. Raises UsageError if folds remain.
    """
    base = mesh.world_positions
    faces = np.asarray(mesh.indices, dtype=np.int64)
    count = len(base)
    values = _thickness(thickness, count).copy()
    normals = _directions(mesh, direction)
    for _ in range(halvings + 1):
        positions = np.concatenate([base, base + values[:, None] * normals])
        welded = _welded(positions, count)
        tets = _prism_tets(positions, faces, count, welded)
        bad = _inverted(positions[tets])
        if not bad.any():
            neighbors, neighbor_faces = _shell_adjacency(tets, welded)
            bad = _folded(_face_planes(positions[tets]), neighbors, neighbor_faces)
        if not bad.any():
            return values
        values[np.unique(tets[bad] % count)] *= 0.5
    raise UsageError(f"{mesh.name}: the shell still folds after thinning it {halvings} times "
                     "where it folds; smooth the mesh's normals or give a smaller thickness")


def _thickness(thickness, count: int) -> np.ndarray:
    """(V,) float64 positive finite thickness from a number or a per-vertex array."""
    if isinstance(thickness, bool):
        raise UsageError(f"thickness must be a positive number or {count} numbers, "
                         "got a bool")
    try:
        arr = np.asarray(thickness, dtype=np.float64)
    except (TypeError, ValueError):
        raise UsageError(f"thickness must be a positive number or {count} numbers, "
                         f"got {thickness!r}") from None
    if arr.ndim == 0:
        arr = np.full(count, float(arr))
    elif arr.shape != (count,):
        raise UsageError(f"thickness must be a number or one per vertex ({count},), "
                         f"got shape {arr.shape}")
    bad = ~(np.isfinite(arr) & (arr > 0))
    if bad.any():
        raise UsageError(f"thickness must be positive and finite, {int(bad.sum())} "
                         f"value(s) are not (e.g. {arr[bad][0]!r})")
    return arr


def _directions(mesh, direction) -> np.ndarray:
    """(V, 3) float64 unit extrusion directions."""
    if direction not in DIRECTIONS:
        raise UsageError(f"direction must be one of {', '.join(DIRECTIONS)}, "
                         f"got {direction!r}")
    normals = np.asarray(mesh.normals, dtype=np.float64)
    length = np.linalg.norm(normals, axis=1)
    if not (length > 1e-12).all():
        raise UsageError(f"{mesh.name}: {int((length <= 1e-12).sum())} vertex normal(s) "
                         "are zero; they give no extrusion direction")
    return normals / length[:, None]


def _check_triangles(base: np.ndarray, faces: np.ndarray) -> None:
    """Refuse triangles with a repeated corner or no area: their prisms have no volume."""
    flat = _flat_triangles(base, faces)[0] | (faces[:, 0] == faces[:, 1]) \
        | (faces[:, 1] == faces[:, 2]) | (faces[:, 0] == faces[:, 2])
    if flat.any():
        raise UsageError(f"{int(flat.sum())} of {len(faces)} triangles are degenerate "
                         "(no area); remove them before building a shell")


def _flat_triangles(base: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(F,) bool triangles with no area (relative to their longest edge), and (F, 3) their
    unit normals (anything where flat)."""
    a, b, c = (base[faces[:, k]] for k in range(3))
    edge = np.max([np.linalg.norm(b - a, axis=1), np.linalg.norm(c - b, axis=1),
                   np.linalg.norm(a - c, axis=1)], axis=0)
    cross = np.cross(b - a, c - a)
    area2 = np.linalg.norm(cross, axis=1)
    flat = area2 <= FLAT * edge ** 2
    return flat, cross / np.where(flat, 1.0, area2)[:, None]


def _welded(positions: np.ndarray, count: int) -> np.ndarray:
    """(2V,) the lowest shell vertex index at the same base and top positions as each vertex:
    a uv seam's two copies of a vertex become one, so the prisms on either side split their
    shared quad the same way and meet as neighbours."""
    pairs = np.concatenate([positions[:count], positions[count:]], axis=1)
    _, first, inverse = np.unique(pairs, axis=0, return_index=True, return_inverse=True)
    base = first[inverse.ravel()]
    return np.concatenate([base, base + count])


def _split_prisms(positions: np.ndarray, faces: np.ndarray, count: int,
                  welded: np.ndarray) -> np.ndarray:
    """`_prism_tets`, refused when some are inverted (see the module docstring)."""
    tets = _prism_tets(positions, faces, count, welded)
    _check_inverted(positions[tets])
    return tets


def _prism_tets(positions: np.ndarray, faces: np.ndarray, count: int,
                welded: np.ndarray) -> np.ndarray:
    """(3F, 4) int64 tetrahedra, each in the vertex order positive in its ideal prism; the
    diagonals follow the welded indices, so a seam's two sides agree."""
    order = np.argsort(welded[faces], axis=1, kind="stable")  # corners i < j < k
    ijk = np.take_along_axis(faces, order, axis=1)
    prism = np.concatenate([ijk, ijk + count], axis=1)  # (i, j, k, i', j', k')
    tets = prism[:, _SPLIT]  # (F, 3, 4)
    ideal = _ideal_signs(positions, faces, order, count)
    flip = ideal < 0
    tets[flip, 0], tets[flip, 1] = tets[flip, 1], tets[flip, 0].copy()
    return tets.reshape(-1, 4)


def _ideal_signs(positions: np.ndarray, faces: np.ndarray, order: np.ndarray,
                 count: int) -> np.ndarray:
    """(F, 3) sign of each tetrahedron's volume in the ideal prism of its triangle.

    The ideal prism puts the winding's corners at (0, 0), (1, 0), (0, 1) (counter-clockwise)
    and the tops at height +1 when the extrusion goes to the front of the triangle (the side
    of (b - a) x (c - a)), -1 when it goes to the back.
    """
    a, b, c = (positions[faces[:, k]] for k in range(3))
    tops = positions[faces + count] - positions[faces]
    side = np.sign(np.einsum("fi,fi->f", np.cross(b - a, c - a), tops.sum(axis=1)))
    side[side == 0] = 1  # an extrusion along the triangle's plane: flat, caught later
    flat = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])[order]  # (F, 3, 2) for i, j, k
    low = np.concatenate([flat, np.zeros(flat.shape[:2] + (1,))], axis=2)
    high = np.concatenate([flat, side[:, None, None] * np.ones(flat.shape[:2] + (1,))], axis=2)
    ideal = np.concatenate([low, high], axis=1)[:, _SPLIT]  # (F, 3, 4, 3)
    return np.sign(_signed_volumes(ideal.reshape(-1, 4, 3))).reshape(-1, 3)


def _signed_volumes(corners: np.ndarray) -> np.ndarray:
    """(T,) signed volume of (T, 4, 3) tetrahedra: positive when 1, 2, 3 turn
    counter-clockwise seen from outside, i.e. det(p1 - p0, p2 - p0, p3 - p0) > 0."""
    edges = corners[:, 1:] - corners[:, :1]
    return np.linalg.det(edges) / 6.0


def _inverted(corners: np.ndarray) -> np.ndarray:
    """(T,) bool: tetrahedra flat or inverted relative to their ideal prism."""
    six = 6.0 * _signed_volumes(corners)
    pairs = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
    longest = np.max([np.linalg.norm(corners[:, p] - corners[:, q], axis=1)
                      for p, q in pairs], axis=0)
    return six <= FLAT * longest ** 3


def _check_inverted(corners: np.ndarray) -> None:
    """Refuse tetrahedra that are flat or inverted relative to their ideal prism."""
    bad = _inverted(corners)
    if bad.any():
        raise UsageError(f"{int(bad.sum())} of {len(corners)} tetrahedra are inverted or flat "
                         "(the extruded shell folds over itself); use a smaller thickness")


def _face_planes(corners: np.ndarray) -> np.ndarray:
    """(T, 4, 4) plane (a, b, c, d) of face f, opposite vertex f, with outward unit normal."""
    planes = np.empty(corners.shape[:1] + (4, 4))
    for f in range(4):
        q = corners[:, [v for v in range(4) if v != f]]
        normal = np.cross(q[:, 1] - q[:, 0], q[:, 2] - q[:, 0])
        normal /= np.linalg.norm(normal, axis=1, keepdims=True)
        toward = np.einsum("ti,ti->t", normal, corners[:, f] - q[:, 0])
        normal[toward > 0] *= -1  # away from the opposite vertex
        planes[:, f, :3] = normal
        planes[:, f, 3] = -np.einsum("ti,ti->t", normal, q[:, 0])
    return planes


def _object_to_texture(corners: np.ndarray, uvw: np.ndarray) -> np.ndarray:
    """(T, 4, 4) affine M with M @ (x, 1) = (uvw, 1) at the four corners.

    Solved relative to the first corner (world coordinates far from the origin would cost
    digits), then composed with the translation. Raises UsageError when the texture-space
    tetrahedron is flat (the UV triangle has no area): M would not be invertible.
    """
    edges = corners[:, 1:] - corners[:, :1]  # (T, 3, 3) rows p_k - p_0
    tex = uvw[:, 1:] - uvw[:, :1]
    uv_edge = np.linalg.norm(tex[:, :, :2], axis=2).max(axis=1)
    flat = np.abs(np.linalg.det(tex)) <= FLAT * uv_edge ** 2
    if flat.any():
        raise UsageError(f"{int(flat.sum())} of {len(corners)} tetrahedra have a degenerate "
                         "texture mapping (UV triangles with no area)")
    linear = np.linalg.solve(edges, tex).transpose(0, 2, 1)  # A with A @ edge = tex edge
    m = np.zeros(corners.shape[:1] + (4, 4))
    m[:, :3, :3] = linear
    m[:, :3, 3] = uvw[:, 0] - np.einsum("tij,tj->ti", linear, corners[:, 0])
    m[:, 3, 3] = 1.0
    return m


def _shell_adjacency(tets: np.ndarray, welded: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """`_adjacency` with uv seams joined (one shell, no boundary there); by the mesh's own
    connectivity alone where joining them makes it non-manifold (coincident surfaces)."""
    try:
        return _adjacency(welded[tets])
    except UsageError:
        return _adjacency(tets)


def _adjacency(tets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(T, 4) neighbour and its face across each face, -1 on the boundary.

    Faces are matched by their sorted vertex triples; a triple met more than twice means
    the mesh is not manifold (three triangles on one edge, or a duplicated triangle).
    """
    total = len(tets)
    faces = np.stack([np.delete(tets, f, axis=1) for f in range(4)], axis=1).reshape(-1, 3)
    keys = np.sort(faces, axis=1)
    order = np.lexsort(keys.T[::-1])
    keys = keys[order]
    same = (keys[1:] == keys[:-1]).all(axis=1)
    if (same[1:] & same[:-1]).any():
        over = int((same[1:] & same[:-1]).sum())
        raise UsageError(f"{over} shell face(s) are shared by more than two tetrahedra; the "
                         "mesh is not manifold (an edge on three triangles, or a duplicate)")
    first, second = order[:-1][same], order[1:][same]
    flat_neighbor = np.full(total * 4, -1, np.int64)
    flat_neighbor[first], flat_neighbor[second] = second, first
    neighbors = np.where(flat_neighbor >= 0, flat_neighbor // 4, -1).reshape(total, 4)
    neighbor_faces = np.where(flat_neighbor >= 0, flat_neighbor % 4, -1).reshape(total, 4)
    return neighbors.astype(np.int32), neighbor_faces.astype(np.int8)


def _folded(planes: np.ndarray, neighbors: np.ndarray,
            neighbor_faces: np.ndarray) -> np.ndarray:
    """(T,) bool: tetrahedra with a neighbour on the same side of their shared face."""
    t, f = np.nonzero(neighbors >= 0)
    mine = planes[t, f, :3]
    theirs = planes[neighbors[t, f], neighbor_faces[t, f], :3]
    out = np.zeros(len(planes), bool)
    out[t[np.einsum("ni,ni->n", mine, theirs) > 0]] = True
    return out


def _check_folds(planes: np.ndarray, neighbors: np.ndarray,
                 neighbor_faces: np.ndarray) -> None:
    """Refuse neighbours on the same side of their shared face (prisms folded onto each
    other): their outward normals there must be opposite."""
    t, f = np.nonzero(neighbors >= 0)
    mine = planes[t, f, :3]
    theirs = planes[neighbors[t, f], neighbor_faces[t, f], :3]
    folded = np.einsum("ni,ni->n", mine, theirs) > 0
    if folded.any():
        raise UsageError(f"{int(folded.sum()) // 2} shared faces have both tetrahedra on one "
                         "side (the extruded shell folds over itself); use a smaller "
                         "thickness")


def _tangent_frames(base: np.ndarray, uv: np.ndarray, faces: np.ndarray,
                    normals: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(V, 3) unit tangents (along +u) and bitangents (along +v) perpendicular to the normals.

    The usual per-triangle UV gradient, summed per vertex and Gram-Schmidt'ed against the
    normal; the bitangent is n x t with the sign of the UV gradient's (mirrored UVs keep
    their handedness). Where the sum vanishes, any perpendicular of the normal.
    """
    p = base[faces]
    t = uv[faces]
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    d1, d2 = t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]
    r = d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]
    inv = np.where(np.abs(r) > 1e-300, 1.0 / np.where(r == 0, 1.0, r), 0.0)[:, None]
    tri_t = (e1 * d2[:, 1:] - e2 * d1[:, 1:]) * inv
    tri_b = (e2 * d1[:, :1] - e1 * d2[:, :1]) * inv
    count = len(base)
    tan, bit = np.zeros((count, 3)), np.zeros((count, 3))
    for corner in range(3):
        np.add.at(tan, faces[:, corner], tri_t)
        np.add.at(bit, faces[:, corner], tri_b)
    tan -= normals * np.einsum("vi,vi->v", tan, normals)[:, None]
    length = np.linalg.norm(tan, axis=1)
    weak = length <= 1e-12
    tan[weak] = _any_perpendicular(normals[weak])
    tan /= np.linalg.norm(tan, axis=1, keepdims=True)
    cross = np.cross(normals, tan)
    hand = np.where(np.einsum("vi,vi->v", cross, bit) < 0, -1.0, 1.0)
    return tan, cross * hand[:, None]


def _any_perpendicular(normals: np.ndarray) -> np.ndarray:
    """A vector perpendicular to each normal (crossed with its least aligned axis)."""
    axis = np.eye(3)[np.argmin(np.abs(normals), axis=1)]
    return np.cross(normals, axis)
