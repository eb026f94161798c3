"""Benchmarks: ``reliefkit bench NAME`` runs a suite registered by a technique, or one of the
core's own (`loading`: the memory of loading meshes; `platform`: multi-view rendering;
`compact`: compressed textures' bytes and error; `scene`: instancing; `export`: glTF
exports' bytes, time and fallbacks; `viewer`: the viewer page's frame time per kind in
headless Chromium; `batch`: assets per hour of `reliefkit batch`, local
and on Ray).

Suites measure side by side in one run (ratios) and report device-independent counts;
`timing` has the shared frame-timing helper. Techniques' suites use `report` and `timing`,
so this package sits below the composition root: its caller (the CLI) fills the registry.
"""

from __future__ import annotations

from pathlib import Path

from ..core.technique import REGISTRY, BenchSuite
from ..errors import UsageError
from ..progress import activity
from . import batch, compact, export, loading, platform, scene, viewer


def run_suite(name: str, *, quick: bool = False, out: Path = Path("out/bench"),
              log=None, mesh: str | None = None, **options) -> tuple[str, list[Path]]:
    """Run the suite ``name``; returns its markdown report and the files it wrote.

    ``mesh`` (a mesh file) replaces the built-in assets of a suite that ``takes_mesh``;
    ``options`` (None: not given) go to a suite that names them in its ``options``.
    Without ``log`` the suite's step messages are its progress (`reliefkit.progress.activity`:
    ``bench NAME: ...`` lines on stderr, a spinner on a terminal).
    """
    table = suites()
    if name not in table:
        raise UsageError(f"unknown benchmark {name!r} (choose from {', '.join(table)})")
    suite = table[name]
    kwargs = {}
    if mesh is not None:
        if not suite.takes_mesh:
            takers = ", ".join(n for n, s in table.items() if s.takes_mesh) or "none"
            raise UsageError(f"bench {name} runs on its own assets only: --mesh applies to "
                             f"{takers}")
        kwargs["mesh"] = str(mesh)
    for key, value in options.items():
        if value is None:
            continue
        if key not in suite.options:
            takers = ", ".join(n for n, s in table.items() if key in s.options) or "none"
            raise UsageError(f"bench {name} takes no --{key}: it applies to {takers}")
        kwargs[key] = value
    if log is not None:
        return suite.run(quick, Path(out), log, **kwargs)
    with activity(f"bench {name}") as progress_log:
        return suite.run(quick, Path(out), progress_log, **kwargs)


def suites() -> dict:
    """Every suite by name: the core's, then each technique's (`core.technique.BenchSuite`)."""
    core = {"loading": BenchSuite("loading", "memory of loading meshes, x the file's size",
                                  loading.run_suite, takes_mesh=True),
            "platform": BenchSuite("platform", "a turntable in one render call against one "
                                   "call per view, per demo tile", platform.run_suite),
            "compact": BenchSuite("compact", "bytes and image error of compressed textures, "
                                  "per demo asset and kind", compact.run_suite),
            "scene": BenchSuite("scene", "1,000 and 10,000 instances of one asset, each "
                                "representation against the mesh decimated to equal error",
                                scene.run_suite, takes_mesh=True),
            "export": BenchSuite("export", "glTF export per demo asset and kind: .rk against "
                                 ".glb bytes, export time, the fallback's triangles and "
                                 "coverage against the mesh", export.run_suite),
            "viewer": BenchSuite("viewer", "the viewer page's frame time per kind in headless "
                                 "Chromium against the mesh's, with its draw calls and texture "
                                 "bytes", viewer.run_suite, options=("size", "browser")),
            "batch": BenchSuite("batch", "assets per hour of reliefkit batch on 10k-triangle "
                                "meshes, local and Ray, 1 and 2 workers; Ray's overhead",
                                batch.run_suite)}
    return core | {s.name: s for t in REGISTRY.techniques() for s in t.bench_suites}


def suite_names() -> tuple[str, ...]:
    return tuple(suites())
