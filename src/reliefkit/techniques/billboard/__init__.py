"""Billboard clouds (Décoret et al. 2003) and displacement-mapped billboard clouds (Mantler,
Jeschke, Wimmer): a mesh as textured rectangles, each holding the faces within epsilon of its
plane, or as boxes around them that ray-cast the volume inside.

The public API re-exported by `reliefkit`: `build_billboard_cloud`, `bake_billboard_cloud`,
`BillboardCloud`.
"""

from __future__ import annotations

from ...core.technique import Baker, CompareVariant, Technique
from .bake import bake_billboard_cloud
from .bakers import BillboardCloudParams, bake_cloud
from .cloud import BillboardCloudPlan, build_billboard_cloud
from .codec import CODECS
from .render import PROGRAMS, drawable_spec
from .representation import BillboardCloud


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
    return {"billboard-cloud": BillboardCloud(
        corners=np.array([[-1.0, -1.0, 0.0], [0.0, -1.0, 1.0]]),
        u_axes=np.array([[2.0, 0, 0], [0, 0, -2.0]]),
        v_axes=np.array([[0, 2.0, 0], [0, 2.0, 0]]),
        rects=np.array([[0, 2, 2, 12, 12], [0, 18, 2, 12, 12]], np.int32),
        color=color, normal=normal, epsilon=0.05,
        source_bounds=np.array([[-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]]),
        params={"source": "sample"})}


TECHNIQUE = Technique(
    name="billboard",
    summary="billboard clouds: textured rectangles, each holding the faces near its plane",
    package=__name__,
    codecs=CODECS[:1],
    representations=(BillboardCloud,),
    bakers=(
        Baker("billboard-cloud", "Décoret's greedy planes, each face within epsilon of one, "
              "as textured rectangles in atlases", BillboardCloudParams, bake_cloud),
    ),
    drawables=(drawable_spec(),),
    compare_variants=(CompareVariant("billboard cloud"),),
    demo_tiles=_demo_tiles,
    programs=PROGRAMS,
    samples=_samples,
    cli_examples={
        "bake": ["reliefkit bake demo:tree --as billboard-cloud -o tree-bbc.rk",
                 "reliefkit bake model.glb --as billboard-cloud --epsilon 0.03 "
                 "--max-planes 24 --texel-size 0.005 -o model-bbc.rk"],
        "render": ["reliefkit render tree-bbc.rk --view 30,10,2.4 -o tree-bbc.png"],
        "compare": ["reliefkit compare demo:vehicle --as billboard-cloud --out cmp"],
    },
)

__all__ = ["TECHNIQUE", "BillboardCloud", "BillboardCloudPlan", "bake_billboard_cloud",
           "build_billboard_cloud"]
