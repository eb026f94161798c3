"""The `reliefkit` command line: parses arguments, calls the library, prints results.

Every failure is one line ``error: ...`` on stderr and a non-zero exit status: 2 for a usage
error (argparse's or a `UsageError`), 1 for bad input (a mesh, an .rk file, the GPU), 3 for
an internal error (docs/cli.md).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import os
import signal
import sys
import warnings
from pathlib import Path

from .errors import FormatError, ReliefkitError, UsageError
from .scene.light import DEFAULT_LIGHT_ANGLES
from .scene.views import DEFAULT_SIZE, DEFAULT_VIEW

EXIT_INPUT, EXIT_USAGE, EXIT_INTERNAL = 1, 2, 3
EXIT_BROKEN_PIPE = 141  # what a shell reports for a process stopped by SIGPIPE
EXIT_TERMINATED = 143   # what a shell reports for a process stopped by SIGTERM
MAX_OPTION_MAGNITUDE = 1e18  # no numeric option takes a value larger than this
MSAA_CHOICES = (1, 2, 4, 8)

CORE_EXAMPLES = {
    "demo": ["reliefkit demo --out out                          contact sheet of every demo"],
    "render": ["reliefkit render bunny.ply -o bunny.png           one view (default --view "
               "30,25)",
               "reliefkit render car.glb --view 90,10,2 --size 800x600 -o side.png --aovs "
               "side.npz",
               "reliefkit render demo:tree --turntable 36 -o spin.gif"],
    "info": ["reliefkit info --gl                               the OpenGL renderer and its "
             "limits",
             "reliefkit info model.obj                          counts and bounds of a mesh "
             "(or an .rk)"],
}
ORDER = ("demo", "render", "bake", "compare", "bench", "info")


def _examples(command: str | None = None) -> list[str]:
    """Example lines: the core's and every technique's, for one command or all in order."""
    from .core.technique import techniques

    table = {name: list(lines) for name, lines in CORE_EXAMPLES.items()}
    for tech in techniques():
        for name, lines in tech.cli_examples.items():
            table.setdefault(name, []).extend(lines)
    names = [command] if command else [n for n in ORDER if n in table]
    return [line for name in names for line in table.get(name, [])]


def _epilog() -> str:
    from .core.technique import bakers

    heightmap_kinds = [name for name, (_, b) in bakers().items() if "heightmap" in b.sources]
    lines = ["examples:", *(f"  {line}" for line in _examples()), "",
             "inputs: a mesh file (.obj .ply .stl .off .gltf .glb), an .rk file, demo:NAME",
             "(demo assets: terrain, blob, tree, vehicle)"]
    if heightmap_kinds:
        lines[-1] += (f", or for `bake --as {'/'.join(heightmap_kinds)}` a heightmap")
        lines.append("(8/16-bit greyscale .png or a 2D .npy array)")
    return "\n".join(lines) + ".\n"


class _Parser(argparse.ArgumentParser):
    """argparse that reports errors as one `error:` line (exit status 2), and lets the flags
    in ``dash_values`` take a value that starts with '-' (``--axis -y``, ``--view -30,20``),
    which argparse alone would read as another option."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.dash_values: set[str] = set()

    def error(self, message: str):  # noqa: D102
        self.exit(EXIT_USAGE, f"error: {message} (see {self.prog} --help)\n")

    def parse_known_args(self, args=None, namespace=None):  # noqa: D102
        args = list(sys.argv[1:] if args is None else args)
        return super().parse_known_args(self._join_dash_values(args), namespace)

    def _join_dash_values(self, args: list[str]) -> list[str]:
        """``--flag -value`` -> ``--flag=-value`` for those flags, unless -value is an option."""
        out, k = [], 0
        while k < len(args):
            arg = args[k]
            following = args[k + 1] if k + 1 < len(args) else None
            if (arg in self.dash_values and following is not None and following.startswith("-")
                    and following not in self._option_string_actions):
                out.append(f"{arg}={following}")
                k += 2
            else:
                out.append(arg)
                k += 1
            if arg == "--":
                return out + args[k:]
        return out


