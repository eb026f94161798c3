"""The technique registry: one `Technique` record per technique, found by kind, class or name.

The core never imports a technique: the composition root (`reliefkit.builtins`) puts the
core's own kind and drawable and every technique of ``reliefkit.techniques.TECHNIQUES`` into
`REGISTRY`, once. Everything generic (the CLI, `bake`, `render`, `compare`, `bench`, the
demo) asks this registry what exists; the .rk reader and the shader loader are handed the
tables derived from it. Duplicates (a kind, a class, a baker or bench name, a shader
namespace) are refused.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field

from ..errors import UsageError
from ..io.rk import Codec, CodecTable
from .params import Option, options_of

__all__ = [
    "Baker", "BenchSuite", "CompareMetric", "CompareVariant", "DemoTile", "DrawableSpec",
    "ProgramVariant", "REGISTRY", "Registry", "Sizing", "Technique", "register", "unregister",
    "techniques", "technique", "technique_of", "baker", "bakers", "drawable_spec",
]

#: The core's shader namespace and the package whose ``shaders/`` folder it is.
CORE_NAMESPACE, CORE_PACKAGE = "core", "reliefkit"


@dataclass(frozen=True)
class Sizing:
    """How `reliefkit shootout` sizes a baker's representation of a whole mesh to a byte budget.

    ``params(n, mesh)`` are the bake parameters at resolution ``n``, an integer in [``lo``,
    ``hi``] whose files grow with it; ``knob`` says in words what ``n`` is (for the report);
    ``label`` names the row (the baker's name when empty: a baker with several variants
    declares one `Sizing` each); ``needs_uvs``: only for meshes with texture coordinates;
    ``render``: the render options it is drawn with (none: its defaults).
    """

    knob: str
    lo: int
    hi: int
    params: Callable
    label: str = ""
    needs_uvs: bool = False
    render: dict | None = None


@dataclass(frozen=True)
class Baker:
    """Bakes a source into a representation; ``--as NAME`` on the command line.

    ``params`` is a dataclass whose fields (made with `reliefkit.core.params.param`) are the
    baker's typed options; the CLI derives flags, defaults and help from it. ``bake(source,
    params, progress)`` gets a validated instance. ``sources`` names what it accepts:
    ``"mesh"`` (a RenderMesh) and/or ``"heightmap"`` (a 2D height array). ``sizings``: how
    the shootout sizes it to a budget (none: it does not stand in for a whole mesh).
    """

    name: str
    summary: str
    params: type
    bake: Callable
    sources: tuple[str, ...] = ("mesh",)
    sizings: tuple[Sizing, ...] = ()

    @property
    def options(self) -> tuple[Option, ...]:
        return options_of(self.params)


@dataclass(frozen=True)
class DrawableSpec:
    """How to draw instances of ``cls``: ``factory(obj, options, instrument)``, no GL.

    ``options`` is the dataclass of its render options (or None); ``factory`` gets an
    instance. ``instrument`` asks for the iteration-counting variant (the core reads the
    counters back, see `reliefkit.gl.targets`). The drawable returned has ``plans`` (its
    `render.plan.DrawPlan` list, which the executor draws), optionally
    ``extra_attachments`` (int), ``counts_iterations`` (False: its instrumented variant
    counts fragments, no loop iterations), ``sort_distance(camera)`` (transparent drawables),
    ``finish(frame, stats)`` (``stats``: its view hooks' for that frame) and ``timed``
    (True: ``stats`` also has the wall time of its draw calls, ``draw_seconds``).
    """

    cls: type
    factory: Callable
    options: type | None = None

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
    (``bench NAME --mesh FILE``): ``run(quick, out, log, mesh=FILE)``. ``options`` names the
    bench command's other options it takes (``size``, ``browser``), given as keywords.
    """

    name: str
    summary: str
    run: Callable
    takes_mesh: bool = False
    options: tuple[str, ...] = ()


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


class Registry:
    """What this process knows: the core's own kinds and drawables, and every technique.

    The tables the layers below look things up in are derived from it, never kept beside
    it: `codecs` (the .rk kinds, handed to `reliefkit.io.rk`), `shader_namespaces` (handed
    to `reliefkit.gl.shaders`) and `drawable_spec`. The composition root
    (`reliefkit.builtins`) fills the one instance, `REGISTRY`; tests plug a toy technique
    in and out with `register` / `unregister`.
    """

    def __init__(self) -> None:
        self._lock = threading.RLock()
        self._techniques: dict[str, Technique] = {}
        self._core_codecs: tuple[Codec, ...] = ()
        self._core_drawables: tuple[DrawableSpec, ...] = ()
        self._codecs = CodecTable()

    def add_core(self, *, codecs: Iterable[Codec] = (), drawables: Iterable[DrawableSpec] = ()):
        """The core's own kinds (``mesh``) and drawables (the ground-truth mesh)."""
        with self._lock:
            specs = (*self._core_drawables, *drawables)
            if len({s.cls for s in specs}) < len(specs):
                raise UsageError("a core drawable is registered twice for one class")
            core_codecs = (*self._core_codecs, *codecs)
            self._codecs = _kinds(core_codecs, self._techniques.values())
            self._core_codecs = core_codecs
            self._core_drawables = specs

    def register(self, tech: Technique) -> None:
        """Add a technique; refuses anything that another technique already claims."""
        if not isinstance(tech, Technique):
            raise UsageError(f"register() needs a Technique, got {type(tech).__name__}")
        with self._lock:
            if tech.name in self._techniques or tech.name == CORE_NAMESPACE:
                raise UsageError(f"technique {tech.name!r} is already registered")
            self._refuse_duplicates(tech)
            self._codecs = _kinds(self._core_codecs, (*self._techniques.values(), tech))
            self._techniques[tech.name] = tech

    def unregister(self, name: str) -> None:
        """Remove a technique and its kinds (for tests that plug in a toy technique)."""
        with self._lock:
            if self._techniques.pop(name, None) is not None:
                self._codecs = _kinds(self._core_codecs, self._techniques.values())

    def techniques(self) -> tuple[Technique, ...]:
        return tuple(self._techniques.values())

    def codecs(self) -> CodecTable:
        """Every .rk kind: the core's and the techniques' (what `reliefkit.io.rk` reads);
        derived again whenever a technique comes or goes."""
        return self._codecs

    def shader_namespaces(self) -> dict[str, str]:
        """Shader namespace -> the package whose ``shaders/`` folder it is."""
        return {CORE_NAMESPACE: CORE_PACKAGE,
                **{t.name: t.package for t in self._techniques.values()}}

    def drawable_spec(self, obj) -> tuple[Technique | None, DrawableSpec | None]:
        """(technique, spec) drawing ``obj``; the core's own drawables have technique None."""
        for spec in self._core_drawables:
            if isinstance(obj, spec.cls):
                return None, spec
        return self._owner(obj, "drawables")

    def technique_of(self, obj) -> Technique | None:
        """The technique whose representation ``obj`` is (None for meshes, unknown objects)."""
        return self._owner(obj, "representations")[0]

    def core_drawables(self) -> tuple[DrawableSpec, ...]:
        return self._core_drawables

    def drawable_specs(self) -> tuple[DrawableSpec, ...]:
        """Every drawable: the core's first, then the techniques'."""
        return (*self._core_drawables, *(d for t in self._techniques.values()
                                         for d in t.drawables))

    def _owner(self, obj, attr: str):
        for tech in self._techniques.values():
            for spec in getattr(tech, attr):
                cls = spec if isinstance(spec, type) else spec.cls
                if isinstance(obj, cls):
                    return tech, spec
        return None, None

    def _refuse_duplicates(self, tech: Technique) -> None:
        others = self._techniques.values()
        taken = {
            "kind": set(self._codecs.kinds),
            "baker": {b.name for t in others for b in t.bakers},
            "bench suite": {s.name for t in others for s in t.bench_suites},
            "representation class": {c for t in others for c in t.representations},
            "drawable class": {d.cls for t in others for d in t.drawables},
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
        self._check_shared_flags(tech)

    def _check_shared_flags(self, tech: Technique) -> None:
        """Two bakers (of any techniques) may share a flag only if it parses the same way."""
        seen: dict[str, Option] = {}
        for other in (*self._techniques.values(), tech):
            for b in other.bakers:
                for opt in b.options:
                    first = seen.setdefault(opt.name, opt)
                    if first.kind != opt.kind:
                        raise UsageError(f"bake option --{opt.flag} is a {opt.kind} for baker "
                                         f"{b.name!r} but a {first.kind} elsewhere; rename one")


def _kinds(core_codecs, techniques) -> CodecTable:
    """The codec table of the core's kinds and the techniques' (conflicts refused)."""
    return CodecTable((*core_codecs, *(c for t in techniques for c in t.codecs)))


#: The one registry; `reliefkit.builtins.registry()` fills it with the built-ins.
REGISTRY = Registry()


def register(tech: Technique) -> None:
    """Add a technique to `REGISTRY` (see `Registry.register`)."""
    REGISTRY.register(tech)


def unregister(name: str) -> None:
    """Remove a technique from `REGISTRY` (see `Registry.unregister`)."""
    REGISTRY.unregister(name)


def techniques() -> tuple[Technique, ...]:
    return REGISTRY.techniques()


def technique(name: str) -> Technique:
    table = {t.name: t for t in REGISTRY.techniques()}
    if name not in table:
        raise UsageError(f"unknown technique {name!r} (known: {', '.join(table)})")
    return table[name]


def technique_of(obj) -> Technique | None:
    """The technique whose representation ``obj`` is (None for meshes and unknown objects)."""
    return REGISTRY.technique_of(obj)


def drawable_spec(obj) -> tuple[Technique | None, DrawableSpec | None]:
    """(technique, spec) drawing ``obj``; the core's own drawables have technique None."""
    return REGISTRY.drawable_spec(obj)


def bakers() -> dict[str, tuple[Technique, Baker]]:
    """Every baker by its ``--as`` name, in registration order."""
    return {b.name: (t, b) for t in REGISTRY.techniques() for b in t.bakers}


def baker(name: str) -> tuple[Technique, Baker]:
    table = bakers()
    if name not in table:
        raise UsageError(f"unknown representation {name!r} (choose from "
                         f"{', '.join(table) or 'none'})")
    return table[name]

