"""The depth-object and visual-hull half of the slicing technique (§4, §5)."""

from __future__ import annotations

from ...core.technique import Baker, CompareMetric, CompareVariant, DemoTile
from . import render
from .bakers import (
    DEPTH_IMAGES_SIZING,
    DepthObjectParams,
    bake_depth_object,
    bake_visual_hull,
)
from .codec import CODECS
from .parts import Part
from .representation import DepthObject, VisualHull


def _is_depth_object(rep) -> bool:
    return isinstance(rep, DepthObject)


def _hull_of(rep, mesh):
    """The visual hull of the compared depth object's own images (same bake)."""
    return rep if rep.hull else VisualHull.of(rep.images, rep.params | {"derived": "hull"},
                                              rep.source_bounds)


def _compare_variants() -> tuple[CompareVariant, ...]:
    """The default drawing first, each other way of drawing the images, then the visual hull
    of the same images (§5)."""
    on = _is_depth_object
    return (CompareVariant("ray cast", {"slicing": "raycast"}, on),
            CompareVariant("orthogonal slices", {"slicing": "orthogonal"}, on),
            CompareVariant("screen slices", {"slicing": "screen"}, on),
            CompareVariant("orthogonal slices, point test", {"slicing": "orthogonal",
                                                             "alpha_test": "point"}, on),
            CompareVariant("stencil passes", {"slicing": "orthogonal", "passes": "stencil"},
                           on),
            CompareVariant("nearest image", {"slicing": "raycast", "texturing": "nearest"},
                           on),
            CompareVariant("paper's texturing", {"slicing": "raycast", "visibility": False},
                           on),
            CompareVariant("visual hull", {"slicing": "raycast"}, on, _hull_of))


def _against_reference(frame, rep, camera):
    if not isinstance(rep, DepthObject):
        return {}, None
    from .measure import against_reference

    scores = against_reference(frame, rep.images, camera)
    return {"reference_iou": scores["iou"], "reference_rms_texels": scores["depth_rms_texels"],
            "reference_wrong": scores["wrong_fraction"]}, scores["wrong"]


def _samples() -> dict:
    """A small box-and-sphere object baked at 16 texels (needs GL)."""
    from ...scene.assets import make_asset

    mesh = make_asset("blob")
    return {"depth-object": bake_depth_object(mesh, DepthObjectParams(res=16)),
            "visual-hull": bake_visual_hull(mesh, DepthObjectParams(res=16))}


def _demo_tiles() -> list[DemoTile]:
    def baked(asset: str, hull: bool):
        def make():
            from ...scene.assets import make_asset

            bake = bake_visual_hull if hull else bake_depth_object
            return bake(make_asset(asset), DepthObjectParams(res=128))

        return make

    return [DemoTile("depth object: vehicle", "depth-object-vehicle", baked("vehicle", False),
                     (40.0, 20.0, None)),
            DemoTile("depth object: blob", "depth-object-blob", baked("blob", False),
                     (35.0, 25.0, 2.5)),
            DemoTile("visual hull: blob", "visual-hull-blob", baked("blob", True),
                     (35.0, 25.0, 2.5))]


PART = Part(
    codecs=CODECS,
    representations=(DepthObject, VisualHull),
    bakers=(Baker("depth-object", "six orthographic depth images on the bounding cube, "
                  "drawn as the intersection of their displaced volumes (§4)",
                  DepthObjectParams, bake_depth_object, sizings=(DEPTH_IMAGES_SIZING,)),
            Baker("visual-hull", "the six images' silhouettes only: the visual hull (§5)",
                  DepthObjectParams, bake_visual_hull, sizings=(DEPTH_IMAGES_SIZING,))),
    drawables=(render.drawable_spec(),),
    compare_variants=_compare_variants(),
    compare_metrics=(CompareMetric("exact reference", _against_reference,
                                   ("reference_iou", "reference_rms_texels",
                                    "reference_wrong")),),
    programs=render.PROGRAMS,
    demo_tiles=_demo_tiles,
    samples=_samples,
    cli_examples={
        "bake": ["reliefkit bake demo:vehicle --as depth-object --res 256 -o van.rk",
                 "reliefkit bake model.glb --as visual-hull --res 128 -o hull.rk"],
        "render": ["reliefkit render van.rk -o van.png --aovs van.npz --stats van.json",
                   "reliefkit render van.rk --slicing screen --slices 200 -o van.png",
                   "reliefkit render van.rk --slicing orthogonal --passes stencil "
                   "--texturing nearest -o van.png"],
        "compare": ["reliefkit compare demo:vehicle --as depth-object --out cmp-van"],
    },
)
