"""The displacement-mapping half of the slicing technique (§3): `DisplacementMap` drawn by
surface, orthogonal or screen-space slicing (see `parts.Part`)."""

from __future__ import annotations

from ...core.technique import Baker, CompareMetric, CompareVariant
from . import displacement_render
from .displacement import DisplacementMap
from .displacement_bake import DisplacementParams, bake_displacement
from .displacement_codec import CODECS
from .parts import Part


def _is_map(rep) -> bool:
    return isinstance(rep, DisplacementMap)


def _compare_variants() -> tuple:
    return (CompareVariant("orthogonal slicing", {"slicing": "orthogonal"}, _is_map),
            CompareVariant("screen slicing", {"slicing": "screen"}, _is_map),
            CompareVariant("surface slicing (fill)", {"slicing": "surface",
                                                      "alpha_test": "fill"}, _is_map),
            CompareVariant("surface slicing (bound)", {"slicing": "surface",
                                                       "alpha_test": "bound"}, _is_map))


def _against_reference(frame, rep, camera):
    from .displacement_reference import against_reference

    return against_reference(frame, rep, camera)


def _demo_tiles():
    from .displacement_demo import demo_tiles

    return demo_tiles()


def _samples() -> dict:
    """A small furry donut (Fig. 1's torus, 25 x 25 quads, a 16-texel fur)."""
    from .displacement_demo import furry_donut

    return {"displacement": furry_donut(res=16)}


PART = Part(
    codecs=CODECS,
    representations=(DisplacementMap,),
    bakers=(Baker("displacement", "a displacement map drawn by slicing (§3): a heightmap on "
                  "one polygon, a mesh projected from above onto one, or a mesh with uvs "
                  "displaced by fur, bumps, waves or a heightmap",
                  DisplacementParams, bake_displacement, sources=("mesh", "heightmap")),),
    drawables=(displacement_render.drawable_spec(),),
    compare_variants=_compare_variants(),
    compare_metrics=(CompareMetric("displacement reference", _against_reference,
                                   ("reference_wrong", "reference_depth_texels")),),
    programs=displacement_render.PROGRAMS,
    demo_tiles=_demo_tiles,
    samples=_samples,
    cli_examples={
        "bake": ["reliefkit bake terrain.png --as displacement --displacement-scale 0.3 "
                 "-o terrain.rk",
                 "reliefkit bake demo:torus --as displacement --displacement fur --tile 8,4 "
                 "--res 64 -o donut.rk"],
        "render": ["reliefkit render donut.rk --slicing orthogonal --slices 20 -o donut.png",
                   "reliefkit render terrain.rk --slicing screen -o terrain.png"],
    },
)
