"""Baking a billboard cloud: the planes of `build_billboard_cloud`, each plane's own faces
projected onto its rectangle through the core's mesh projection, packed into atlases."""

from __future__ import annotations

import numpy as np

from ...bake.project import dilate, project_mesh
from ...colorspace import to_rgba8
from ...errors import UsageError
from ...scene.mesh import RenderMesh
from .atlas import pack
from .cloud import BillboardCloudPlan, BillboardPlane, build_billboard_cloud
from .representation import GUTTER, BillboardCloud

#: Most texels a cloud's atlases may hold (four 4096² pages, 448 MiB with the normals).
MAX_TEXELS = 4 * 4096 * 4096


def bake_billboard_cloud(mesh: RenderMesh, *, epsilon: float = 0.05,
                         max_planes: int | None = None, texel_size: float | None = None,
                         progress=None, ctx=None) -> BillboardCloud:
    """The billboard cloud of ``mesh``: planes chosen greedily (every face within ``epsilon``
    times the bounding-box diagonal of its plane), then baked at ``texel_size`` (world;
    default diagonal / 256). ``progress(done, total)`` counts faces assigned, then planes."""
    faces = mesh.triangle_count
    total = [faces]

    def generating(done, _):
        if progress:
            progress(done, total[0])

    plan = build_billboard_cloud(mesh, epsilon, max_planes, texel_size, progress=generating)
    total[0] = faces + len(plan.planes)
    cloud = bake_plan(mesh, plan, progress=lambda k: progress and progress(faces + k, total[0]),
                      ctx=ctx)
    if max_planes is not None:
        cloud.params["max_planes"] = max_planes
    return cloud


def bake_plan(mesh: RenderMesh, plan: BillboardCloudPlan, *, progress=None,
              ctx=None) -> BillboardCloud:
    """Colour (alpha = coverage) and normal maps of every plane of ``plan``, in atlases."""
    texels = sum(w * h for w, h in (p.resolution for p in plan.planes))
    if texels > MAX_TEXELS:
        raise UsageError(f"the {len(plan.planes)} rectangles need {texels:,} texels at a texel "
                         f"size of {plan.texel_size:.3g}, more than {MAX_TEXELS:,}; bake with a "
                         "larger --texel-size")
    side, pages, placed = pack([p.resolution for p in plan.planes])
    color = np.zeros((pages, side, side, 4), np.uint8)
    normal = np.full((pages, side, side, 3), 128, np.uint8)
    for k, plane in enumerate(plan.planes):
        block_color, block_normal = _plane_maps(mesh, plane, plan.epsilon, ctx)
        page, x, y = placed[k]
        h, w = block_color.shape[:2]
        color[page, y - GUTTER:y + h - GUTTER, x - GUTTER:x + w - GUTTER] = block_color
        normal[page, y - GUTTER:y + h - GUTTER, x - GUTTER:x + w - GUTTER] = block_normal
        if progress:
            progress(k + 1)
    rects = np.array([[*placed[k], *p.resolution] for k, p in enumerate(plan.planes)], np.int32)
    params = {"epsilon": plan.epsilon_fraction, "texel_size": plan.texel_size,
              "source": mesh.name, "generation": plan.summary()}
    return BillboardCloud(
        corners=np.stack([p.corner for p in plan.planes]),
        u_axes=np.stack([p.u_axis for p in plan.planes]),
        v_axes=np.stack([p.v_axis for p in plan.planes]),
        rects=rects, color=color, normal=normal, epsilon=plan.epsilon,
        source_bounds=mesh.bounds, params=params, generation_seconds=plan.seconds)


def plane_box(plane: BillboardPlane, epsilon: float) -> np.ndarray:
    """box_to_world of the plane's billboard box: its rectangle, +-epsilon along its normal
    (h = 1 on the side the faces face, so a projection sees them from outside)."""
    box = np.eye(4)
    box[:3, 0], box[:3, 1] = plane.u_axis, plane.v_axis
    box[:3, 2] = 2 * epsilon * plane.normal
    box[:3, 3] = plane.corner - epsilon * plane.normal
    return box


def faces_of(mesh: RenderMesh, faces: np.ndarray) -> RenderMesh:
    """The mesh with only ``faces`` (its vertex arrays shared, not copied)."""
    return RenderMesh(mesh.positions, mesh.indices[faces], mesh.normals, mesh.colors,
                      mesh.uvs, name=mesh.name, materials=mesh.materials,
                      material=mesh.material[faces], origin=mesh.origin)


def _plane_maps(mesh, plane: BillboardPlane, epsilon: float, ctx):
    """(h + 2G, w + 2G) RGBA8 and normal8 blocks of one plane, gutter included: alpha is the
    coverage; colours and normals are dilated into the empty texels so filtering near a
    silhouette never mixes in black."""
    # a box a little thicker than epsilon: faces lie within it up to rounding
    projection = project_mesh(faces_of(mesh, plane.faces), plane_box(plane, 1.001 * epsilon),
                              plane.resolution, ctx=ctx)
    w, h = plane.resolution
    mask = np.zeros((h + 2 * GUTTER, w + 2 * GUTTER), bool)
    mask[GUTTER:GUTTER + h, GUTTER:GUTTER + w] = projection.mask
    rgba = np.zeros(mask.shape + (4,), np.float32)
    nrm = np.zeros(mask.shape + (3,), np.float32)
    inner = (slice(GUTTER, GUTTER + h), slice(GUTTER, GUTTER + w))
    rgba[inner] = projection.color
    nrm[inner] = projection.normal
    alpha = np.where(mask, rgba[..., 3], 0.0)
    rgba, nrm = dilate(mask, rgba, nrm)
    rgba[..., 3] = alpha
    length = np.linalg.norm(nrm, axis=-1, keepdims=True)
    unit = np.where(length > 0, nrm / np.maximum(length, 1e-12), 0.0)
    return to_rgba8(rgba), np.round((unit + 1.0) * 127.5).astype(np.uint8)
