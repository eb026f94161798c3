"""Billboard clouds (Décoret et al. 2003) and displacement-mapped billboard clouds (Mantler,
Jeschke, Wimmer): a mesh as textured rectangles, each holding the faces within epsilon of its
plane, or as boxes around them that ray-cast the volume inside.

The public API re-exported by `reliefkit`: `build_billboard_cloud`, `bake_billboard_cloud`,
`bake_boxes`, `BillboardCloud`, `BillboardBoxes`.
"""

from __future__ import annotations

from ...core.technique import Baker, BenchSuite, CompareMetric, CompareVariant, Technique
from . import box_render, render
from .bake import bake_billboard_cloud
from .bakers import (
    CLOUD_SIZING,
    DMBBC_SIZINGS,
    BillboardBoxesParams,
    BillboardCloudParams,
    bake_cloud,
    bake_dmbbc,
)
from .box_bake import bake_boxes
from .boxes import VARIANTS, BillboardBoxes
from .cloud import BillboardCloudPlan, build_billboard_cloud
from .codec import CODECS
from .representation import BillboardCloud


def _box_wrong_hits(frame, rep, camera):
    """Wrong hits of a DMBBC against its exact CPU reference (none for the flat cloud)."""
    if not isinstance(rep, BillboardBoxes):
        return {}, None
    from .box_reference import wrong_hits

    wrong = wrong_hits(frame, rep, camera)
    return ({"wrong_hit_fraction": wrong["wrong_fraction"],
             "wrong_pixels": wrong["wrong_pixels"]}, wrong["wrong"])


def _depth_error(frame, rep, camera, mesh_frame):
    """Mean distance between the representation's and the mesh's surface point per pixel both
    cover, in voxels (texels) of the bake: how far the BBC's flat rectangles and the DMBBC's
    boxes put the surface."""
    import numpy as np

    both = frame.mask & mesh_frame.mask
    texel = rep.params.get("texel_size")
    if not both.any() or not texel:
        return {}, None
    gap = np.linalg.norm(frame.position[both] - mesh_frame.position[both], axis=-1)
    return {"depth_error_voxels": float(gap.mean() / texel)}, None


def _other_variant(variant: str):
    """A DMBBC of ``variant`` baked from the mesh with the compared one's parameters."""
    def derive(rep, mesh):
        if rep.variant == variant:
            return rep
        p = rep.params
        return bake_boxes(mesh, variant, epsilon=p["epsilon"], max_planes=p.get("max_planes"),
                          texel_size=p["texel_size"], surfaces=p.get("surfaces", "average"))

    return derive


def _compare_variants() -> tuple[CompareVariant, ...]:
    """The flat cloud (itself, or a DMBBC's own), a DMBBC in the three marches (the exact one
    is the reference the others are measured against), and the other two DMBBC variants
    baked with the same planes, sphere-traced."""
    def boxes(rep) -> bool:
        return isinstance(rep, BillboardBoxes)

    flat = CompareVariant("billboard cloud",
                          derive=lambda rep, mesh: rep.cloud if boxes(rep) else rep)
    marches = tuple(CompareVariant(march, {"march": march}, boxes)
                    for march in box_render.MARCHES)
    others = tuple(CompareVariant(variant, {"march": "sphere"},
                                  lambda rep, v=variant: boxes(rep) and rep.variant != v,
                                  _other_variant(variant)) for variant in VARIANTS)
    return (flat, *marches, *others)


def _bench(quick, out, log):
    from .bench import run_suite

    return run_suite(quick, out, log)


def _demo_tiles():
    from .demo import demo_tiles

    return demo_tiles()


def _samples() -> dict:
    """A two-rectangle cloud (a red and a green card crossing at right angles) for the
    contract tests."""
    import numpy as np

    color = np.zeros((1, 16, 32, 4), np.uint8)
    color[0, 2:14, 2:14] = (200, 40, 40, 255)
    color[0, 2:14, 18:30] = (40, 200, 40, 255)
    normal = np.zeros((1, 16, 32, 3), np.uint8)
    normal[0, :, :16] = (128, 128, 255)   # +z
    normal[0, :, 16:] = (255, 128, 128)   # +x
    cloud = BillboardCloud(
        corners=np.array([[-1.0, -1.0, 0.0], [0.0, -1.0, 1.0]]),
        u_axes=np.array([[2.0, 0, 0], [0, 0, -2.0]]),
        v_axes=np.array([[0, 2.0, 0], [0, 2.0, 0]]),
        rects=np.array([[0, 2, 2, 12, 12], [0, 18, 2, 12, 12]], np.int32),
        color=color, normal=normal, epsilon=0.05,
        source_bounds=np.array([[-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]]),
        params={"source": "sample"})
    return {"billboard-cloud": cloud, "dmbbc": _sample_boxes(cloud)}


