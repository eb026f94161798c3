"""`TexturedShell`: a base mesh, its shell of tetrahedra and the 3D texture the shell holds
(the representation of the ``shell-volume`` kind).

Nothing is precomputed beyond the shell itself (the paper's point, §6): the tetrahedra are
built from the base mesh when the representation is made (and again, from the deformed base,
for each frame of an animation); the visibility order is computed per frame.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...bake.uv_atlas import MAX_MATERIALS, MaterialAtlas
from ...errors import UsageError
from ...scene.mesh import RenderMesh
from ...scene.views import source_box
from . import fallback
from .shell import ShellVolume, build_shell
from .textures import VolumeTexture

#: The renderer keeps each tetrahedron in TET_TEXELS texels of a 2D float texture,
#: TETS_PER_ROW per row (render.tet_texels), and OpenGL 4.3 guarantees 2D textures of
#: GL43_TEXTURE_ROWS rows: a shell of more tetrahedra (three per triangle) cannot be drawn
#: on every GPU, so it is refused before it is built (a 1M-triangle bake took 44 s and 4.1 GB
#: to be refused by the render).
TET_TEXELS, TETS_PER_ROW, GL43_TEXTURE_ROWS = 16, 128, 16384
MAX_TETRAHEDRA = TETS_PER_ROW * GL43_TEXTURE_ROWS

#: Deformation of an animated base (`TexturedShell.shell_at`): vertices move along their
#: normals by this fraction of the shell's thickness, as a wave over the surface.
WAVE_AMPLITUDE = 0.6


@dataclass(eq=False)
class TexturedShell:
    """A shell of thickness ``thickness`` (per base vertex, world units) over ``base`` (a
    RenderMesh with uvs), filled with ``texture`` tiled ``texture.tile`` times over the uvs.

    ``surface``: the base's own materials in its uv space (`reliefkit.bake.uv_atlas`), one
    layer per material of ``base.material``; the volume's colours are multiplied by it (the
    surface tints what grows on it). None: the texture's colours as they are.

    ``shell`` is built at construction (`build_shell`), so a bad base or thickness is refused
    here, with the reason. ``source_bounds`` is the box of the mesh it was baked from (None
    if unknown): views frame the shell by it, as they frame its mesh.
    """

    base: object
    thickness: np.ndarray
    texture: VolumeTexture
    params: dict = field(default_factory=dict)
    source_bounds: np.ndarray | None = None
    surface: MaterialAtlas | None = None
    shell: ShellVolume = field(init=False)

    def __post_init__(self) -> None:
        if not isinstance(self.texture, VolumeTexture):
            raise UsageError(f"a textured shell needs a VolumeTexture, got "
                             f"{type(self.texture).__name__}")
        check_tetrahedron_count(len(self.base.indices))
        self.thickness = np.broadcast_to(np.asarray(self.thickness, np.float64),
                                         (len(self.base.positions),)).copy()
        self.source_bounds = source_box(self.source_bounds)
        if self.surface is not None and len(self.surface.rgba8) <= int(
                np.max(self.base.material, initial=0)):
            raise UsageError(f"a shell's surface has {len(self.surface.rgba8)} material "
                             f"layers, its base uses {int(np.max(self.base.material)) + 1}")
        self.shell = build_shell(self.base, self.thickness)

    @property
    def bounds(self) -> np.ndarray:
        """(2, 3) world box of the shell (base and tops)."""
        p = self.shell.positions
        return np.array([p.min(axis=0), p.max(axis=0)])

    @property
    def tetrahedron_count(self) -> int:
        return len(self.shell.tets)

    @property
    def opaque(self) -> bool:
        """Whether the texture is opaque (every voxel empty or a solid): drawn depth-tested,
        without sorting (§4, the tree of Color plate E)."""
        return self.texture.opaque

    def surface_layers(self) -> np.ndarray | None:
        """(T,) int64 the `surface` layer of each tetrahedron (its base triangle's material:
        three tetrahedra per triangle, in the triangles' order); None without a surface."""
        if self.surface is None:
            return None
        return np.repeat(np.asarray(self.base.material, np.int64), 3)

    def shell_at(self, time: float | None) -> ShellVolume:
        """The shell at animation ``time`` (None: at rest): the base deformed by a wave along
        its normals, the shell rebuilt from it (nothing else precomputed)."""
        if time is None:
            return self.shell
        base = self.base
        p = base.world_positions
        extent = float(np.linalg.norm(p.max(axis=0) - p.min(axis=0))) or 1.0
        phase = 2 * np.pi * (time + 1.5 * (p[:, 0] + 0.7 * p[:, 1] + 0.4 * p[:, 2]) / extent)
        offset = (WAVE_AMPLITUDE * self.thickness * np.sin(phase))[:, None] * \
            np.asarray(base.normals, np.float64)

        moved = RenderMesh(p + offset, base.indices, base.normals, base.colors, base.uvs,
                           name=base.name)
        return build_shell(moved, self.thickness)

    def fallback_mesh(self, triangles: int = 20_000) -> RenderMesh:
        """What a glTF viewer that knows nothing of reliefkit shows: the base mesh with the
        volume's colour projected on it (composited down each column of the texture) as a
        tiled texture, cut away where a column is mostly clear (`fallback`). Its triangles
        are the base's own: ``triangles`` does not apply (a shell's base is already what
        its tetrahedra are built on)."""
        return fallback.fallback_mesh(self)

    def bake_report(self) -> list[str]:
        """What `reliefkit bake` says of a fresh shell."""
        s = self.shell.summary()
        d, h, w = self.texture.shape
        kind = "opaque" if self.opaque else "semi-transparent"
        lines = [f"shell volume: {s['prisms']} prisms, {s['tetrahedra']} tetrahedra, thickness "
                 f"{s['thickness'][0]:.4g}..{s['thickness'][1]:.4g}; texture "
                 f"'{self.texture.name}' {w}x{h}x{d} ({kind}), tiled "
                 f"{self.texture.tile[0]}x{self.texture.tile[1]}"]
        dropped, thinned, left_out = (self.params.get(k, 0) for k in (
            "dropped_triangles", "thinned_vertices", "materials_left_out"))
        if dropped:
            lines.append(f"warning: {dropped} triangles were left out of the shell (no area "
                         "in space or in uv, or a vertex normal along or behind the triangle)")
        if thinned:
            lines.append(f"warning: the shell is thinner (down to {s['thickness'][0]:.3g}) at "
                         f"{thinned} of {s['base_vertices']} vertices, where "
                         f"{self.params.get('thickness', 0):.3g} would fold it over itself")
        if self.surface is not None:
            lines.append(f"the surface's {len(self.surface.rgba8)} material(s) tint the volume")
        if left_out:
            lines.append(f"warning: the surface's {left_out} materials are left out (at most "
                         f"{MAX_MATERIALS} tint a shell); the volume keeps its own colours")
        return lines


def check_tetrahedron_count(triangles: int) -> None:
    """Refuse a base of ``triangles`` whose shell (three tetrahedra each) the renderer could
    not hold on every GPU (`MAX_TETRAHEDRA`), before anything is built."""
    if 3 * triangles > MAX_TETRAHEDRA:
        raise UsageError(f"a shell over {triangles:,} triangles has {3 * triangles:,} "
                         f"tetrahedra, more than the {MAX_TETRAHEDRA:,} a GPU is guaranteed to "
                         f"hold (at most {MAX_TETRAHEDRA // 3:,} triangles); simplify the mesh "
                         "(for example with Blender's Decimate modifier)")
