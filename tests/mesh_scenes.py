"""Meshes that exercise every material path of the mesh drawable: a unit cube whose faces
take a texture through a uv transform, a colour factor, a MASK cut-out and vertex colours
(the glTF writer's tests and the viewer's)."""

from __future__ import annotations

import numpy as np

from reliefkit.scene.mesh import Material, RenderMesh

# the cube's faces: outward normal, then two axes spanning the face (u, v), u x v = normal
FACES = [((1, 0, 0), (0, 0, -1), (0, 1, 0)), ((-1, 0, 0), (0, 0, 1), (0, 1, 0)),
         ((0, 1, 0), (1, 0, 0), (0, 0, -1)), ((0, -1, 0), (1, 0, 0), (0, 0, 1)),
         ((0, 0, 1), (1, 0, 0), (0, 1, 0)), ((0, 0, -1), (-1, 0, 0), (0, 1, 0))]


def asymmetric_texture() -> np.ndarray:
    """8 x 16 texels, no two alike and no symmetry: red grows with the column, green with the
    row (row 0 at v = 0), blue marks one corner."""
    rows, cols = np.mgrid[0:8, 0:16]
    rgba = np.zeros((8, 16, 4), np.uint8)
    rgba[..., 0] = 40 + cols * 13
    rgba[..., 1] = 30 + rows * 25
    rgba[..., 2] = np.where((rows < 3) & (cols < 4), 220, 60)
    rgba[..., 3] = 255
    return rgba


def cutout_texture() -> np.ndarray:
    """16 x 16 texels: colour by column only, and bands of rows fully transparent (alpha 0):
    each transparent texel's nearest opaque texel lies in its own column, so the writer's
    dilation keeps this texture as it is and a re-read mesh draws exactly the original."""
    rows, cols = np.mgrid[0:16, 0:16]
    rgba = np.zeros((16, 16, 4), np.uint8)
    rgba[..., 0] = 200 - cols * 8
    rgba[..., 1] = 60 + cols * 9
    rgba[..., 2] = 120
    rgba[..., 3] = np.where((rows // 4) % 2 == 1, 0, 255)
    return rgba


def sampler_mesh(offset: float = 0.0) -> RenderMesh:
    """A unit cube with each face's own corners: +x an asymmetric texture through a uv
    transform; -x the same image with another colour factor (one image in the file); +y and
    -y a double-sided MASK cut-out (see through into the cube); +z and -z vertex colours on a
    colour factor. ``offset`` moves it far away (along all three axes)."""
    positions, normals, uvs, faces = [], [], [], []
    for normal, u, v in FACES:
        n, u, v = (np.array(a, np.float64) for a in (normal, u, v))
        base = len(positions)
        for du, dv in ((0, 0), (1, 0), (1, 1), (0, 1)):
            positions.append(0.5 * n + (du - 0.5) * u + (dv - 0.5) * v)
            normals.append(n)
            uvs.append((du, dv))
        faces += [(base, base + 1, base + 2), (base, base + 2, base + 3)]
    positions = np.array(positions) + offset
    rng = np.random.default_rng(31)
    colors = np.ones((len(positions), 4))
    colors[16:24, :3] = rng.uniform(0.25, 0.9, (8, 3))  # the z faces' corners
    rotate = np.array([[0.0, -1.0, 1.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])  # 90 degrees
    picture = asymmetric_texture()
    materials = (
        Material("turned", (1.0, 1.0, 1.0, 1.0), picture, uv_transform=rotate),
        Material("tinted", (0.9, 0.7, 0.5, 1.0), picture),
        Material("cutout", (1.0, 1.0, 1.0, 1.0), cutout_texture(), alpha_mode="MASK",
                 alpha_cutoff=0.4, double_sided=True),
        Material("painted", (0.8, 0.9, 1.0, 1.0)),
        Material("unused", (0.1, 0.2, 0.3, 1.0)),
    )
    material = np.repeat([0, 1, 2, 2, 3, 3], 2)
    return RenderMesh(positions, faces, normals, colors, uvs, name="sampler",
                      materials=materials, material=material)
