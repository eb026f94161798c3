"""Scenes shared by the shell-volume tests: a flat grid extruded into slabs, an icosphere,
textures from arrays, and cameras looking at the grid from an angle."""

from __future__ import annotations

import numpy as np
import trimesh

from reliefkit.scene.camera import Camera
from reliefkit.scene.mesh import RenderMesh, vertex_normals
from reliefkit.techniques.shellvolume.textures import VolumeTexture, density_normals

HALF = 1.0  # the grid covers [-HALF, HALF]^2 at z = 0, normal +z


def grid_mesh(n=8, uv=(0.0, 1.0)):
    xs = np.linspace(-HALF, HALF, n + 1)
    x, y = np.meshgrid(xs, xs)
    p = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    faces = []
    for i in range(n):
        for j in range(n):
            a, b = i * (n + 1) + j, i * (n + 1) + j + 1
            c, d = b + n + 1, a + n + 1
            faces += [(a, b, c), (a, c, d)]  # counter-clockwise seen from +z
    uvs = uv[0] + (uv[1] - uv[0]) * (p[:, :2] + HALF) / (2 * HALF)
    normals = np.tile([0.0, 0.0, 1.0], (len(p), 1))
    return RenderMesh(p, np.asarray(faces), normals, np.ones((len(p), 4)), uvs)


def sphere_mesh(subdivisions=2):
    ico = trimesh.creation.icosphere(subdivisions=subdivisions, radius=1.0)
    p = np.asarray(ico.vertices, dtype=np.float64)
    unit = p / np.linalg.norm(p, axis=1, keepdims=True)
    u = np.arctan2(unit[:, 1], unit[:, 0]) / (2 * np.pi) + 0.5
    v = np.arccos(np.clip(unit[:, 2], -1, 1)) / np.pi
    uvs = np.column_stack([u + 0.05 * unit[:, 2], v + 0.05 * unit[:, 0]])
    return RenderMesh(p, np.asarray(ico.faces), unit, np.ones((len(p), 4)), uvs)


def texture_from(rgb, alpha, tile=(1, 1)) -> VolumeTexture:
    """(D, H, W) alpha and (D, H, W, 3) (or broadcastable) rgb as a VolumeTexture."""
    alpha = np.asarray(alpha, dtype=np.float64)
    rgb = np.broadcast_to(np.asarray(rgb, dtype=np.float64), alpha.shape + (3,))
    rgba = np.concatenate([rgb, alpha[..., None]], axis=-1).astype(np.float32)
    return VolumeTexture(rgba, density_normals(alpha), "test", tile)


def uniform_texture(a0, rgb=(0.2, 0.5, 0.7)) -> VolumeTexture:
    return texture_from(rgb, np.full((4, 4, 4), a0))


def slab_camera(theta_deg=0.0, size=(32, 32), ortho=True, below=False, dist=3.0):
    """Looking at the grid's centre from angle theta off +z (off -z when below)."""
    th = np.radians(theta_deg)
    offset = dist * np.array([np.sin(th), 0.0, -np.cos(th) if below else np.cos(th)])
    return Camera(eye=tuple(offset), target=(0.0, 0.0, 0.0), up=(0.0, 1.0, 0.0),
                  fov_deg=30.0, size=size, near=0.5, far=10.0,
                  ortho_height=0.4 if ortho else None)


def inside_grid(camera, thickness, margin=0.05):
    """(H, W) pixels whose ray meets both slab planes (z = 0, z = thickness) well inside the
    grid, and the rays (origins, unit directions)."""
    o, d = camera.pixel_rays()
    ok = np.abs(d[..., 2]) > 1e-6
    dz = np.where(ok, d[..., 2], 1.0)
    inside = ok.copy()
    for z in (0.0, thickness):
        hit = o + ((z - o[..., 2]) / dz)[..., None] * d
        inside &= (np.abs(hit[..., :2]) < HALF - margin).all(axis=-1)
    return inside, o, d


def torus_mesh():
    """A torus (non-convex: side-on rays leave the shell and re-enter it)."""
    tor = trimesh.creation.torus(1.0, 0.35, major_sections=20, minor_sections=10)
    p = np.asarray(tor.vertices, dtype=np.float64)
    faces = np.asarray(tor.faces)
    theta = np.arctan2(p[:, 1], p[:, 0])
    phi = np.arctan2(p[:, 2], np.hypot(p[:, 0], p[:, 1]) - 1.0)
    uvs = np.column_stack([theta / (2 * np.pi) + 0.05 * np.sin(phi),
                           phi / (2 * np.pi) + 0.05 * np.cos(theta)])
    return RenderMesh(p, faces, vertex_normals(p, faces), np.ones((len(p), 4)), uvs)
