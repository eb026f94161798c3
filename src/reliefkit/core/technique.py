"""The technique registry: one `Technique` record per technique, found by kind, class or name.

The core never imports a technique; `load_all()` imports `reliefkit.techniques`, whose
``TECHNIQUES`` tuple lists them, and registers each record once. Everything generic (the CLI,
`bake`, `render`, `compare`, `bench`, the demo, the .rk reader) asks this registry what exists.
Duplicates (a kind, a class, a baker or bench name, a shader namespace) are refused.
"""

from __future__ import annotations

import importlib
import threading
from collections.abc import Callable
from dataclasses import dataclass, field

from ..errors import UsageError
from .params import Option, options_of

__all__ = [
    "Baker", "BenchSuite", "CompareMetric", "CompareVariant", "DemoTile", "DrawableSpec",
    "ProgramVariant", "Technique", "register", "unregister", "load_all", "techniques",
    "technique", "technique_of", "baker", "bakers", "drawable_spec", "bench_suite",
    "bench_suites", "registered_kinds",
]


@dataclass(frozen=True)
class Baker:
    """Bakes a source into a representation; ``--as NAME`` on the command line.

    ``params`` is a dataclass whose fields (made with `reliefkit.core.params.param`) are the
    baker's typed options; the CLI derives flags, defaults and help from it. ``bake(source,
    params, progress)`` gets a validated instance. ``sources`` names what it accepts:
    ``"mesh"`` (a RenderMesh) and/or ``"heightmap"`` (a 2D height array).
    """

    name: str
    summary: str
    params: type
    bake: Callable
    sources: tuple[str, ...] = ("mesh",)

    @property
    def options(self) -> tuple[Option, ...]:
        return options_of(self.params)


@dataclass(frozen=True)
class DrawableSpec:
    """How to draw instances of ``cls``: ``factory(ctx, obj, options, instrument)``.

    ``options`` is the dataclass of its render options (or None); ``factory`` gets an
    instance. ``instrument`` asks for the iteration-counting variant (the core reads the
    counters back, see `reliefkit.gl.targets`). The drawable returned has ``draw(camera,
    light)``, optionally ``finish(frame)``, ``release()``, ``transparent`` (bool) and
    ``extra_attachments`` (int).
    """

    cls: type
    factory: Callable
    options: type | None = None
    #: the factory takes ``(obj, options, instrument)``, no context, and returns a drawable
    #: whose ``plans`` (`render.plan.DrawPlan`) the executor draws, with optionally
    #: ``finish(frame, stats)``, ``sort_distance(camera)`` and ``extra_attachments``
    planned: bool = False

    @property
    def option_list(self) -> tuple[Option, ...]:
        return options_of(self.options) if self.options is not None else ()


@dataclass(frozen=True)
class CompareVariant:
    """One rendering of a representation beside the mesh in `compare` (a method, a mode).

    ``options`` are render options; the variant is skipped when ``available(rep)`` is False.
    ``derive(rep, mesh)``, when given, makes what is drawn from the compared representation
    and its mesh (the flat billboard cloud inside a DMBBC, the other DMBBC variants baked
    with the same parameters), so one comparison covers a family of representations.
    """

    name: str
    options: dict = field(default_factory=dict)
    available: Callable[[object], bool] = lambda rep: True
    derive: Callable[[object, object], object] | None = None


@dataclass(frozen=True)
class CompareMetric:
    """An extra metric of a technique: ``measure(frame, rep, camera) -> (scores, error_mask)``.

    ``scores`` is a dict of JSON numbers (merged into the variant's row; ``columns`` name the
    ones shown in the table); ``error_mask`` (H, W) bool or None is drawn red in the sheet.
    With ``against_mesh`` it is called ``measure(frame, rep, camera, mesh_frame)``: the
    mesh's own Frame from the same camera is its reference.
    """

    name: str
    measure: Callable
    columns: tuple[str, ...] = ()
    against_mesh: bool = False


