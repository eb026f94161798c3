"""Octahedral impostors, the game engines' default stand-in for a distant mesh: a grid of
orthographic views on an octahedral map of directions (colour, normal, depth per view),
drawn as one camera-facing quad that blends the three views around the view direction.

The public API re-exported by `reliefkit`: `bake_impostor`, `OctahedralImpostor`.
"""

from __future__ import annotations

from ...core.technique import Baker, BenchSuite, CompareMetric, CompareVariant, Technique
from . import render
from .bake import bake_impostor
from .bakers import ATLAS_SIZING, ImpostorParams, bake_octahedral
from .codec import CODECS
from .representation import OctahedralImpostor


def _grid_position(frame, rep, camera):
    """Where the view lies on the grid: the largest of its three frames' weights (1 on a
    frame, 1/3 at the middle of three) and the angle to the nearest frame."""
    import numpy as np

    from . import octahedral

    if camera.orthographic:
        towards = np.asarray(camera.eye, np.float64) - np.asarray(camera.target, np.float64)
    else:
        towards = np.asarray(camera.eye, np.float64) - rep.center
    towards /= np.linalg.norm(towards)
    frames, weights = octahedral.blend_frames(towards, rep.grid, rep.hemi)
    directions = octahedral.frame_directions(rep.grid, rep.hemi)[frames[:, 1], frames[:, 0]]
    angle = np.degrees(np.arccos(np.clip(directions @ towards, -1.0, 1.0)).min())
    return {"frame_weight": float(weights.max()), "degrees_to_frame": float(angle)}, None


def _depth_error(frame, rep, camera, mesh_frame):
    """Mean distance between the impostor's and the mesh's surface point per pixel both
    cover, in frame texels: how well the stored depths put the surface."""
    import numpy as np

    both = frame.mask & mesh_frame.mask
    if not both.any():
        return {}, None
    gap = np.linalg.norm(frame.position[both] - mesh_frame.position[both], axis=-1)
    return {"depth_error_texels": float(gap.mean() / (2.0 * rep.frame_radius / rep.frame))}, None


def _bench(quick, out, log, mesh=None):
    from .bench import run_suite

    return run_suite(quick, out, log, mesh=mesh)


def _demo_tiles():
    from .demo import demo_tiles

    return demo_tiles()


def _samples() -> dict:
    """A sphere whose every frame is the same disc (4 x 4 frames of 16 texels)."""
    from .analytic import sphere_impostor

    return {"octahedral-impostor": sphere_impostor((0.0, 0.0, 0.0), 1.0)}


TECHNIQUE = Technique(
    name="impostor",
    summary="octahedral impostors: a grid of views on an octahedral map of directions, "
            "three blended on one camera-facing quad",
    package=__name__,
    codecs=CODECS,
    representations=(OctahedralImpostor,),
    bakers=(Baker("octahedral-impostor", "N x N orthographic views (colour, normal, depth) "
                  "on a full or hemi octahedral map, in one atlas per channel",
                  ImpostorParams, bake_octahedral, sizings=(ATLAS_SIZING,)),),
    drawables=(render.drawable_spec(),),
    compare_variants=(CompareVariant("parallax"),
                      CompareVariant("no parallax", {"parallax_steps": 0}),
                      CompareVariant("shadows", {"shadows": True})),
    compare_metrics=(CompareMetric("grid position", _grid_position,
                                   ("frame_weight", "degrees_to_frame")),
                     CompareMetric("depth error", _depth_error, ("depth_error_texels",),
                                   against_mesh=True)),
    bench_suites=(BenchSuite("impostor", "the impostor against the mesh on grid frames and "
                             "between them, at grazing to steep elevations, for several "
                             "grid sizes", _bench, takes_mesh=True),),
    demo_tiles=_demo_tiles,
    programs=render.PROGRAMS,
    samples=_samples,
    cli_examples={
        "bake": ["reliefkit bake demo:tree --as octahedral-impostor -o tree-imp.rk",
                 "reliefkit bake model.glb --as octahedral-impostor --grid 16 --hemi "
                 "--atlas-res 2048 -o model-imp.rk"],
        "render": ["reliefkit render tree-imp.rk --view 30,10,2.4 -o tree-imp.png",
                   "reliefkit render tree-imp.rk --parallax-steps 0 --shadows -o tree.png"],
        "compare": ["reliefkit compare demo:vehicle --as octahedral-impostor --out cmp"],
    },
)

__all__ = ["TECHNIQUE", "OctahedralImpostor", "bake_impostor"]
