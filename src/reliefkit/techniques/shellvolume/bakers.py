"""The shell-volume baker and its typed parameters (``bake --as shell-volume``)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...core.params import param
from ...errors import FormatError, UsageError
from .representation import TexturedShell
from .shell import fitted_thickness, unusable_triangles
from .textures import TEXTURES, load_texture_npy, texture_from_mesh

DEFAULT_THICKNESS = 0.05  # of the base's bounding-box diagonal, when --thickness is not given


@dataclass(frozen=True)
class ShellVolumeParams:
    texture: str = param("fur", "the 3D texture: " + ", ".join(TEXTURES) + ", a FILE.npy "
                         "(D, H, W, 4) float RGBA, or a mesh (FILE or demo:NAME) voxelized "
                         "into one")
    thickness: float | None = param(None, "shell thickness in the mesh's own units (none: "
                                    f"{DEFAULT_THICKNESS:g} of its bounding-box diagonal)",
                                    kind="float", lo=1e-12)
    tile: tuple = param((1.0, 1.0), "how many times the texture repeats over the uvs, U,V",
                        kind="floats", count=2, lo=1, hi=4096)
    texture_size: tuple = param((32.0, 32.0, 16.0), "W,H,D voxels of a generated or "
                                "voxelized texture", kind="floats", count=3, lo=2, hi=256)


def make_texture(spec: str, size, thickness: float, progress=None):
    """The texture ``spec`` names (see `ShellVolumeParams.texture`) at ``size`` (W, H, D);
    a generated one's alpha converted for a shell of ``thickness``."""
    size = tuple(int(round(s)) for s in size)
    if spec in TEXTURES:
        return TEXTURES[spec](size=size).over_length(thickness)
    if spec.lower().endswith(".npy"):
        return load_texture_npy(spec)
    from pathlib import Path

    from ...io.inputs import DEMO_PREFIX, load_input
    from ...scene.mesh import RenderMesh

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


def bake_shell(source, p: ShellVolumeParams, progress=None) -> TexturedShell:
    for t in p.tile:
        if t != int(t):
            raise UsageError(f"--tile takes whole numbers, got {p.tile[0]:g},{p.tile[1]:g}")
    lo, hi = source.bounds
    thickness = p.thickness if p.thickness is not None else \
        DEFAULT_THICKNESS * float(np.linalg.norm(np.asarray(hi) - np.asarray(lo)))
    texture = make_texture(p.texture, p.texture_size, thickness, progress).tiled(
        (int(p.tile[0]), int(p.tile[1])))
    base, dropped = usable_part(source)
    fitted = fitted_thickness(base, thickness)
    thinned = int((fitted < thickness).sum())
    return TexturedShell(base, fitted, texture,
                         {"source": source.name, "thickness": thickness,
                          "dropped_triangles": dropped, "thinned_vertices": thinned})


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
    from ...scene.mesh import RenderMesh

    kept = np.asarray(mesh.indices)[~bad]
    return RenderMesh(mesh.world_positions, kept, mesh.normals, mesh.colors, mesh.uvs,
                      name=mesh.name), int(bad.sum())
