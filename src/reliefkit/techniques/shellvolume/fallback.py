"""What a glTF viewer that knows nothing of shell volumes shows of one
(`TexturedShell.fallback_mesh`): the base mesh with the volume's colour projected on it.

**The projection.** Each column of the 3D texture, seen straight down from the shell's top
(w = 1) to its base (w = 0), is composited front to back as the CPU integrator
(reference.py) composites a ray: the optical density and the density-weighted colour of
`textures.marched_volume`, linear between voxel centres along w (clamped), each step of
length dt dimming what lies below by exp(-density dt). The column is as long as the shell
is thick: its mean thickness (the bake thins it only where it would fold). The result is
one tile of the texture as an image, straight colour and the column's total opacity; the
mesh's uvs are the base's times the texture's tiling, so a viewer's default REPEAT wrap
tiles it as the shell does. Glow (emission) is left out, as the CPU integrator leaves it:
a RenderMesh has no emissive colour.

**The surface.** Where the base's own materials tint the volume (`TexturedShell.surface`),
the tint is the vertex colour (glTF multiplies it by the texture), read at each vertex's uv
in its material's layer.

**Alpha.** A column whose total opacity is below `ALPHA_CUTOFF` is cut away (glTF's MASK):
the gaps of a chain, a clear medium. The cutoff is low because a shell is seen obliquely and
through two layers, so it covers more than its columns' opacity straight down says.
Measured on demo:torus from three views against the shell's own render (pixels of
opacity >= 0.5): the chain's gaps match best at 0.1 (IoU 0.54-0.59; 0.42-0.50 drawn opaque,
0.21-0.25 at a cutoff of 0.5); fur, clouds, rocks, ellipsoids and absorption are covered
everywhere at 0.1 (0.79-0.87, as opaque; ellipsoids at 0.5 lose half their surface). The
material is double-sided, as the shell is seen from either side of its base.
"""

from __future__ import annotations

import numpy as np

from ...bake.uv_atlas import linear_tint
from ...colorspace import to_rgba8
from ...scene.mesh import Material, RenderMesh
from .textures import density_floor, marched_volume

#: Steps per voxel along the column (the texture is linear between voxel centres).
STEPS_PER_VOXEL = 4
#: Columns less opaque than this are cut away (glTF MASK's alphaCutoff).
ALPHA_CUTOFF = 0.1


def fallback_mesh(rep) -> RenderMesh:
    """The base mesh of shell ``rep``, its own triangles (the budget does not apply), with
    the projected volume as a tiled texture (see the module docstring)."""
    base = rep.base
    thickness = float(np.mean(rep.shell.thickness))
    image = column_image(rep.texture.rgba, rep.texture.length, thickness)
    tile = np.asarray(rep.texture.tile, np.float64)
    count = len(base.positions)
    colors = np.ones((count, 4), np.float32)
    if rep.surface is not None:
        layer = np.zeros(count, np.int64)
        layer[np.asarray(base.indices).ravel()] = np.repeat(np.asarray(base.material), 3)
        colors[:, :3] = linear_tint(rep.surface, base.uvs, layer)
    material = Material(name="shell volume", texture=to_rgba8(image), alpha_mode="MASK",
                        alpha_cutoff=ALPHA_CUTOFF, double_sided=True)
    return RenderMesh(base.world_positions, base.indices, base.normals, colors,
                      np.asarray(base.uvs, np.float64) * tile, name="shell volume fallback",
                      materials=[material])


def column_image(rgba: np.ndarray, length: float, thickness: float) -> np.ndarray:
    """(H, W, 4) float32: the (D, H, W, 4) texture's columns composited from w = 1 down to
    w = 0 over ``thickness`` (alpha the opacity over ``length``, as `VolumeTexture`):
    straight linear colour (0 where nothing is opaque) and the column's total opacity."""
    marched = marched_volume(rgba, length, thickness)  # float32; one layer at a time in float64
    depth = marched.shape[0]
    steps = STEPS_PER_VOXEL * depth
    dt = thickness / steps
    floor = density_floor(thickness)
    colour = np.zeros(marched.shape[1:3] + (3,))
    opacity = np.zeros(marched.shape[1:3])
    for s in reversed(range(steps)):  # the top first
        x = min(max((s + 0.5) / steps * depth - 0.5, 0.0), depth - 1.0)
        k = min(int(x), depth - 2) if depth > 1 else 0
        f = x - k
        sample = marched[k].astype(np.float64)
        if depth > 1:
            sample = (1 - f) * sample + f * marched[k + 1]
        density = np.maximum(sample[..., 3], 0.0)
        a = -np.expm1(-density * dt)
        weight = (1.0 - opacity) * a
        colour += weight[..., None] * sample[..., :3] / (density + floor)[..., None]
        opacity += weight
    straight = np.where(opacity[..., None] > 0,
                        colour / np.maximum(opacity, 1e-300)[..., None], 0.0)
    return np.concatenate([np.clip(straight, 0, 1), opacity[..., None]],
                          axis=-1).astype(np.float32)