def _add_flag(parser: _Parser, *args, within=None, dash_value: bool = False, **kwargs):
    """``add_argument`` (to ``within``, a group of ``parser``, if given); with ``dash_value``
    the flag's value may start with '-' (see `_Parser`)."""
    action = (within or parser).add_argument(*args, **kwargs)
    if dash_value:
        parser.dash_values.update(s for s in action.option_strings if s.startswith("--"))
    return action


def _add_view_args(p: _Parser) -> None:
    """--view, --size, --fov and --light: the camera and light of every render."""
    _add_flag(p, "--view", dash_value=True, metavar="AZ,EL[,DIST]",
              default=",".join(f"{x:g}" for x in DEFAULT_VIEW[:2]),
              help="orbit the bounding-box centre (of the source mesh for a baked .rk): "
                   "azimuth about +y from +z towards +x and elevation in degrees, distance in "
                   "bounding-sphere radii, within [0.01, 10000] (default: %(default)s, at the "
                   "distance that fits the sphere in view)")
    p.add_argument("--size", default="x".join(map(str, DEFAULT_SIZE)), metavar="WxH",
                   help="image size in pixels (default: %(default)s)")
    _add_flag(p, "--fov", dash_value=True, type=float, default=40.0, metavar="DEG",
              help="vertical field of view in degrees, within [0.1, 179] (default: "
                   "%(default)g)")
    _add_flag(p, "--light", dash_value=True, metavar="AZ,EL",
              default=",".join(f"{x:g}" for x in DEFAULT_LIGHT_ANGLES),
              help="where the light comes from: azimuth and elevation in degrees, as in "
                   "--view (default: %(default)s, a low sun from the side)")


def _command(sub, name: str, summary: str, description: str):
    """A subcommand parser whose --help ends with its examples."""
    epilog = "examples:\n" + "\n".join(f"  {line}" for line in _examples(name))
    return sub.add_parser(name, help=summary, description=description, epilog=epilog,
                          formatter_class=argparse.RawDescriptionHelpFormatter)


