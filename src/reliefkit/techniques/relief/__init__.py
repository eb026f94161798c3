"""Relief textures (Baboud & Décoret 2006): heightfields in a box, a reverse frustum or six.

The public API re-exported by `reliefkit`: `bake_relief`, `bake_relief_frustum`,
`bake_relief_cube`, `relief_from_heights`, `ReliefTexture`, `ReliefObject`.
"""

from __future__ import annotations

from ...core.technique import (
    Baker,
    BenchSuite,
    CompareMetric,
    CompareVariant,
    DrawableSpec,
    ProgramVariant,
    Technique,
)
from .bake import bake_relief, relief_from_heights
from .bakers import (
    CUBE_SIZING,
    ReliefCubeParams,
    ReliefFrustumParams,
    ReliefParams,
    bake_cube,
    bake_frustum,
    bake_orthographic,
)
from .codec import CODECS
from .frustum import bake_relief_cube, bake_relief_frustum
from .render import (
    METHODS,
    PROGRAM,
    ReliefDrawable,
    ReliefObjectDrawable,
    ReliefRenderOptions,
    drawn_method,
)
from .representation import ReliefObject, ReliefTexture


def _robust_draws(rep) -> bool:
    """Whether robust can draw ``rep``: every part has its radii or is drawn without them."""
    options = ReliefRenderOptions(method="robust")
    return all(p.safety is not None or drawn_method(p, options) != "robust"
               for p in getattr(rep, "parts", [rep]))


def _wrong_hits(frame, rep, camera):
    from .reference import wrong_hits

    wrong = wrong_hits(frame, rep, camera)
    return ({"wrong_hit_fraction": wrong["wrong_fraction"],
             "wrong_pixels": wrong["wrong_pixels"]}, wrong["wrong"])


def _bench(quick, out, log, mesh=None):
    from .bench import run_suite

    return run_suite(quick, out, log, mesh=mesh)


def _bench_sampling(quick, out, log):
    from .bench_sampling import run_suite

    return run_suite(quick, out, log)


def _demo_tiles():
    from .demo import demo_tiles

    return demo_tiles()


def _samples() -> dict:
    """A 16x16 terrain-like relief with safety radii, and a two-part object of two boxes."""
    import numpy as np

    u, v = np.meshgrid(np.linspace(0, 1, 16), np.linspace(0, 1, 16))
    heights = 0.5 + 0.3 * np.sin(6 * u) * np.cos(5 * v)
    relief = relief_from_heights(heights, size=(2.0, 0.5, 2.0), safety=True)
    lifted = relief.box_to_world.copy()
    lifted[1, 3] += 0.6
    second = ReliefTexture(height=relief.height, color=relief.color,
                           normal=relief.normal, box_to_world=lifted, safety=relief.safety,
                           clip_bounds=np.array([[-1.0, 0.6, -1.0], [1.0, 1.0, 1.0]]))
    return {"relief": relief,
            "relief-object": ReliefObject(parts=[relief, second], params={"projection": "test"})}


def _programs() -> tuple[ProgramVariant, ...]:
    flags = {"WRITE_DEPTH": True, "SHADOWS": True, "COUNT_ITERATIONS": True}
    return tuple(ProgramVariant(PROGRAM, {f"METHOD_{m.upper()}": True} | extra)
                 for m in METHODS for extra in ({}, flags, flags | {"INSTANCED": True})) + (
        ProgramVariant(PROGRAM, {"METHOD_ROBUST": True, "SAFETY_OCTANTS": True} | flags),)


TECHNIQUE = Technique(
    name="relief",
    summary="relief textures: heightfields in a box, a reverse frustum or six frusta",
    package=__name__,
    codecs=CODECS,
    representations=(ReliefTexture, ReliefObject),
    bakers=(
        Baker("relief", "orthographic heightfield over the bounding box (or a heightmap)",
              ReliefParams, bake_orthographic, sources=("mesh", "heightmap")),
        Baker("relief-frustum", "one reverse-perspective frustum that sees the sides (§4.1)",
              ReliefFrustumParams, bake_frustum),
        Baker("relief-cube", "six reverse frusta splitting the bounding cube (§4.2)",
              ReliefCubeParams, bake_cube, sizings=(CUBE_SIZING,)),
    ),
    drawables=(DrawableSpec(ReliefTexture, ReliefDrawable, ReliefRenderOptions),
               DrawableSpec(ReliefObject, ReliefObjectDrawable, ReliefRenderOptions)),
    compare_variants=tuple(
        CompareVariant(m, {"method": m}, _robust_draws if m == "robust" else (lambda rep: True))
        for m in METHODS),
    compare_metrics=(CompareMetric("wrong hits", _wrong_hits,
                                   ("wrong_hit_fraction", "wrong_pixels")),),
    bench_suites=(BenchSuite("relief", "Table 1, Fig. 12 and correctness of relief textures",
                             _bench, takes_mesh=True),
                  BenchSuite("relief-sampling", "safety radii: sampling vs time vs the "
                             "checker's violating rays", _bench_sampling)),
    demo_tiles=_demo_tiles,
    programs=_programs(),
    samples=_samples,
    cli_examples={
        "render": ["reliefkit render terrain.rk --method robust --shadows -o terrain.png",
                   "reliefkit render terrain.rk --method exact --stats stats.json -o t.png"],
        "bake": ["reliefkit bake demo:terrain --as relief --depth-res 256 -o terrain.rk",
                 "reliefkit bake model.glb --as relief --depth-res 256 --color-res 512 "
                 "-o model.rk",
                 "reliefkit bake demo:vehicle --as relief-frustum -o van.rk",
                 "reliefkit bake height.png --as relief --box 2,0.4,2 -o terrain.rk"],
        "compare": ["reliefkit compare demo:vehicle --as relief-frustum --out cmp",
                    "reliefkit compare car.glb --as relief-frustum --view 60,15,2 --out cmp"],
        "bench": ["reliefkit bench relief --quick", "reliefkit bench relief --out docs/bench",
                  "reliefkit bench relief-sampling --out docs/bench"],
    },
)

__all__ = ["TECHNIQUE", "bake_relief", "bake_relief_frustum", "bake_relief_cube",
           "relief_from_heights", "ReliefTexture", "ReliefObject"]