@dataclass(frozen=True)
class BenchSuite:
    """``reliefkit bench NAME``: ``run(quick, out, log) -> (markdown, written paths)``.

    A suite with ``takes_mesh`` also runs on a user's mesh instead of its built-in assets
    (``bench NAME --mesh FILE``): ``run(quick, out, log, mesh=FILE)``.
    """

    name: str
    summary: str
    run: Callable
    takes_mesh: bool = False


@dataclass(frozen=True)
class DemoTile:
    """One picture of the demo sheet: ``make()`` returns what to render; ``view`` is AZ,EL,DIST.

    ``options`` are render options, plus ``light`` for a `DirectionalLight`.
    """

    title: str
    slug: str
    make: Callable[[], object]
    view: tuple = (35.0, 30.0, 2.4)  # AZ, EL, DIST (DIST None: fit the bounding sphere)
    options: dict | None = None


@dataclass(frozen=True)
class ProgramVariant:
    """A draw-path shader program and one set of defines (compiled by the portability test)."""

    file: str
    defines: dict = field(default_factory=dict)


@dataclass(frozen=True)
class Technique:
    """Everything one technique contributes; its package's ``__init__`` exports one of these.

    ``package`` is the technique's Python package (``__name__`` of its ``__init__``); its
    ``shaders/`` folder becomes the shader namespace ``name`` (``"relief:relief.glsl"``).
    ``samples()`` returns one small representation per kind, which the contract tests
    (tests/contracts/) round-trip, forge and render; ``programs`` are the draw-path shader
    variants the portability test compiles as GLSL ES.
    """

    name: str
    summary: str
    package: str
    codecs: tuple = ()
    representations: tuple[type, ...] = ()
    bakers: tuple[Baker, ...] = ()
    drawables: tuple[DrawableSpec, ...] = ()
    compare_variants: tuple[CompareVariant, ...] = ()
    compare_metrics: tuple[CompareMetric, ...] = ()
    bench_suites: tuple[BenchSuite, ...] = ()
    demo_tiles: Callable[[], list[DemoTile]] | None = None
    programs: tuple[ProgramVariant, ...] = ()
    samples: Callable[[], dict] | None = None  # kind -> a small representation (contract tests)
    cli_examples: dict = field(default_factory=dict)  # CLI command -> example lines for --help

    @property
    def kinds(self) -> tuple[str, ...]:
        return tuple(codec.kind for codec in self.codecs)


_lock = threading.RLock()
_techniques: dict[str, Technique] = {}
_loaded = False


def register(tech: Technique) -> None:
    """Add a technique; refuses anything that another technique already claims."""
    from ..gl.shaders import register_namespace
    from ..io import rk

    if not isinstance(tech, Technique):
        raise UsageError(f"register() needs a Technique, got {type(tech).__name__}")
    with _lock:
        if tech.name in _techniques or tech.name == "core":
            raise UsageError(f"technique {tech.name!r} is already registered")
        _refuse_duplicates(tech)
        for codec in tech.codecs:
            rk.register(codec)
        register_namespace(tech.name, tech.package)
        _techniques[tech.name] = tech


def _refuse_duplicates(tech: Technique) -> None:
    from ..io import rk

    taken = {
        "kind": set(rk.registered_kinds(load=False)),
        "baker": {b.name for t in _techniques.values() for b in t.bakers},
        "bench suite": {s.name for t in _techniques.values() for s in t.bench_suites},
        "representation class": {c for t in _techniques.values() for c in t.representations},
        "drawable class": {d.cls for t in _techniques.values() for d in t.drawables},
    }
    mine = {
        "kind": [c.kind for c in tech.codecs],
        "baker": [b.name for b in tech.bakers],
        "bench suite": [s.name for s in tech.bench_suites],
        "representation class": list(tech.representations),
        "drawable class": [d.cls for d in tech.drawables],
    }
    for what, names in mine.items():
        for name in names:
            label = getattr(name, "__qualname__", name)
            if name in taken[what]:
                raise UsageError(f"technique {tech.name!r}: {what} {label!r} is already "
                                 "registered by another technique")
            if names.count(name) > 1:
                raise UsageError(f"technique {tech.name!r} declares {what} {label!r} twice")
    for spec in tech.drawables:
        spec.option_list  # noqa: B018 - validates the option dataclass now, not at render time
    for b in tech.bakers:
        b.options  # noqa: B018
    _check_shared_flags(tech)


