"""The `reliefkit` command line: parses arguments, calls the library, prints results.

Every failure is one line ``error: ...`` on stderr and a non-zero exit status.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

from .errors import ReliefkitError, UsageError
from .scene.views import DEFAULT_SIZE, DEFAULT_VIEW

CORE_EXAMPLES = {
    "demo": ["reliefkit demo --out out                          contact sheet of every demo"],
    "render": ["reliefkit render bunny.ply -o bunny.png           one view (default --view "
               "30,25,2.6)",
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
    """argparse that reports errors as one `error:` line (exit status 2)."""

    def error(self, message: str):  # noqa: D102
        self.exit(2, f"error: {message} (see {self.prog} --help)\n")


def _add_view_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--view", default=",".join(f"{x:g}" for x in DEFAULT_VIEW[:2]),
                   metavar="AZ,EL[,DIST]",
                   help="orbit the bounding-box centre (of the source mesh for a baked .rk): "
                        "azimuth and elevation in degrees, distance in bounding-sphere radii "
                        "(default: %(default)s, at the distance that fits the sphere in view)")
    p.add_argument("--size", default="x".join(map(str, DEFAULT_SIZE)), metavar="WxH",
                   help="image size in pixels (default: %(default)s)")
    p.add_argument("--fov", type=float, default=40.0, help="vertical field of view in degrees")


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
    p.add_argument("--background", default="transparent",
                   help="'transparent' or a grey level 0..1 to composite over")
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
    _add_bake_args(p, table)
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
        group.add_argument(flag, dest=OPTION_PREFIX + name, default=None, metavar=metavar,
                           help=_option_help(decls))


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
    """``given`` restricted to ``options``; a flag that does not apply is an error."""
    names = {opt.name for opt in options}
    wrong = [k for k in given if k not in names]
    if wrong:
        flags = ", ".join("--" + k.replace("_", "-") for k in wrong)
        has = ", ".join("--" + opt.flag for opt in options) or "none"
        raise UsageError(f"{flags} does not apply to {what} (its options: {has})")
    return given


def _add_bake_args(p: argparse.ArgumentParser, table: dict) -> None:
    p.add_argument("input", help="mesh file, demo:NAME, or a heightmap (.png/.npy)")
    kinds = tuple(table)
    p.add_argument("--as", dest="kind", default=kinds[0] if kinds else None, choices=kinds,
                   help="representation to bake (default: %(default)s)")
    _add_options(p, [(name, b.options) for name, (_, b) in table.items()], "bake options")


def _bake_input(args):
    from .bake import bake
    from .core.technique import baker
    from .progress import progress_bar
    from .scene.heightmap import is_heightmap, load_heightmap

    _, chosen = baker(args.kind)
    params = _applicable(_given_options(args), chosen.options, f"--as {args.kind}")
    if is_heightmap(args.input):
        source = load_heightmap(args.input)
    else:
        from .io.inputs import load_input

        source = load_input(args.input)
    with progress_bar(f"baking {args.kind}", 1) as advance:
        return bake(source, args.kind, progress=advance, **params)


def cmd_bake(args) -> int:
    from .io.rk import file_sha256, save

    if Path(args.output).suffix.lower() != ".rk":
        raise UsageError(f"output must be an .rk file, got {args.output}")
    rep = _bake_input(args)
    source_hash = file_sha256(args.input) if Path(args.input).is_file() else None
    save(args.output, rep, source_hash=source_hash)
    print(f"wrote {args.output} ({json.dumps(rep.summary().get('bytes', {}))})")
    return 0


def _version() -> str:
    from . import __version__

    return f"reliefkit {__version__}"


def _background(text: str):
    if text == "transparent":
        return None
    try:
        level = float(text)
    except ValueError:
        raise UsageError(f"--background must be 'transparent' or a number, got {text!r}") from None
    return (level, level, level)


def cmd_render(args) -> int:
    from .io.inputs import load_input
    from .pictures import TILE_BACKGROUND, save_gif
    from .render import render, render_options
    from .scene.views import framing_bounds, orbit_bounds, parse_size, parse_view, turntable

    az, el, dist = parse_view(args.view)
    size = parse_size(args.size)
    background = _background(args.background)
    suffix = Path(args.output).suffix.lower()
    if args.turntable is not None and suffix != ".gif":
        raise UsageError("--turntable writes an animated .gif: name the output *.gif")
    if args.turntable is None and suffix != ".png":
        raise UsageError(f"output must be a .png file, got {args.output}")
    if args.stats and Path(args.stats).suffix.lower() != ".json":
        raise UsageError(f"--stats writes JSON: name the file *.json, got {args.stats}")
    obj = load_input(args.input)
    options = _applicable(_given_options(args), render_options(obj),
                          f"a {type(obj).__name__} ({args.input})")
    if args.turntable is not None:
        from .progress import progress_bar

        cameras = turntable(framing_bounds(obj), args.turntable, el, dist, size, args.fov)
        frames = []
        with progress_bar("turntable", len(cameras)) as advance:
            for k, camera in enumerate(cameras):
                frames.append(render(obj, camera, **options).rgba8(
                    background or TILE_BACKGROUND))
                advance(k + 1)
        save_gif(frames, args.output)
        print(f"wrote {args.output} ({len(frames)} views)")
        return 0
    camera = orbit_bounds(framing_bounds(obj), az, el, dist, size, args.fov)
    frame = render(obj, camera, **options)
    frame.save(args.output, background)
    print(f"wrote {args.output} ({size[0]}x{size[1]}, {frame.stats['covered']} pixels covered)")
    if args.aovs:
        frame.save_aovs(args.aovs)
        print(f"wrote {args.aovs}")
    if args.stats:
        _write_stats(args, frame, render(obj, camera, count_iterations=True, **options))
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
    from .compare import compare, metrics_markdown, write_comparison
    from .io.inputs import load_input
    from .scene.views import orbit_bounds, parse_size, parse_view

    az, el, dist = parse_view(args.view)
    size = parse_size(args.size)
    mesh = load_input(args.input)
    if not hasattr(mesh, "triangle_count"):
        raise UsageError("compare needs a mesh (or demo:NAME) as INPUT, not an .rk file")
    rep = _bake_input(args)
    result = compare(mesh, rep, orbit_bounds(mesh.bounds, az, el, dist, size, args.fov))
    title = f"{mesh.name} as {args.kind}, view {args.view}"
    paths = write_comparison(result, Path(args.out), title)
    print(metrics_markdown(result, title))
    print("wrote " + ", ".join(str(p) for p in paths.values()))
    return 0


def cmd_bench(args) -> int:
    from .bench import run_suite

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
        if Path(args.file).suffix.lower() == ".rk":
            from .io.rk import read_manifest

            report["file"] = read_manifest(args.file)
        else:
            from .io.inputs import describe, load_input

            report["file"] = describe(load_input(args.file))
    if args.json:
        print(json.dumps(report, indent=2))
    else:
        for section in report.values():
            for key, value in section.items():
                shown = json.dumps(value) if isinstance(value, dict | list) else value
                print(f"{key:>24}: {shown}")
    return 0


def cmd_demo(args) -> int:
    from .demo import build_demo
    from .scene.views import parse_size

    sheet = build_demo(Path(args.out), tile_size=parse_size(args.size))
    print(f"wrote {sheet}")
    return 0


def main(argv: list[str] | None = None) -> int:
    try:
        parser = build_parser()
    except ReliefkitError as exc:  # a technique failed to register
        print(f"error: {exc}", file=sys.stderr)
        return 1
    args = parser.parse_args(argv)
    if not getattr(args, "run", None):
        parser.print_help()
        return 2
    try:
        return args.run(args)
    except ReliefkitError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    except OSError as exc:
        name = f" {exc.filename}" if getattr(exc, "filename", None) else ""
        print(f"error: cannot access{name}: {exc.strerror or exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("error: interrupted", file=sys.stderr)
        return 130
    except Exception as exc:  # a bug, not bad input: still one line, details on request
        if os.environ.get("RELIEFKIT_DEBUG"):
            raise
        print(f"error: internal error ({type(exc).__name__}: {exc}); "
              "rerun with RELIEFKIT_DEBUG=1 for a traceback", file=sys.stderr)
        return 3


if __name__ == "__main__":
    sys.exit(main())
