"""Displacement mapping by slicing, image-based depth objects and visual hulls (Kautz &
Seidel 2001): a displacement volume (or the bounding cube of six depth images) cut into
slices, each fragment kept by an alpha test against the displacement (or against all six
depth images).

Two halves, each a `parts.Part`: displacement maps (§3, `displacement_part`) and depth
objects with visual hulls (§4-§5, `depth_object_part`); this module merges them into one
`Technique`.

The public API re-exported by `reliefkit`: `DepthImages`, `bake_depth_images`,
`DepthObject`, `VisualHull`, `DisplacementMap`.
"""

from __future__ import annotations

from ...core.technique import BenchSuite, Technique
from .depth_images import DepthImages, bake_depth_images
from .depth_object_part import PART as DEPTH_OBJECTS
from .displacement import DisplacementMap
from .displacement_part import PART as DISPLACEMENT
from .representation import DepthObject, VisualHull

PARTS = (DEPTH_OBJECTS, DISPLACEMENT)


def _merged(name: str) -> tuple:
    return tuple(x for part in PARTS for x in getattr(part, name))


def _demo_tiles() -> list:
    return [tile for part in PARTS if part.demo_tiles for tile in part.demo_tiles()]


def _samples() -> dict:
    out: dict = {}
    for part in PARTS:
        if part.samples:
            out |= part.samples()
    return out


def _bench(quick, out, log):
    from .bench import run_suite

    return run_suite(quick, out, log)


def _cli_examples() -> dict:
    out: dict = {}
    for part in PARTS:
        for command, lines in part.cli_examples.items():
            out.setdefault(command, []).extend(lines)
    return out


TECHNIQUE = Technique(
    name="slicing",
    summary="displacement maps, depth objects and visual hulls drawn by slicing their volume "
            "(or by ray casting the six depth images)",
    package=__name__,
    codecs=_merged("codecs"),
    representations=_merged("representations"),
    bakers=_merged("bakers"),
    drawables=_merged("drawables"),
    compare_variants=_merged("compare_variants"),
    compare_metrics=_merged("compare_metrics"),
    bench_suites=(BenchSuite("slicing", "quality, convergence, texturing, Fig. 12 and the "
                             "stencil passes of the displacement slicing and depth objects "
                             "paper, with Open3D's carving as a peer", _bench),),
    demo_tiles=_demo_tiles,
    programs=_merged("programs"),
    samples=_samples,
    cli_examples=_cli_examples(),
)

__all__ = ["TECHNIQUE", "DepthImages", "DepthObject", "DisplacementMap", "VisualHull",
           "bake_depth_images"]
