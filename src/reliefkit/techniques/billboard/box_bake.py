"""Baking displacement-mapped billboard clouds (Mantler, Jeschke, Wimmer §3.3, §3.4.1).

The planes are those of the flat billboard cloud of the same parameters (`build_billboard_cloud`,
kept baked as `BillboardBoxes.cloud`). Each plane's box (`plane_box`: its rectangle, +-epsilon
along its normal) gets W x H texels (the rectangle's resolution) and D voxels across, D about
2 epsilon / texel size so voxels are about cubic (§3.3.1). Only the plane's own faces are
voxelized into its box, by the core's GPU voxelizer in surface mode. From that grid:

* volumetric (§3.3.1): the grid itself, one colour, normal and occupancy per voxel;
* shell (§3.3.2): one displacement per texel column, its surface's colour and normal, and one
  thickness for the whole cloud;
* thick shell (§3.3.3): the lowest and highest occupied w per column, one colour and normal;

and, for all three, a distance texture over the box's voxels for sphere tracing (§3.4.1).

Choices (the paper leaves them open):

* Occupancy: a voxel is occupied when ``VoxelGrid.surface > 0``, i.e. some sample line of
  the voxelizer meets the surface inside the voxel. A higher threshold (say half covered)
  would drop the voxels a sloped sheet only clips, and rays would leak through the sheet
  between diagonal neighbours; the surface passing through a voxel at all is what §3.3.1's
  "rasterizing the triangles into these voxels" marks.
* ``surfaces="outside"``: the faces of a box are split by facing: those whose geometric
  normal faces +w (the box's outside, where its plane's faces face; the plane is chosen
  nearly tangent to the model) and those facing -w. Each half is voxelized separately; where
  both occupy a voxel the +w one wins, so a thin double-sided sheet shows its outer side's
  colour and normal instead of a mix (whose normal cancels). ``"average"`` averages the
  surfaces that share a voxel. Solid-mode inside information is not used: a box holds a
  patch of the mesh, never closed.
* The shells, with either choice, keep each column's outermost surface: the colour and
  normal of its highest occupied voxel facing +w (else of its highest), the one seen first
  from the w = 1 side (the box's outside), and, for the shell, the middle of the run of
  occupied voxels through it as its displacement. One colour and displacement per texel
  cannot show two surfaces, and those below the outermost are hidden by it in the mesh (a
  roof's rafters, the far side of a leg); averaging the whole column showed them through
  and put the shell between them. A -w-facing voxel above it is the underside of something
  closed beyond the box (from outside its top is seen, in another box): taking it painted a
  van's window glass down its doors, where a box on the belt line runs along the wall.
* Automatic shell thickness: the standard deviation of the acquired displacements over all
  covered texels of all boxes (the paper: "over all acquired texel positions"; one global
  value, as `BillboardBoxes` has one thickness), clamped to [1/D, 1] so a shell is at least
  one voxel thick.
* The distance textures: see `distance` (the same code checks a file's on load).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...bake.voxelize import MAX_VOXELS, voxelize
from ...colorspace import to_rgba8
from ...errors import UsageError
from ...scene.mesh import RenderMesh
from .bake import bake_plan, plane_box
from .boxes import VARIANTS, BillboardBox, BillboardBoxes, shell_thickness
from .cloud import BillboardPlane, build_billboard_cloud
from .distance import DISP_SCALE, distance_texture, occupancy

SURFACES = ("average", "outside")
#: Most voxels all boxes together may have (256 M: 2 GiB of volumetric colour, normal and
#: distance; a shell keeps only its 256 MiB of distance texture but bakes the same grids).
MAX_TOTAL_VOXELS = 1 << 28
#: A voxel whose surface coverage exceeds this is occupied: any sample line meets the surface.
OCCUPIED_ABOVE = 0.0
_EDGE = 1e-5  # box units: vertices are kept this far inside the box (half-open voxel bounds)
_NOTHING_INSIDE = "no part of the mesh was found inside"


@dataclass(eq=False)
class _Voxels:
    """One box's voxelized faces: occupancy (D, H, W) bool, linear straight-alpha colour
    (D, H, W, 4) and unit world normal (D, H, W, 3), zero where unoccupied."""

    occupied: np.ndarray
    color: np.ndarray
    normal: np.ndarray

    @property
    def depth(self) -> int:
        return self.occupied.shape[0]


@dataclass(eq=False)
class _Maps:
    """A box's maps before the distance texture (the shell's depends on the cloud-wide
    thickness)."""

    color: np.ndarray
    normal: np.ndarray
    displacement: np.ndarray | None


def bake_boxes(mesh: RenderMesh, variant: str = "volumetric", *, epsilon: float = 0.05,
               max_planes: int | None = None, texel_size: float | None = None,
               thickness: float | None = None, surfaces: str = "average", progress=None,
               ctx=None) -> BillboardBoxes:
    """The displacement-mapped billboard cloud of ``mesh`` in ``variant`` (one of `VARIANTS`).

    ``epsilon``, ``max_planes`` and ``texel_size`` choose the planes as for the flat cloud
    (`bake_billboard_cloud`). ``thickness`` (shell only) is the shell's interval width as a
    fraction of the box depth, in (0, 1], or None for the automatic one (see the module).
    ``surfaces`` is how samples of several surfaces in one voxel combine: ``"average"``
    (equal weights) or ``"outside"`` (the one seen from the box's outside); the shells keep
    each column's outermost surface either way.
    ``progress(done, total)`` counts faces assigned to planes, then the flat cloud's planes
    baked, then the boxes. Raises UsageError for bad options or work that would not fit.
    """
    _check_options(variant, thickness, surfaces)
    faces = mesh.triangle_count
    total = [faces]

    def report(done):
        if progress:
            progress(done, total[0])

    plan = build_billboard_cloud(mesh, epsilon, max_planes, texel_size,
                                 progress=lambda done, _: report(done))
    depth = max(1, round(2 * plan.epsilon / plan.texel_size))
    _check_size(plan.planes, depth, plan.texel_size)
    count = len(plan.planes)
    total[0] = faces + 2 * count
    cloud = bake_plan(mesh, plan, progress=lambda k: report(faces + k), ctx=ctx)

    transforms, maps = [], []
    for k, plane in enumerate(plan.planes):
        box_to_world = plane_box(plane, plan.epsilon)
        voxels = _box_voxels(mesh, plane, box_to_world, depth, surfaces, ctx)
        transforms.append(box_to_world)
        maps.append(_variant_maps(voxels, variant, plane.normal))
        report(faces + count + k + 1)

    shell = None
    if variant == "shell":
        shell = _auto_thickness(maps, depth) if thickness is None else float(thickness)
    boxes = [BillboardBox(box_to_world=t, color=m.color, normal=m.normal,
                          distance=distance_texture(occupancy(variant, m.color, m.displacement,
                                                              depth, shell), t),
                          displacement=m.displacement)
             for t, m in zip(transforms, maps, strict=True)]
    params = {"variant": variant, "epsilon": plan.epsilon_fraction,
              "texel_size": plan.texel_size, "voxels_across": depth,
              "thickness": shell, "thickness_auto": variant == "shell" and thickness is None,
              "surfaces": surfaces, "source": mesh.name, "generation": plan.summary()}
    if max_planes is not None:
        params["max_planes"] = max_planes
    return BillboardBoxes(variant=variant, boxes=boxes, cloud=cloud, thickness=shell,
                          source_bounds=mesh.bounds, params=params)


# -- options and limits -----------------------------------------------------------------

def _check_options(variant, thickness, surfaces) -> None:
    if variant not in VARIANTS:
        raise UsageError(f"variant must be one of {', '.join(VARIANTS)}, got {variant!r}")
    if surfaces not in SURFACES:
        raise UsageError(f"surfaces must be one of {', '.join(SURFACES)}, got {surfaces!r}")
    if thickness is None:
        return
    if variant != "shell":
        raise UsageError(f"thickness applies only to the shell variant, not {variant!r}")
    shell_thickness(thickness)


def _check_size(planes: tuple[BillboardPlane, ...], depth: int, texel: float) -> None:
    """Refuse, before anything is allocated, boxes the voxelizer or memory cannot hold."""
    sizes = [w * h * depth for w, h in (p.resolution for p in planes)]
    hint = f"at a texel size of {texel:.3g}; bake with a larger --texel-size"
    if max(sizes) > MAX_VOXELS:
        raise UsageError(f"a billboard box needs {max(sizes):,} voxels, more than the "
                         f"voxelizer's {MAX_VOXELS:,}, {hint}")
    if sum(sizes) > MAX_TOTAL_VOXELS:
        raise UsageError(f"the {len(planes)} billboard boxes need {sum(sizes):,} voxels, more "
                         f"than {MAX_TOTAL_VOXELS:,}, {hint}")


# -- voxelizing a box -------------------------------------------------------------------

def _box_voxels(mesh: RenderMesh, plane: BillboardPlane, box_to_world: np.ndarray,
                depth: int, surfaces: str, ctx) -> _Voxels:
    """The plane's faces voxelized into its box; with ``"outside"`` the +w-facing faces win
    every voxel they share with -w-facing ones."""
    w, h = plane.resolution
    resolution = (w, h, depth)
    faces = np.asarray(plane.faces)
    if surfaces == "average":
        return _voxelized(mesh, faces, box_to_world, resolution, ctx)
    corners = mesh.world_positions[mesh.indices[faces]]
    facing = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    front = facing @ plane.normal >= 0
    outer = _voxelized(mesh, faces[front], box_to_world, resolution, ctx)
    inner = _voxelized(mesh, faces[~front], box_to_world, resolution, ctx)
    take = outer.occupied[..., None]
    return _Voxels(outer.occupied | inner.occupied,
                   np.where(take, outer.color, inner.color),
                   np.where(take, outer.normal, inner.normal))


def _voxelized(mesh: RenderMesh, faces: np.ndarray, box_to_world: np.ndarray,
               resolution: tuple[int, int, int], ctx) -> _Voxels:
    """Surface voxels of ``faces``; an empty grid when they miss every sample line (a sliver
    or a fully transparent patch: its box stays empty rather than failing the bake)."""
    w, h, d = resolution
    empty = _Voxels(np.zeros((d, h, w), bool), np.zeros((d, h, w, 4), np.float32),
                    np.zeros((d, h, w, 3), np.float32))
    if len(faces) == 0:
        return empty
    try:
        grid = voxelize(_inside_box(mesh, faces, box_to_world), box_to_world, resolution,
                        mode="surface", ctx=ctx)
    except UsageError as error:
        if _NOTHING_INSIDE in str(error):
            return empty
        raise
    occupied = grid.surface > OCCUPIED_ABOVE
    voxels = _Voxels(occupied, np.where(occupied[..., None], grid.color, 0.0),
                     np.where(occupied[..., None], grid.normal, 0.0))
    _repair_non_finite(voxels)
    return voxels


def _repair_non_finite(voxels: _Voxels) -> None:
    """Occupied voxels whose colour or normal came back NaN copy the nearest sound voxel.

    The voxelizer on llvmpipe can return NaN attributes for a few crossings of triangles
    seen almost edge-on (one NaN fragment spoils the voxel's whole sum); their occupancy is
    still right, so only the attributes are borrowed from the neighbourhood."""
    from scipy.ndimage import distance_transform_edt

    sound = np.isfinite(voxels.color).all(-1) & np.isfinite(voxels.normal).all(-1)
    bad = ~sound
    if not bad.any():
        return
    good = voxels.occupied & sound
    if not good.any():
        voxels.color[bad], voxels.normal[bad] = 0.0, 0.0
        return
    nearest = distance_transform_edt(~good, return_distances=False, return_indices=True)
    source = tuple(index[bad] for index in nearest)
    voxels.color[bad] = voxels.color[source]
    voxels.normal[bad] = voxels.normal[source]


def _inside_box(mesh: RenderMesh, faces: np.ndarray, box_to_world: np.ndarray) -> RenderMesh:
    """The faces as a compact mesh with every vertex moved just inside the box: the faces
    lie within epsilon of the plane only up to rounding, and the voxelizer's half-open
    bounds would drop a face exactly on the far side (or at u = 1 or v = 1)."""
    indices = mesh.indices[faces]
    used, local = np.unique(indices, return_inverse=True)
    to_box = np.linalg.inv(box_to_world)
    world = mesh.world_positions[used]
    uvw = world @ to_box[:3, :3].T + to_box[:3, 3]
    outside = ((uvw < _EDGE) | (uvw > 1 - _EDGE)).any(axis=1)
    clamped = np.clip(uvw[outside], _EDGE, 1 - _EDGE)
    world[outside] = clamped @ box_to_world[:3, :3].T + box_to_world[:3, 3]
    return RenderMesh(world - mesh.origin, local.reshape(-1, 3), mesh.normals[used],
                      mesh.colors[used], None if mesh.uvs is None else mesh.uvs[used],
                      name=mesh.name, materials=mesh.materials, material=mesh.material[faces],
                      origin=mesh.origin)


# -- the variants -----------------------------------------------------------------------

def _variant_maps(voxels: _Voxels, variant: str, outward: np.ndarray) -> _Maps:
    if variant == "volumetric":
        return _Maps(_encode_color(voxels.color, voxels.occupied),
                     _encode_normal(voxels.normal), None)
    covered = voxels.occupied.any(axis=0)
    lowest, highest = _column_extremes(voxels.occupied)
    outer = _outer_surface(voxels, highest, outward)
    index = outer[None, ..., None]
    color = np.take_along_axis(voxels.color, index, axis=0)[0]
    normal = np.take_along_axis(voxels.normal, index, axis=0)[0]
    d = voxels.depth
    if variant == "shell":
        bottom, top = _run_around(voxels.occupied, outer)
        middle = (bottom + top + 1) / 2 / d
        displacement = _encode_w(np.where(covered, middle, 0.0))[..., None]
        return _Maps(_encode_color(color, covered), _encode_normal(normal), displacement)
    interval = np.stack([np.where(covered, lowest / d, 0.0),
                         np.where(covered, (highest + 1) / d, 0.0)], axis=-1)
    return _Maps(_encode_color(color, covered), _encode_normal(normal), _encode_w(interval))


def _column_extremes(occupied: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(H, W) indices of the lowest and highest occupied voxel of each column (0 if none)."""
    d = occupied.shape[0]
    lowest = np.argmax(occupied, axis=0)
    highest = d - 1 - np.argmax(occupied[::-1], axis=0)
    return lowest, highest


def _outer_surface(voxels: _Voxels, highest: np.ndarray, outward: np.ndarray) -> np.ndarray:
    """(H, W) index of each column's outermost surface seen from the box's outside: its
    highest occupied voxel whose normal faces ``outward`` (+w), else its highest one.

    A surface facing -w at the top of a column is the underside of something whose top
    lies beyond the box (a window's sill, seen along a van's wall from a box on the belt
    line); from w = 1 one sees the +w-facing surface below it, and a thick shell seen from
    the side shows that colour over the whole interval (taking the sill's painted the glass
    down the doors). Surfaces below the outermost are hidden by it in the mesh."""
    d = voxels.depth
    facing = voxels.occupied & (voxels.normal @ np.asarray(outward, np.float32) > 0)
    faced = facing.any(axis=0)
    top_facing = d - 1 - np.argmax(facing[::-1], axis=0)
    return np.where(faced, top_facing, highest)


def _run_around(occupied: np.ndarray, index: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(H, W) lowest and highest voxel of the run of occupied voxels through ``index`` in
    each column: one surface's extent (a sloped sheet spans several voxels; whatever lies
    beyond a gap is another surface)."""
    d = occupied.shape[0]
    layer = np.arange(d)[:, None, None]
    below = ~occupied & (layer < index[None])
    above = ~occupied & (layer > index[None])
    bottom = np.where(below.any(axis=0), d - np.argmax(below[::-1], axis=0), 0)
    top = np.where(above.any(axis=0), np.argmax(above, axis=0) - 1, d - 1)
    return bottom, top


def _auto_thickness(maps: list[_Maps], depth: int) -> float:
    """The standard deviation of the stored displacements of every covered texel of every
    box, clamped to [one voxel, the whole box]."""
    values = np.concatenate([m.displacement[..., 0][m.color[..., 3] >= 128] for m in maps])
    spread = float(np.std(values / DISP_SCALE)) if values.size else 0.0
    return min(max(spread, 1.0 / depth), 1.0)


# -- encodings --------------------------------------------------------------------------

def _encode_color(linear: np.ndarray, occupied: np.ndarray) -> np.ndarray:
    """sRGB uint8 colour with alpha 255 where occupied, 0 elsewhere."""
    rgba = np.concatenate([linear[..., :3], occupied[..., None].astype(np.float32)], axis=-1)
    return to_rgba8(rgba)


def _encode_normal(normal: np.ndarray) -> np.ndarray:
    """(n + 1) / 2 * 255 as uint8 (a zero normal, opposite samples cancelled, is 128)."""
    return np.round((np.clip(normal, -1.0, 1.0) + 1.0) * 127.5).astype(np.uint8)


def _encode_w(w: np.ndarray) -> np.ndarray:
    return np.round(np.clip(w, 0.0, 1.0) * DISP_SCALE).astype(np.uint16)
