"""The shell-volume baker and its typed parameters (``bake --as shell-volume``)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...bake.detail import LAYER_PER_EDGE, TILE_PER_LAYER, layer_thickness, uv_tiling
from ...bake.uv_atlas import kept_atlas
from ...core.params import param
from ...core.technique import Sizing
from ...errors import FormatError, UsageError
from ...io.inputs import DEMO_PREFIX, load_input
from ...scene.mesh import RenderMesh
from .representation import TexturedShell, check_tetrahedron_count
from .shell import fitted_thickness, unusable_triangles
from .textures import TEXTURES, load_texture_npy, texture_from_mesh

# A generated or voxelized texture costs about MADE_SECONDS_PER_MVOXEL per million voxels and
# MADE_BYTES_PER_VOXEL at its peak (fur, the slowest, at 128^3: 42 s and 0.7 GB on 2026-12-06
# on this 2-core machine); above MADE_MAX_VOXELS a bake would run for minutes, so it is
# refused with the estimate before anything is allocated.
MADE_SECONDS_PER_MVOXEL = 20.0
MADE_BYTES_PER_VOXEL = 350
MADE_MAX_VOXELS = 128**3


@dataclass(frozen=True)
class ShellVolumeParams:
    texture: str = param("fur", "the 3D texture: " + ", ".join(TEXTURES) + ", a FILE.npy "
                         "(D, H, W, 4) float RGBA, or a mesh (FILE or demo:NAME) voxelized "
                         "into one")
    thickness: float | None = param(None, "shell thickness in the mesh's own units (none: "
                                    f"{LAYER_PER_EDGE:g} of its median edge length)",
                                    kind="float", lo=1e-12)
    tile: tuple | None = param(None, "how many times the texture repeats over the uvs, U,V "
                               f"(none: as often as makes a tile about {TILE_PER_LAYER:g} "
                               "thicknesses long on the surface)",
                               kind="floats", count=2, lo=1, hi=4096)
    texture_size: tuple = param((32.0, 32.0, 16.0), "W,H,D voxels of a generated or "
                                "voxelized texture (at most 128^3 in all)", kind="floats",
                                count=3, lo=2, hi=256)


def make_texture(spec: str, size, thickness: float, progress=None):
    """The texture ``spec`` names (see `ShellVolumeParams.texture`) at ``size`` (W, H, D);
    a generated one's alpha converted for a shell of ``thickness``."""
    size = tuple(int(round(s)) for s in size)
    if not spec.lower().endswith(".npy"):
        check_made_size(size)
    if spec in TEXTURES:
        return TEXTURES[spec](size=size).over_length(thickness)
    if spec.lower().endswith(".npy"):
        return load_texture_npy(spec)
    from pathlib import Path

    if not spec.startswith(DEMO_PREFIX) and not Path(spec).is_file():
        # a name with a suffix is a file's, so a missing input (exit 1); else a bad value
        error = FormatError if Path(spec).suffix else UsageError
        raise error(f"--texture {spec}: not one of {', '.join(TEXTURES)}, and no such "
                         "file (give a generated texture's name, a .npy volume or a mesh)")
    mesh = load_input(spec)
    if not isinstance(mesh, RenderMesh):
        raise UsageError(f"--texture {spec}: expected one of {', '.join(TEXTURES)}, a .npy "
                         "volume or a mesh to voxelize")
    return texture_from_mesh(mesh, size, progress=progress)


def check_made_size(size) -> None:
    """Refuse a generated or voxelized texture of ``size`` (W, H, D) whose making would take
    minutes (estimate in the message)."""
    voxels = size[0] * size[1] * size[2]
    if voxels <= MADE_MAX_VOXELS:
        return
    minutes = MADE_SECONDS_PER_MVOXEL * voxels / 1e6 / 60
    gib = MADE_BYTES_PER_VOXEL * voxels / 2**30
    raise UsageError(f"--texture-size {size[0]},{size[1]},{size[2]} is {voxels:,} voxels: making "
                     f"that texture would take about {minutes:.0f} minutes and {gib:.1f} GiB "
                     f"here (the limit is {MADE_MAX_VOXELS:,} voxels, e.g. 128,128,128); use a "
                     "smaller size, or a .npy volume made elsewhere")


def bake_shell(source, p: ShellVolumeParams, progress=None) -> TexturedShell:
    if p.tile is not None and any(t != int(t) for t in p.tile):
        raise UsageError(f"--tile takes whole numbers, got {p.tile[0]:g},{p.tile[1]:g}")
    check_tetrahedron_count(len(source.indices))
    thickness = p.thickness if p.thickness is not None else layer_thickness(source)
    tile = uv_tiling(source, TILE_PER_LAYER * thickness) if p.tile is None else \
        (int(p.tile[0]), int(p.tile[1]))
    texture = make_texture(p.texture, p.texture_size, thickness, progress).tiled(tile)
    base, dropped = usable_part(source)
    fitted = fitted_thickness(base, thickness)
    thinned = int((fitted < thickness).sum())
    surface, left_out = kept_atlas(base)  # the surface's own look, under the volume's colours
    return TexturedShell(base, fitted, texture,
                         {"source": source.name, "thickness": thickness,
                          "dropped_triangles": dropped, "thinned_vertices": thinned,
                          "materials_left_out": left_out},
                         source_bounds=source.bounds, surface=surface)


def usable_part(mesh):
    """``mesh`` without the triangles a shell cannot use (no area, or no uv area), and how
    many were left out; a mesh without uvs is refused."""
    if mesh.uvs is None:
        raise UsageError(f"{mesh.name}: a shell volume needs texture coordinates (uvs); "
                         "unwrap the mesh (for example in Blender) or use a demo surface")
    bad = unusable_triangles(mesh)
    if bad.all():
        raise UsageError(f"{mesh.name}: none of its {len(bad)} triangles has an area in "
                         "space and in uv; there is nothing to extrude")
    if not bad.any():
        return mesh, 0

    kept = np.asarray(mesh.indices)[~bad]
    return RenderMesh(mesh.world_positions, kept, mesh.normals, mesh.colors, mesh.uvs,
                      name=mesh.name, materials=mesh.materials,
                      material=np.asarray(mesh.material)[~bad]), int(bad.sum())


#: The shootout sizes a shell volume (meshes with uvs only) by its 3D texture's voxels.
SHELL_SIZING = Sizing("texture_size n,n,n/2: voxels of the 3D texture", 4, 128,
                      lambda n, mesh: {"texture_size": (n, n, max(n // 2, 2))},
                      needs_uvs=True)