def build_parser() -> argparse.ArgumentParser:
    from .bench import suite_names
    from .core.technique import bakers, bench_suites, techniques

    parser = _Parser(prog="reliefkit", description="Render geometry from textures with depth.",
                     epilog=_epilog(), formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version", version=_version())
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    table = bakers()

    p = _command(sub, "render", "render a mesh or an .rk representation to PNG / GIF",
                 "Render a mesh (ground truth) or an .rk representation.")
    p.add_argument("input", help="mesh file, .rk file or demo:NAME")
    _add_view_args(p)
    p.add_argument("-o", "--output", required=True, help="output .png (or .gif with --turntable)")
    p.add_argument("--aovs", metavar="OUT.npz",
                   help="also write color, mask, depth, position, normal, view, proj, viewport")
    p.add_argument("--stats", metavar="OUT.json",
                   help="also write the frame's counters: covered pixels, fragments and loop "
                        "iterations per pixel (mean, max) where the renderer counts them")
    p.add_argument("--turntable", type=int, metavar="N", help="N views around the object (GIF)")
    _add_flag(p, "--background", dash_value=True, default="transparent",
              metavar="transparent|LEVEL",
              help="'transparent' or a grey level 0..1 to composite over (default: "
                   "%(default)s)")
    p.add_argument("--msaa", type=int, default=1, choices=MSAA_CHOICES, metavar="N",
                   help="samples per pixel for the colour (1, 2, 4 or 8, up to the GPU's "
                        "GL_MAX_SAMPLES); the AOVs stay single-sample (default: %(default)s)")
    _add_options(p, [(t.name, spec.option_list) for t in techniques() for spec in t.drawables],
                 "render options")
    p.set_defaults(run=cmd_render)

    p = _command(sub, "bake", "bake a mesh or heightmap into an .rk representation",
                 "Bake a mesh (or a heightmap) into a representation. Representations: "
                 + "; ".join(f"{name}: {b.summary}" for name, (_, b) in table.items()) + ".")
    _add_bake_args(p, table)
    p.add_argument("-o", "--output", required=True, help="output .rk file")
    p.set_defaults(run=cmd_bake)

    p = _command(sub, "compare", "bake, then render the mesh and every variant side by side",
                 "Bake INPUT, render the mesh and each variant of the representation (its "
                 "methods or modes) from one view; write compare.png, metrics.md, metrics.json.")
    _add_bake_args(p, table, "mesh file or demo:NAME (not a heightmap: there is no mesh to "
                             "compare against)")
    _add_view_args(p)
    p.add_argument("--out", default="out/compare", help="output folder (default: %(default)s)")
    p.set_defaults(run=cmd_compare)

    names = suite_names()
    p = _command(sub, "bench", "reproduce a paper's tables (speed, iterations, errors)",
                 "Benchmarks measured side by side in one run: "
                 + "; ".join(f"{n}: {s.summary}" for n, (_, s) in bench_suites().items()) + ".")
    p.add_argument("name", choices=names, help="which benchmark")
    p.add_argument("--quick", action="store_true", help="small sizes (a smoke run)")
    p.add_argument("--out", default="out/bench", help="folder for .md and .json results")
    p.set_defaults(run=cmd_bench)

    p = _command(sub, "info", "GL capabilities, or the contents of a mesh / .rk file",
                 "Print the OpenGL renderer and limits (--gl) and/or summarise a mesh or .rk "
                 "file.")
    p.add_argument("file", nargs="?", help="mesh file, .rk file or demo:NAME")
    p.add_argument("--gl", action="store_true", help="print renderer, GL version and limits")
    p.add_argument("--json", action="store_true", help="print JSON instead of text")
    p.set_defaults(run=cmd_info)

    p = _command(sub, "demo", "render the demo assets into a titled contact sheet",
                 "Render every demo asset (and representation) into OUT/demo.png plus one "
                 "PNG per tile.")
    p.add_argument("--out", default="out", help="output folder (default: %(default)s)")
    p.add_argument("--size", default="256x256", metavar="WxH", help="tile size")
    p.set_defaults(run=cmd_demo)
    return parser


OPTION_PREFIX = "opt_"  # argparse dest of a declared option (kept apart from the command's own)


def _add_options(p: argparse.ArgumentParser, owners: list[tuple[str, tuple]], title: str):
    """One flag per declared option name, whoever declares it; defaults stay the owners'.

    The flag's value is checked later by the declaration of whatever the input turns out to
    be, so two techniques may both declare ``method`` with different choices.
    """
    by_name: dict[str, list] = {}
    for owner, options in owners:
        for opt in options:
            by_name.setdefault(opt.name, []).append((owner, opt))
    group = p.add_argument_group(title)
    for name, decls in by_name.items():
        first = decls[0][1]
        flag = "--" + first.flag
        if all(opt.kind == "bool" for _, opt in decls):
            group.add_argument(flag, dest=OPTION_PREFIX + name, default=None,
                               action=argparse.BooleanOptionalAction, help=_option_help(decls))
            continue
        metavar = "|".join(map(str, first.choices)) if first.choices else (
            ",".join(["X"] * (first.count or 2)) if first.kind == "floats" else first.kind.upper())
        _add_flag(p, flag, within=group, dest=OPTION_PREFIX + name, default=None,
                  metavar=metavar, help=_option_help(decls),
                  dash_value=any(_takes_dash(opt) for _, opt in decls))


def _takes_dash(opt) -> bool:
    """Whether a value of ``opt`` may start with '-': a number, or a choice such as '-y'."""
    if opt.choices:
        return any(str(choice).startswith("-") for choice in opt.choices)
    return opt.kind in ("int", "float", "floats")


def _option_help(decls: list) -> str:
    """One help text for an option that several owners declare: owners sharing a text or a
    default are listed together."""
    from .core.params import describe_default

    texts: dict[str, list[str]] = {}
    defaults: dict[str, list[str]] = {}
    for owner, opt in decls:
        texts.setdefault(opt.help, []).append(owner)
        defaults.setdefault(describe_default(opt), []).append(owner)
    single = len(texts) == 1
    parts = [text if single else f"{', '.join(owners)}: {text}" for text, owners in texts.items()]
    owners_all = ", ".join(dict.fromkeys(o for o, _ in decls))
    if len(defaults) == 1:
        tail = f"default {next(iter(defaults))}"
    else:
        tail = "default " + ", ".join(f"{d} ({', '.join(o)})" for d, o in defaults.items())
    return (f"[{owners_all}] " if single else "") + "; ".join(parts).replace("%", "%%") + \
        f"; {tail}"


def _given_options(args) -> dict:
    """The declared options the user gave (the rest keep their declared defaults)."""
    return {key[len(OPTION_PREFIX):]: value for key, value in vars(args).items()
            if key.startswith(OPTION_PREFIX) and value is not None}


def _applicable(given: dict, options, what: str) -> dict:
    """``given`` restricted to ``options`` and checked by their declarations; a flag that
    does not apply, or a bad value, is a UsageError naming the flag as the user typed it."""
    by_name = {opt.name: opt for opt in options}
    wrong = [k for k in given if k not in by_name]
    if wrong:
        flags = ", ".join("--" + k.replace("_", "-") for k in wrong)
        has = ", ".join("--" + opt.flag for opt in options) or "none"
        raise UsageError(f"{flags} does not apply to {what} (its options: {has})")
    return {name: _checked(by_name[name], value, what) for name, value in given.items()}


def _checked(opt, value, what: str):
    """``opt.check`` with the message saying ``--flag`` (the declaration says ``flag``)."""
    try:
        checked = opt.check(value, what)
    except UsageError as exc:
        message, bare = str(exc), f"{what}: {opt.flag} "
        if message.startswith(bare):
            message = f"--{opt.flag} {message[len(bare):]} ({what})"
        raise UsageError(message) from None
    if opt.kind in ("float", "floats") and checked is not None:
        for v in (checked if opt.kind == "floats" else (checked,)):
            if not (math.isfinite(v) and abs(v) <= MAX_OPTION_MAGNITUDE):
                raise UsageError(f"--{opt.flag} needs finite numbers of magnitude at most "
                                 f"{MAX_OPTION_MAGNITUDE:g}, got {value!r} ({what})")
    return checked


def _add_bake_args(p: argparse.ArgumentParser, table: dict,
                   input_help: str = "mesh file, demo:NAME, or a heightmap (.png/.npy)") -> None:
    p.add_argument("input", help=input_help)
    kinds = tuple(table)
    p.add_argument("--as", dest="kind", default=kinds[0] if kinds else None, choices=kinds,
                   help="representation to bake (default: %(default)s)")
    _add_options(p, [(name, b.options) for name, (_, b) in table.items()], "bake options")


def _check_not_empty(spec: str) -> None:
    """A zero-byte input file is refused as such (before a loader guesses why it fails)."""
    path = Path(spec)
    if path.is_file() and path.stat().st_size == 0:
        raise FormatError(f"{spec}: the file is empty (0 bytes)")


def _bake_source(spec: str, command: str = "bake"):
    """The mesh or heightmap ``bake`` and ``compare`` start from."""
    from .scene.heightmap import is_heightmap, load_heightmap

    _check_not_empty(spec)
    if Path(spec).suffix.lower() == ".rk":
        raise UsageError(f"{command} needs a mesh or heightmap, not an .rk file ({spec})")
    if is_heightmap(spec):
        if command == "compare":
            raise UsageError(f"compare needs a mesh or demo:NAME as INPUT, not a heightmap "
                             f"({spec}): there is no mesh to compare against; bake it with "
                             "`reliefkit bake` and render the .rk instead")
        return load_heightmap(spec)
    return _load(spec)


def _load(spec: str):
    """`load_input`, then each warning the loader left on a mesh as one `warning:` line."""
    from .io.inputs import load_input

    obj = load_input(spec)
    _print_load_warnings(obj)
    return obj


def _print_load_warnings(obj) -> None:
    """The loader's human-readable warnings (``mesh.extra["warnings"]``), one line each."""
    extra = getattr(obj, "extra", None)
    found = extra.get("warnings", ()) if isinstance(extra, dict) else ()
    for text in found if isinstance(found, list | tuple) else ():
        line = " ".join(str(text).split())
        print(f"warning: {line}", file=sys.stderr)


def _bake_input(args, source=None):
    from .bake import bake
    from .core.technique import baker
    from .progress import progress_bar

    _, chosen = baker(args.kind)
    params = _applicable(_given_options(args), chosen.options, f"--as {args.kind}")
    source = _bake_source(args.input) if source is None else source
    with progress_bar(f"baking {args.kind}", 1) as advance:
        return bake(source, args.kind, progress=advance, **params)


def cmd_bake(args) -> int:
    from .io.atomic import check_writable
    from .io.rk import array_bytes, file_sha256, save
    from .units import format_bytes

    if Path(args.output).suffix.lower() != ".rk":
        raise UsageError(f"output must be an .rk file, got {args.output}")
    check_writable(args.output, "-o")
    rep = _bake_input(args)
    source_hash = file_sha256(args.input) if Path(args.input).is_file() else None
    save(args.output, rep, source_hash=source_hash)
    sizes = array_bytes(rep)
    parts = ", ".join(f"{name} {format_bytes(n)}" for name, n in sizes.items())
    print(f"wrote {args.output}: {format_bytes(sum(sizes.values()))} of arrays ({parts}), "
          f"{format_bytes(Path(args.output).stat().st_size)} on disk")
    return 0


def _version() -> str:
    from . import __version__

    return f"reliefkit {__version__}"


def _background(text: str):
    """--background: None (transparent) or a linear grey (level, level, level) in 0..1."""
    if text == "transparent":
        return None
    try:
        level = float(text)
    except ValueError:
        level = float("nan")
    if not 0.0 <= level <= 1.0:
        raise UsageError(f"--background must be 'transparent' or a grey level within [0, 1], "
                         f"got {text!r}")
    return (level, level, level)


def _light(args):
    from .scene.light import DirectionalLight
    from .scene.views import parse_light

    return DirectionalLight.from_angles(*parse_light(args.light))


def _warn_nothing_visible(what: str) -> None:
    """A picture with nothing in it is written, but never silently (exit status 0 still)."""
    print(f"warning: {what} 0 pixels: nothing visible (check --view, --fov and the input's "
          "bounds)", file=sys.stderr)


def cmd_render(args) -> int:
    from .render import render, render_options
    from .scene.views import check_fov, framing_bounds, orbit_bounds, parse_size, parse_view

    az, el, dist = parse_view(args.view)
    size = parse_size(args.size)
    check_fov(args.fov)
    background = _background(args.background)
    light = _light(args)
    _check_render_outputs(args)
    _check_not_empty(args.input)
    obj = _load(args.input)
    options = _applicable(_given_options(args), render_options(obj),
                          f"{args.input}, a {type(obj).__name__}")

    def draw(camera, msaa=args.msaa, **core):
        return render(obj, camera, light=light, msaa=msaa, **core, **options)

    if args.turntable is not None:
        return _render_turntable(args, framing_bounds(obj), draw, el, dist, size, background)
    camera = orbit_bounds(framing_bounds(obj), az, el, dist, size, args.fov)
    frame = draw(camera)
    frame.save(args.output, background)
    print(f"wrote {args.output} ({size[0]}x{size[1]}, {frame.stats['covered']} pixels covered)")
    if frame.stats["covered"] == 0:
        _warn_nothing_visible("the render covers")
    if args.aovs:
        frame.save_aovs(args.aovs)
        print(f"wrote {args.aovs}")
    if args.stats:
        counted = draw(camera, msaa=1, count_iterations=True)  # counters are single-sample
        _write_stats(args, frame, counted)
    return 0


def _check_render_outputs(args) -> None:
    """The output names fit what is written; per-frame outputs do not go with --turntable."""
    suffix = Path(args.output).suffix.lower()
    if args.turntable is not None:
        if suffix != ".gif":
            raise UsageError("--turntable writes an animated .gif: name the output *.gif")
        given = [flag for flag, value in (("--aovs", args.aovs), ("--stats", args.stats))
                 if value]
        if given:
            raise UsageError(f"{' and '.join(given)} {'does' if len(given) == 1 else 'do'} not "
                             "apply to --turntable (one frame's arrays and counters): render "
                             "a single --view for them")
    elif suffix != ".png":
        raise UsageError(f"output must be a .png file, got {args.output}")
    if args.stats and Path(args.stats).suffix.lower() != ".json":
        raise UsageError(f"--stats writes JSON: name the file *.json, got {args.stats}")
    if args.aovs and Path(args.aovs).suffix.lower() != ".npz":
        raise UsageError(f"--aovs writes NumPy arrays: name the file *.npz, got {args.aovs}")
    from .io.atomic import check_writable

    for flag, value in (("-o", args.output), ("--aovs", args.aovs), ("--stats", args.stats)):
        if value:
            check_writable(value, flag)


def _render_turntable(args, bounds, draw, elevation, distance, size, background) -> int:
    """``args.turntable`` views of ``draw(camera)`` into a GIF, warning about empty views."""
    from .pictures import TILE_BACKGROUND, save_gif
    from .progress import progress_bar
    from .scene.views import turntable

    cameras = turntable(bounds, args.turntable, elevation, distance, size, args.fov)
    frames, empty = [], []
    with progress_bar("turntable", len(cameras)) as advance:
        for k, camera in enumerate(cameras):
            frame = draw(camera)
            if frame.stats["covered"] == 0:
                empty.append(str(k + 1))
            frames.append(frame.rgba8(background or TILE_BACKGROUND))
            advance(k + 1)
    save_gif(frames, args.output)
    print(f"wrote {args.output} ({len(frames)} views)")
    if empty:
        many = len(empty) > 1
        _warn_nothing_visible(f"view{'s' if many else ''} {', '.join(empty)} of {len(frames)} "
                              f"cover{'' if many else 's'}")
    return 0


def _write_stats(args, frame, counted) -> None:
    """The plain frame's counters plus the instrumented pass's (fragments, iterations)."""
    from .io.atomic import atomic_path

    stats = {"input": args.input, "size": list(frame.size), "view": args.view,
             **counted.stats, **frame.stats}
    with atomic_path(args.stats) as tmp:
        tmp.write_text(json.dumps(stats, indent=2) + "\n")
    print(f"wrote {args.stats}")


def cmd_compare(args) -> int:
    from .compare import metrics_markdown, write_comparison
    from .scene.views import check_fov, orbit_bounds, parse_size, parse_view

    az, el, dist = parse_view(args.view)
    size = parse_size(args.size)
    check_fov(args.fov)
    light = _light(args)
    from .io.atomic import check_writable

    check_writable(args.out, "--out", folder=True)
    mesh = _bake_source(args.input, "compare")
    if not hasattr(mesh, "triangle_count"):
        raise UsageError("compare needs a mesh (or demo:NAME) as INPUT, not a heightmap")
    rep = _bake_input(args, mesh)
    camera = orbit_bounds(mesh.bounds, az, el, dist, size, args.fov)
    result = _compare_with_progress(mesh, rep, camera, light)
    title = f"{mesh.name} as {args.kind}, view {args.view}"
    paths = write_comparison(result, Path(args.out), title)
    print(metrics_markdown(result, title))
    print("wrote " + ", ".join(str(p) for p in paths.values()))
    return 0


def _compare_with_progress(mesh, rep, camera, light) -> dict:
    """`compare` with a progress line per variant (the mesh, then each available variant)."""
    from .compare import compare
    from .core.technique import technique_of
    from .progress import progress_bar

    tech = technique_of(rep)
    variants = [v for v in (tech.compare_variants if tech else ()) if v.available(rep)]
    with progress_bar("compare", len(variants) + 1) as advance:
        return compare(mesh, rep, camera, light=light, progress=advance)


def cmd_bench(args) -> int:
    from .bench import run_suite
    from .io.atomic import check_writable

    check_writable(args.out, "--out", folder=True)
    report, paths = run_suite(args.name, quick=args.quick, out=Path(args.out))
    print(report)
    print("wrote " + ", ".join(map(str, paths)))
    return 0


def cmd_info(args) -> int:
    if not args.gl and not args.file:
        raise UsageError("info needs --gl and/or a FILE")
    report = {}
    if args.gl:
        from .gl.context import gl_info

        report["gl"] = gl_info()
    if args.file:
        report["file"] = _describe_file(args.file)
    if args.json:
        print(json.dumps(report, indent=2))
    else:
        for section in report.values():
            for key, value in section.items():
                shown = json.dumps(value) if isinstance(value, dict | list) else value
                print(f"{key:>24}: {shown}")
    return 0


def _describe_file(spec: str) -> dict:
    """A mesh's counts and bounds, or an .rk file's manifest once every array is read and its
    checksum verified (so "checksums: ok" is only ever printed for a file that loads)."""
    _check_not_empty(spec)
    if Path(spec).suffix.lower() == ".rk":
        from .io.rk import load, read_manifest

        load(spec)  # every check render makes: checksums, then the representation's own
        return {**read_manifest(spec), "checksums": "ok", "valid": "ok"}
    from .io.inputs import describe

    return describe(_load(spec))


def cmd_demo(args) -> int:
    from .demo import build_demo
    from .io.atomic import check_writable
    from .scene.views import parse_size

    size = parse_size(args.size)
    check_writable(args.out, "--out", folder=True)
    sheet = build_demo(Path(args.out), tile_size=size)
    print(f"wrote {sheet}")
    return 0


def main(argv: list[str] | None = None) -> int:
    try:
        parser = build_parser()
    except ReliefkitError as exc:  # a technique failed to register
        print(f"error: {exc}", file=sys.stderr)
        return EXIT_INPUT
    args = parser.parse_args(argv)
    if not getattr(args, "run", None):
        parser.print_help()
        return EXIT_USAGE
    with _one_line_warnings(), _sigterm_interrupts():
        return _run(args)


class Terminated(BaseException):
    """SIGTERM arrived: unwinds like KeyboardInterrupt, so every `atomic_path` removes its
    temporary file, and is no Exception, so no `except Exception` swallows it."""


@contextlib.contextmanager
def _sigterm_interrupts():
    """While a command runs, SIGTERM raises `Terminated` (where Python can take signals)."""
    def handler(signum, frame):
        raise Terminated

    try:
        previous = signal.signal(signal.SIGTERM, handler)
    except ValueError:  # not the main thread (main() called from a test's thread)
        yield
        return
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


@contextlib.contextmanager
def _one_line_warnings():
    """Python warnings become one ``warning: ...`` line each; numpy's floating-point
    RuntimeWarnings (overflow, invalid value) are silenced: bad values are refused by the
    checks that follow them, with their own one-line error. Deprecations are silenced;
    PIL's DecompressionBombWarning stays (one line)."""
    def show(message, category, filename, lineno, file=None, line=None):
        text = " ".join(str(message).split())
        print(f"warning: {text}", file=sys.stderr)

    with warnings.catch_warnings():
        warnings.simplefilter("default")
        warnings.filterwarnings("ignore", category=DeprecationWarning)
        warnings.filterwarnings("ignore", category=PendingDeprecationWarning)
        warnings.filterwarnings("ignore", category=RuntimeWarning)
        # ... but PIL's DecompressionBombWarning (a RuntimeWarning) matters: one line
        warnings.filterwarnings("default", message=r"Image size \(", category=RuntimeWarning)
        warnings.showwarning = show
        yield


def _run(args) -> int:
    try:
        status = args.run(args)
        sys.stdout.flush()  # a closed pipe shows here, not in the interpreter's exit
        return status
    except BrokenPipeError:
        return _broken_pipe()
    except ReliefkitError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return EXIT_USAGE if isinstance(exc, UsageError) else EXIT_INPUT
    except OSError as exc:
        name = f" {exc.filename}" if getattr(exc, "filename", None) else ""
        print(f"error: cannot access{name}: {exc.strerror or exc}", file=sys.stderr)
        return EXIT_INPUT
    except KeyboardInterrupt:
        print("error: interrupted", file=sys.stderr)
        return 130
    except Terminated:
        print("error: terminated (SIGTERM); no output was left half-written", file=sys.stderr)
        return EXIT_TERMINATED
    except Exception as exc:  # a bug, not bad input: still one line, details on request
        if os.environ.get("RELIEFKIT_DEBUG"):
            raise
        print(f"error: internal error ({type(exc).__name__}: {exc}); "
              "rerun with RELIEFKIT_DEBUG=1 for a traceback", file=sys.stderr)
        return EXIT_INTERNAL


def _broken_pipe() -> int:
    """The reader of stdout went away (``... | head``): stop quietly, as `cat` would.

    stdout is pointed at /dev/null so the interpreter's final flush cannot fail again.
    """
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, sys.stdout.fileno())
    os.close(devnull)
    return EXIT_BROKEN_PIPE


if __name__ == "__main__":
    sys.exit(main())
