"""Semi-transparent 3D textures on a shell of tetrahedra (Dufort, Leblanc & Poulin 2005): a
mesh extruded into prisms, each split into three tetrahedra, filled with a tiled 3D texture,
sorted per frame (SXMPVO) and ray-marched per tetrahedron.

The public API re-exported by `reliefkit`: `build_shell`, `VolumeTexture`,
`visibility_order`, `TexturedShell`.
"""

from __future__ import annotations

from ...core.technique import Baker, BenchSuite, CompareMetric, CompareVariant, Technique
from . import render
from .bakers import SHELL_SIZING, ShellVolumeParams, bake_shell
from .codec import CODECS
from .representation import TexturedShell
from .shell import ShellVolume, build_shell
from .textures import TEXTURES, VolumeTexture


def _compare_variants() -> tuple[CompareVariant, ...]:
    """Lit as drawn by default; unlit without mip filtering (what the CPU reference computes)
    with each order and each exit computation; and with shadows."""
    def sorted_(rep) -> bool:
        return not rep.opaque

    plain = {"unlit": True, "mip": False}
    return (CompareVariant("sxmpvo"),
            CompareVariant("shadows", {"shadows": True}),
            CompareVariant("unlit", plain),
            CompareVariant("unlit, centroid sort", plain | {"sort": "centroid"}, sorted_),
            CompareVariant("unlit, depth peeling", plain | {"sort": "peel"}, sorted_),
            CompareVariant("unlit, exit per vertex", plain | {"exit": "vertex"}))


def _against_reference(frame, rep, camera):
    """Unlit, unfiltered frames against the CPU reference integrator (reference.py): RMSE of
    premultiplied colour and alpha, and the pixels off by more than 0.05; with the order's
    violations on the frame's rays where the shell was sorted."""
    import numpy as np

    from .order import visibility_order
    from .order_check import ordering_violations
    from .reference import reference_render

    out: dict = {}
    sort = frame.stats.get("sort")
    if sort in ("sxmpvo", "centroid"):
        order = visibility_order(rep.shell, camera, method=sort, resolution=max(camera.size))
        out["order_violations"] = ordering_violations(rep.shell, camera, order.order).violations
    if not frame.stats.get("unlit") or frame.stats.get("mip"):
        return out, None
    ref = reference_render(rep.shell, rep.texture, camera, samples=frame.stats["samples"],
                           surface=rep.surface, layers=rep.surface_layers())

    def premultiplied(c):
        return np.concatenate([c[..., :3] * c[..., 3:], c[..., 3:]], axis=-1)

    diff = np.abs(premultiplied(frame.color) - premultiplied(ref.color)).max(axis=-1)
    rmse = float(np.sqrt(((premultiplied(frame.color) - premultiplied(ref.color)) ** 2).mean()))
    wrong = diff > 0.05
    return out | {"reference_rmse": rmse, "reference_off": float(wrong.mean())}, wrong


def _samples() -> dict:
    """Ellipsoids in a medium over a 4 x 4 grid of the xz plane, for the contract tests."""
    import numpy as np

    from ...scene.mesh import RenderMesh
    from .textures import make_ellipsoids

    n = 5
    x, z = np.meshgrid(np.linspace(-1, 1, n), np.linspace(1, -1, n))
    positions = np.column_stack([x.ravel(), np.zeros(n * n), z.ravel()])
    uvs = np.column_stack([(x.ravel() + 1) / 2, (1 - z.ravel()) / 2])
    quads = [(j * n + i, j * n + i + 1, (j + 1) * n + i + 1, (j + 1) * n + i)
             for j in range(n - 1) for i in range(n - 1)]
    faces = [(a, b, c) for a, b, c, _ in quads] + [(a, c, d) for a, _, c, d in quads]
    base = RenderMesh(positions, faces, np.tile((0.0, 1.0, 0.0), (n * n, 1)),
                      np.ones((n * n, 4)), uvs, name="grid")
    texture = make_ellipsoids(size=(8, 8, 4)).tiled((2, 2))
    return {"shell-volume": TexturedShell(base, 0.3, texture, {"source": "sample"})}


def _bench(quick, out, log):
    from .bench import run_suite

    return run_suite(quick, out, log)


def _demo_tiles():
    from .demo import demo_tiles

    return demo_tiles()


TECHNIQUE = Technique(
    name="shellvolume",
    summary="semi-transparent 3D textures in a shell of tetrahedra, sorted and ray-marched",
    package=__name__,
    codecs=CODECS,
    representations=(TexturedShell,),
    bakers=(Baker("shell-volume", "a 3D texture (fur, clouds, ellipsoids, absorption, chain, "
                  "rocks, a .npy, a voxelized mesh) tiled in a shell extruded from the mesh",
                  ShellVolumeParams, bake_shell, sizings=(SHELL_SIZING,)),),
    drawables=(render.drawable_spec(),),
    compare_variants=_compare_variants(),
    compare_metrics=(CompareMetric("CPU reference", _against_reference,
                                   ("reference_rmse", "reference_off", "order_violations")),),
    bench_suites=(BenchSuite("shellvolume", "Table 1, sorting, ordering, depth peeling, "
                             "GPU vs CPU reference and filtering of the semi-transparent 3D "
                             "textures paper", _bench),),
    demo_tiles=_demo_tiles,
    programs=render.PROGRAMS,
    samples=_samples,
    cli_examples={
        "bake": ["reliefkit bake demo:sphere --as shell-volume --texture fur --thickness 0.15 "
                 "--tile 4,2 -o fur.rk",
                 "reliefkit bake model.obj --as shell-volume --texture clouds.npy "
                 "--thickness 0.02 -o clouds.rk"],
        "compare": ["reliefkit compare demo:sphere --as shell-volume --texture clouds "
                    "--thickness 0.15 --out cmp"],
        "render": ["reliefkit render fur.rk --samples 16 --shadows -o fur.png",
                   "reliefkit render fur.rk --sort centroid --unlit --aovs f.npz -o fur.png",
                   "reliefkit render fur.rk --animate 24 -o fur.gif"],
    },
)

__all__ = ["TECHNIQUE", "TEXTURES", "ShellVolume", "TexturedShell", "VolumeTexture",
           "build_shell", "visibility_order"]


def __getattr__(name: str):
    """`visibility_order` is imported on first use: it loads numba, which declaring the
    technique (the command line's help) does not need."""
    if name == "visibility_order":
        from .order import visibility_order

        return visibility_order
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