def _check_shared_flags(tech: Technique) -> None:
    """Two bakers (of any techniques) may share a flag only if it parses the same way."""
    seen: dict[str, Option] = {}
    for other in (*_techniques.values(), tech):
        for b in other.bakers:
            for opt in b.options:
                first = seen.setdefault(opt.name, opt)
                if first.kind != opt.kind:
                    raise UsageError(f"bake option --{opt.flag} is a {opt.kind} for baker "
                                     f"{b.name!r} but a {first.kind} elsewhere; rename one")


def unregister(name: str) -> None:
    """Remove a technique and its kinds (for tests that plug in a toy technique)."""
    from ..gl.shaders import unregister_namespace
    from ..io import rk

    with _lock:
        tech = _techniques.pop(name, None)
        if tech is not None:
            for codec in tech.codecs:
                rk.unregister(codec.kind)
            unregister_namespace(name)


def load_all() -> tuple[Technique, ...]:
    """Register every built-in technique (once per process) and return all registered."""
    global _loaded
    with _lock:
        if not _loaded:
            _loaded = True
            try:
                builtin = importlib.import_module("reliefkit.techniques").TECHNIQUES
                for tech in builtin:
                    if tech.name not in _techniques:
                        register(tech)
            except BaseException:
                _loaded = False
                raise
        return tuple(_techniques.values())


def techniques() -> tuple[Technique, ...]:
    return load_all()


def technique(name: str) -> Technique:
    load_all()
    if name not in _techniques:
        raise UsageError(f"unknown technique {name!r} (known: {', '.join(_techniques)})")
    return _techniques[name]


def _owner(obj, attr: str):
    for tech in load_all():
        for spec in getattr(tech, attr):
            cls = spec if isinstance(spec, type) else spec.cls
            if isinstance(obj, cls):
                return tech, spec
    return None, None


def technique_of(obj) -> Technique | None:
    """The technique whose representation ``obj`` is (None for meshes and unknown objects)."""
    return _owner(obj, "representations")[0]


def drawable_spec(obj) -> tuple[Technique | None, DrawableSpec | None]:
    """(technique, spec) drawing ``obj``; the core's own drawables have technique None."""
    from ..render.registry import core_drawables

    for spec in core_drawables():
        if isinstance(obj, spec.cls):
            return None, spec
    return _owner(obj, "drawables")


def bakers() -> dict[str, tuple[Technique, Baker]]:
    """Every baker by its ``--as`` name, in registration order."""
    return {b.name: (t, b) for t in load_all() for b in t.bakers}


def baker(name: str) -> tuple[Technique, Baker]:
    table = bakers()
    if name not in table:
        raise UsageError(f"unknown representation {name!r} (choose from "
                         f"{', '.join(table) or 'none'})")
    return table[name]


def bench_suites() -> dict[str, tuple[Technique, BenchSuite]]:
    return {s.name: (t, s) for t in load_all() for s in t.bench_suites}


def bench_suite(name: str) -> BenchSuite:
    table = bench_suites()
    if name not in table:
        raise UsageError(f"unknown benchmark {name!r} (choose from {', '.join(table)})")
    return table[name][1]


def registered_kinds() -> tuple[str, ...]:
    """Every .rk kind this process reads and writes (built-in techniques loaded first)."""
    from ..io import rk

    return rk.registered_kinds()