def _sample_boxes(cloud: BillboardCloud) -> BillboardBoxes:
    """The cloud's two cards as volumetric boxes 12 x 12 x 3 with a bumpy sheet in each."""
    import numpy as np

    from .bake import plane_box
    from .boxes import BillboardBox

    boxes = []
    for p, rgb in ((0, (200, 40, 40)), (1, (40, 200, 40))):
        plane = type("Plane", (), {"u_axis": cloud.u_axes[p], "v_axis": cloud.v_axes[p],
                                   "normal": cloud.normals[p], "corner": cloud.corners[p]})
        color = np.zeros((3, 12, 12, 4), np.uint8)
        layer = (np.add.outer(np.arange(12), np.arange(12)) // 4) % 3  # a staircase
        for k in range(3):
            color[k][layer == k] = (*rgb, 255)
        normal = np.zeros((3, 12, 12, 3), np.uint8)
        normal[...] = np.round((cloud.normals[p] + 1) * 127.5).astype(np.uint8)
        occupied = color[..., 3] > 0
        from scipy.ndimage import distance_transform_edt

        distance = np.minimum(np.floor(distance_transform_edt(~occupied)), 255).astype(np.uint8)
        boxes.append(BillboardBox(plane_box(plane, cloud.epsilon), color, normal, distance))
    return BillboardBoxes("volumetric", boxes, cloud, source_bounds=cloud.source_bounds,
                          params={"source": "sample"})


TECHNIQUE = Technique(
    name="billboard",
    summary="billboard clouds: textured rectangles, each holding the faces near its plane",
    package=__name__,
    codecs=CODECS,
    representations=(BillboardCloud, BillboardBoxes),
    bakers=(
        Baker("billboard-cloud", "Décoret's greedy planes, each face within epsilon of one, "
              "as textured rectangles in atlases", BillboardCloudParams, bake_cloud,
              sizings=(CLOUD_SIZING,)),
        Baker("dmbbc", "displacement-mapped billboard clouds: boxes of +-epsilon around the "
              "same rectangles, ray-cast (volumetric, shell or thick shell)",
              BillboardBoxesParams, bake_dmbbc, sizings=DMBBC_SIZINGS),
    ),
    drawables=(render.drawable_spec(), box_render.drawable_spec()),
    compare_variants=_compare_variants(),
    compare_metrics=(CompareMetric("wrong hits", _box_wrong_hits,
                                   ("wrong_hit_fraction", "wrong_pixels")),
                     CompareMetric("depth error", _depth_error, ("depth_error_voxels",),
                                   against_mesh=True)),
    bench_suites=(BenchSuite("billboard", "Tables 1-2 and Fig. 6 of the DMBBC paper: BBC vs "
                             "DMBBC vs the mesh, sphere vs uniform marches, the lod switch",
                             _bench),),
    demo_tiles=_demo_tiles,
    programs=render.PROGRAMS + box_render.PROGRAMS,
    samples=_samples,
    cli_examples={
        "bake": ["reliefkit bake demo:tree --as billboard-cloud -o tree-bbc.rk",
                 "reliefkit bake demo:tree --as dmbbc --variant volumetric -o tree-box.rk",
                 "reliefkit bake demo:vehicle --as dmbbc --variant thick-shell -o van-box.rk",
                 "reliefkit bake model.glb --as billboard-cloud --epsilon 0.03 "
                 "--max-planes 24 --texel-size 0.005 -o model-bbc.rk"],
        "render": ["reliefkit render tree-bbc.rk --view 30,10,2.4 -o tree-bbc.png",
                   "reliefkit render tree-box.rk --march sphere --stats s.json -o tree.png",
                   "reliefkit render tree-box.rk --march uniform --samples 4 -o tree.png"],
        "compare": ["reliefkit compare demo:vehicle --as billboard-cloud --out cmp",
                    "reliefkit compare demo:tree --as dmbbc --out cmp"],
    },
)

__all__ = ["TECHNIQUE", "BillboardCloud", "BillboardCloudPlan", "BillboardBoxes",
           "bake_billboard_cloud", "bake_boxes", "build_billboard_cloud"]
