"""Quadric decimation of a mesh to a byte budget (fast_simplification), for the benches
that compare a representation with the mesh at equal bytes or at equal error."""

from __future__ import annotations

import numpy as np

from ..io.rk import array_bytes
from .mesh import RenderMesh, vertex_normals


def mesh_bytes(mesh) -> int:
    return sum(array_bytes(mesh).values())


def decimated(mesh, target_bytes: int):
    """``mesh`` simplified by fast_simplification to about ``target_bytes`` (None when the
    package is missing; the mesh itself when it is already that small). Colours, UVs and
    materials come from the nearest original vertex / face."""
    full = mesh_bytes(mesh)
    if target_bytes >= full:
        return mesh
    try:
        import fast_simplification
    except ImportError:
        return None
    from scipy.spatial import cKDTree

    points = mesh.world_positions
    reduction = min(1.0 - target_bytes / full, 0.999)
    new_points, faces = fast_simplification.simplify(points, mesh.indices.astype(np.int64),
                                                     target_reduction=reduction)
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
