"""A toy technique that lives in the tests: it proves the core's hooks suffice.

It registers a kind (``toy-quad``), a baker, a drawable with a render option named
``method`` (as relief has, with other choices), a compare variant and metric, a bench suite,
a demo tile, sample representations and a shader namespace, all from this one module and its
``shaders/`` folder, without touching the core. Its quad is opaque or, with an alpha below 1,
a transparent drawable of known opacity (the analytic scene of the transparent-pass tests).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from reliefkit.core.params import param
from reliefkit.core.technique import (
    Baker,
    BenchSuite,
    CompareMetric,
    CompareVariant,
    DemoTile,
    DrawableSpec,
    ProgramVariant,
    Technique,
)
from reliefkit.errors import FormatError, UsageError
from reliefkit.io.rk import ArraySpec, Codec
from reliefkit.render.plan import Attribute, DrawPlan, Geometry, Program, Raster
from reliefkit.scene.mesh import Material, RenderMesh

PROGRAM = "toy:toy.glsl"


@dataclass(eq=False)
class ToyQuad:
    """A planar quad: corners (4, 3) in order around it, linear straight RGBA colour."""

    corners: np.ndarray
    color: np.ndarray
    params: dict = field(default_factory=dict)

    def __post_init__(self):
        self.corners = np.asarray(self.corners, dtype=np.float64)
        self.color = np.asarray(self.color, dtype=np.float32)
        if self.corners.shape != (4, 3) or self.color.shape != (4,):
            raise UsageError("a toy quad has (4, 3) corners and an RGBA colour")
        if not (np.isfinite(self.color).all() and (self.color >= 0).all()
                and (self.color <= 1).all()):
            raise UsageError("toy quad colour must lie in [0, 1]")

    @property
    def normal(self) -> np.ndarray:
        c = self.corners
        n = np.cross(c[1] - c[0], c[3] - c[0])
        return n / np.linalg.norm(n)

    @property
    def bounds(self) -> np.ndarray:
        return np.stack([self.corners.min(axis=0), self.corners.max(axis=0)])

    def summary(self) -> dict:
        return {"kind": "toy-quad", "opacity": float(self.color[3])}

    def fallback_mesh(self, triangles: int = 20_000) -> RenderMesh:
        """What a glTF viewer shows: the quad's two triangles in its colour (opacity as
        glTF's BLEND when below 1); the count is fixed."""
        alpha = "OPAQUE" if self.color[3] >= 1 else "BLEND"
        return RenderMesh(self.corners, [[0, 1, 2], [0, 2, 3]], np.tile(self.normal, (4, 1)),
                          np.ones((4, 4)), name="toy-quad",
                          materials=[Material("toy", self.color, alpha_mode=alpha)])


CODEC = Codec(
    kind="toy-quad", cls=ToyQuad,
    arrays={"corners": ArraySpec(("float64",), 2, trailing=(4, 3), finite=True),
            "color": ArraySpec(("float32",), 1, trailing=(4,), finite=True)},
    to_arrays=lambda q: ({"corners": q.corners, "color": q.color}, dict(q.params)),
    from_arrays=lambda arrays, params: _from_arrays(arrays, params))


def _from_arrays(arrays, params):
    try:
        return ToyQuad(arrays["corners"], arrays["color"], params)
    except UsageError as exc:
        raise FormatError(f"invalid toy quad: {exc}") from None


@dataclass(frozen=True)
class ToyBakeParams:
    opacity: float = param(1.0, "the quad's opacity", lo=0.0, hi=1.0)
    depth_res: int = param(16, "unused resolution (shares relief's flag)", lo=1, hi=64)


def bake_quad(mesh, p: ToyBakeParams, progress=None) -> ToyQuad:
    """The mesh's bounding rectangle in the plane z = centre, facing +z."""
    lo, hi = mesh.bounds
    z = 0.5 * (lo[2] + hi[2])
    corners = [[lo[0], lo[1], z], [hi[0], lo[1], z], [hi[0], hi[1], z], [lo[0], hi[1], z]]
    if progress:
        progress(1, 1)
    return ToyQuad(corners, [0.9, 0.5, 0.1, p.opacity], {"source": mesh.name})


@dataclass(frozen=True)
class ToyRenderOptions:
    method: str = param("flat", "toy: flat colour or a checker", choices=("flat", "checker"))


class ToyDrawable:
    """One quad as one draw plan; transparent when its opacity is below 1."""

    def __init__(self, quad: ToyQuad, options: ToyRenderOptions, instrument: bool):
        self.quad = quad
        transparent = bool(quad.color[3] < 1.0)
        self.extra_attachments = 1 if instrument and not transparent else 0
        origin = quad.corners.mean(axis=0)  # geometry relative to it (camera-relative)
        tris = (quad.corners[[0, 1, 2, 0, 2, 3]] - origin).astype(np.float32)
        self.plans = [DrawPlan(
            name="toy quad",
            program=Program(PROGRAM, {"TRANSPARENT": transparent,
                                      "CHECKER": options.method == "checker",
                                      "COUNT_ITERATIONS": bool(self.extra_attachments)}),
            geometry=Geometry({"in_position": Attribute(tris)}),
            uniforms={"u_color": tuple(float(c) for c in quad.color),
                      "u_normal": tuple(float(c) for c in quad.normal)},
            raster=Raster(depth_write=False, blend="under") if transparent else Raster(),
            render_pass="transparent" if transparent else "opaque",
            origin=tuple(float(x) for x in origin))]

    def sort_distance(self, camera) -> float:
        return float(np.linalg.norm(self.quad.corners.mean(axis=0) - np.asarray(camera.eye)))

    def finish(self, frame, stats) -> None:
        frame.stats["toy_quads"] = frame.stats.get("toy_quads", 0) + 1


def _mean_alpha(frame, quad, camera):
    alpha = frame.color[..., 3]
    return {"mean_alpha": float(alpha[frame.mask].mean()) if frame.mask.any() else 0.0}, None


def _bench(quick, out, log):
    out.mkdir(parents=True, exist_ok=True)
    path = Path(out) / "toy.md"
    path.write_text("toy bench\n")
    log("toy bench ran")
    return "toy bench: nothing to measure\n", [path]


def _samples():
    return {"toy-quad": ToyQuad([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]],
                                [0.2, 0.4, 0.8, 1.0], {"note": "sample"})}


def _demo_tiles():
    return [DemoTile("toy quad", "toy-quad", lambda: _samples()["toy-quad"], (0, 0, 3.0))]


TECHNIQUE = Technique(
    name="toy",
    summary="a coloured quad (test technique)",
    package=__name__,
    codecs=(CODEC,),
    representations=(ToyQuad,),
    bakers=(Baker("toy-quad", "the bounding rectangle of a mesh", ToyBakeParams, bake_quad),),
    drawables=(DrawableSpec(ToyQuad, ToyDrawable, ToyRenderOptions),),
    compare_variants=(CompareVariant("flat", {"method": "flat"}),
                      CompareVariant("checker", {"method": "checker"})),
    compare_metrics=(CompareMetric("alpha", _mean_alpha, ("mean_alpha",)),),
    bench_suites=(BenchSuite("toy", "a bench suite of the toy technique", _bench),),
    demo_tiles=_demo_tiles,
    programs=tuple(ProgramVariant(PROGRAM, {"TRANSPARENT": t, "CHECKER": c})
                   for t in (False, True) for c in (False, True)),
    samples=_samples,
    cli_examples={"bake": ["reliefkit bake demo:blob --as toy-quad -o quad.rk"]},
)
