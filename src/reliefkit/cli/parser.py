"""Building the argument parser from the registry: commands, flags, help, examples."""

from __future__ import annotations

import argparse
import sys

from .. import __version__
from ..bench import suite_names, suites
from ..builtins import registry
from ..compact.compact import CompressOptions
from ..core.params import options_of
from ..core.technique import bakers, techniques
from ..export.gltf import DEFAULT_FALLBACK_TRIANGLES
from ..scene.assets import DEMO_NAMES
from ..scene.light import DEFAULT_LIGHT_ANGLES
from ..scene.views import DEFAULT_FOV, DEFAULT_SIZE, DEFAULT_VIEW
from ..shootout.sizing import candidates as shootout_candidates
from ..viewer.browser import BACKENDS as BROWSER_BACKENDS
from .commands import (
    cmd_bake,
    cmd_batch,
    cmd_bench,
    cmd_compare,
    cmd_demo,
    cmd_export,
    cmd_info,
    cmd_render,
    cmd_shootout,
    cmd_view,
)
from .exits import EXIT_USAGE
from .options import add_flag, add_options

MSAA_CHOICES = (1, 2, 4, 8)

CORE_EXAMPLES = {
    "demo": ["reliefkit demo --out out                          contact sheet of every demo"],
    "render": ["reliefkit render bunny.ply -o bunny.png           one view (default --view "
               "30,25)",
               "reliefkit render car.glb --view 90,10,2 --size 800x600 -o side.png --aovs "
               "side.npz",
               "reliefkit render demo:tree --turntable 36 -o spin.gif",
               "reliefkit render demo:tree --turntable 36 -o spin.webp    with alpha (.png: "
               "APNG)",
               "reliefkit render demo:tree --turntable 36 --size 640x480 -o spin.mp4",
               "reliefkit render demo:tree --turntable 36 -o frames/%04d.png"],
    "export": ["reliefkit export tree.rk -o tree.glb                 any viewer shows it; "
               "reliefkit reads it back",
               "reliefkit export car.glb --lod relief-cube,billboard-cloud -o car-lod.glb",
               "reliefkit export tree.rk -o tree.gltf --embed-shaders"],
    "view": ["reliefkit view tree.rk demo:tree                    in the browser, side by side",
             "reliefkit view car.glb --no-browser --port 8000   print the URL only",
             "reliefkit view tree.rk --export-html site/        a folder any static server shows"],
    "shootout": ["reliefkit shootout demo:tree --out out/shootout    what to ship at 64 and "
                 "256 px, 256 KB and 1 MB",
                 "reliefkit shootout car.glb tree.obj --budgets 256KB,1MB --sizes 128,512 "
                 "--out out/shootout"],
    "batch": ["reliefkit batch assets/ --as octahedral-impostor --out baked/   every mesh, "
              "resumable",
              "reliefkit batch 'assets/**/*.glb' --as relief-cube --depth-res 128 --out baked "
              "--export glb",
              "reliefkit batch manifest.csv --out baked --workers 2 --timeout 600"],
    "info": ["reliefkit info --gl                               the OpenGL renderer and its "
             "limits",
             "reliefkit info model.obj                          counts and bounds of a mesh "
             "(or an .rk)"],
}
ORDER = ("demo", "render", "bake", "batch", "compare", "export", "view", "shootout", "bench",
         "info")


def _examples(command: str | None = None) -> list[str]:
    """Example lines: the core's and every technique's, for one command or all in order."""
    table = {name: list(lines) for name, lines in CORE_EXAMPLES.items()}
    for tech in techniques():
        for name, lines in tech.cli_examples.items():
            table.setdefault(name, []).extend(lines)
    names = [command] if command else [n for n in ORDER if n in table]
    return [line for name in names for line in table.get(name, [])]


def _epilog() -> str:
    import textwrap

    heightmap_kinds = [name for name, (_, b) in bakers().items() if "heightmap" in b.sources]
    inputs = ("inputs: a mesh file (.obj .ply .stl .off .gltf .glb), an .rk file, demo:NAME "
              f"(demo assets: {', '.join(DEMO_NAMES)})")
    if heightmap_kinds:
        inputs += (f", or for `bake --as {'/'.join(heightmap_kinds)}` a heightmap (8/16-bit "
                   "greyscale .png or a 2D .npy array)")
    return "\n".join(["examples:", *(f"  {line}" for line in _examples()), "",
                      textwrap.fill(inputs + ".", 88)]) + "\n"


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


def _add_view_args(p: _Parser) -> None:
    """--view, --size, --fov and --light: the camera and light of every render."""
    add_flag(p, "--view", dash_value=True, metavar="AZ,EL[,DIST]",
              default=",".join(f"{x:g}" for x in DEFAULT_VIEW[:2]),
              help="orbit the bounding-box centre (of the source mesh for a baked .rk): "
                   "azimuth about +y from +z towards +x and elevation in degrees, distance in "
                   "bounding-sphere radii, within [0.01, 10000] (default: %(default)s, at the "
                   "distance that fits the sphere in view)")
    p.add_argument("--size", default="x".join(map(str, DEFAULT_SIZE)), metavar="WxH",
                   help="image size in pixels (default: %(default)s)")
    add_flag(p, "--fov", dash_value=True, type=float, default=DEFAULT_FOV, metavar="DEG",
              help="vertical field of view in degrees, within [0.1, 179] (default: "
                   "%(default)g)")
    add_flag(p, "--light", dash_value=True, metavar="AZ,EL",
              default=",".join(f"{x:g}" for x in DEFAULT_LIGHT_ANGLES),
              help="where the light comes from: azimuth and elevation in degrees, as in "
                   "--view (default: %(default)s, a low sun from the side)")


def _drawn_kinds(tech, spec) -> str:
    """Who owns a drawable's options in --help: its technique, or where the technique's
    drawables take different options (depth objects and displacement maps) the kinds this
    one draws."""
    if len({d.options for d in tech.drawables}) == 1:
        return tech.name
    return "/".join(c.kind for c in tech.codecs if issubclass(c.cls, spec.cls)) or tech.name


def _command(sub, name: str, summary: str, description: str):
    """A subcommand parser whose --help ends with its examples."""
    epilog = "examples:\n" + "\n".join(f"  {line}" for line in _examples(name))
    return sub.add_parser(name, help=summary, description=description, epilog=epilog,
                          formatter_class=argparse.RawDescriptionHelpFormatter)


def build_parser() -> argparse.ArgumentParser:
    core_drawables = registry().core_drawables

    parser = _Parser(prog="reliefkit", description="Render geometry from textures with depth.",
                     epilog=_epilog(), formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version", version=f"reliefkit {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    table = bakers()

    p = _command(sub, "render", "render a mesh or an .rk representation to PNG, or an animation",
                 "Render a mesh (ground truth) or an .rk representation.")
    p.add_argument("input", help="mesh file, .rk file or demo:NAME")
    _add_view_args(p)
    p.add_argument("-o", "--output", required=True,
                   help="output .png; with --turntable or --animate, by its name: a .gif, an "
                        "animated .png/.apng or .webp (with alpha), an .mp4, or one PNG per "
                        "frame (frames/%%04d.png or a folder/)")
    p.add_argument("--aovs", metavar="OUT.npz",
                   help="also write color, mask, depth, position, normal, view, proj, viewport")
    p.add_argument("--stats", metavar="OUT.json",
                   help="also write the frame's counters: covered pixels, fragments and loop "
                        "iterations per pixel (mean, max) where the renderer counts them")
    p.add_argument("--turntable", type=int, metavar="N",
                   help="N views around the object, as an animation (see -o)")
    p.add_argument("--animate", type=int, metavar="N",
                   help="N frames of the input's animation, times 0, 1/N, ... (an "
                        "animation, see -o; for inputs with a --time option, such as shell "
                        "volumes)")
    add_flag(p, "--background", dash_value=True, default="transparent",
              metavar="transparent|LEVEL",
              help="'transparent' or a grey level 0..1 to composite over (default: "
                   "%(default)s)")
    p.add_argument("--msaa", type=int, default=1, choices=MSAA_CHOICES, metavar="N",
                   help="samples per pixel for the colour (1, 2, 4 or 8, up to the GPU's "
                        "GL_MAX_SAMPLES); the AOVs stay single-sample (default: %(default)s)")
    _add_render_options(p, core_drawables)
    p.set_defaults(run=cmd_render)

    p = _command(sub, "bake", "bake a mesh or heightmap into an .rk representation",
                 "Bake a mesh (or a heightmap) into a representation. Representations: "
                 + "; ".join(f"{name}: {b.summary}" for name, (_, b) in table.items()) + ".")
    _add_bake_args(p, table)
    p.add_argument("-o", "--output", required=True, help="output .rk file")
    p.set_defaults(run=cmd_bake)

    p = _command(sub, "batch", "bake many meshes (folders, globs, a manifest), resumable",
                 "Bake every mesh INPUT names into DIR, keeping each input's relative path "
                 "(chairs/a.obj -> DIR/chairs/a.rk), on a pool of worker processes. An "
                 "output whose cache key (the source and its textures, the kind, the "
                 "options, reliefkit's version) matches is skipped, so a rerun goes on "
                 "where one stopped. Each asset's result is appended to DIR/batch.jsonl; "
                 "a summary table ends the run (exit 1 when any asset failed). "
                 "docs/batch.md.")
    p.add_argument("inputs", nargs="+", metavar="INPUT",
                   help="mesh files, folders (searched recursively), glob patterns "
                        "('assets/**/*.glb'), or a manifest (.csv: input,kind,options; "
                        ".jsonl: {\"input\", \"kind\", \"options\"}) naming a kind and "
                        "options per asset")
    _add_bake_options(p, table)
    p.add_argument("--out", required=True, metavar="DIR", help="output folder")
    p.add_argument("--workers", type=int, metavar="N",
                   help="worker processes, or Ray tasks in flight (default: the CPU cores, "
                        "or a Ray cluster's CPUs; each gets cores/N Mesa and numba threads)")
    p.add_argument("--executor", default="local", choices=("local", "ray"),
                   help="where the workers run: local processes or Ray tasks (pip install "
                        "'reliefkit[ray]') (default: %(default)s)")
    p.add_argument("--address", metavar="ADDR",
                   help="with --executor ray: the cluster, auto, HOST:PORT or ray://HOST:PORT "
                        "(default: a local one started for the run)")
    p.add_argument("--force", action="store_true",
                   help="bake every asset again, whatever is on disk")
    p.add_argument("--export", choices=("glb",),
                   help="also write each output's glTF export beside its .rk")
    p.add_argument("--sheet", action="store_true",
                   help="also write DIR/sheet.png and DIR/index.html: each output's "
                        "thumbnail beside its mesh's")
    p.add_argument("--timeout", type=float, metavar="S",
                   help="seconds one asset may take; its worker is stopped and replaced, "
                        "the asset failed")
    p.add_argument("--max-memory", metavar="SIZE",
                   help="memory one worker may hold (2GB, 512MB); past it the worker is "
                        "stopped and replaced, the asset failed")
    p.set_defaults(run=cmd_batch)

    p = _command(sub, "compare", "bake, then render the mesh and every variant side by side",
                 "Bake INPUT, render the mesh and each variant of the representation (its "
                 "methods or modes) from one view; write compare.png, metrics.md, metrics.json.")
    _add_bake_args(p, table, "mesh file or demo:NAME (not a heightmap: there is no mesh to "
                             "compare against)")
    _add_view_args(p)
    p.add_argument("--out", default="out/compare", help="output folder (default: %(default)s)")
    p.set_defaults(run=cmd_compare)

    p = _command(sub, "shootout", "which representation to ship for a mesh, per size and budget",
                 "Bake every representation the registry can size so that its bytes on a GPU "
                 "(textures block-compressed, read back from its .rk file) fit each budget, "
                 "decimate the mesh to the same compact GPU bytes, render both "
                 "from six views with the bounding sphere spanning each size in pixels, and "
                 "measure them against the full mesh; write shootout.md, shootout.json, a "
                 "Pareto plot and a contact sheet per size, and one recommendation per size "
                 "and budget.")
    p.add_argument("meshes", nargs="+", metavar="MESH", help="mesh files or demo:NAME")
    p.add_argument("--budgets", default="256KB,1MB",
                   help="byte budgets, KB/MB binary (default: %(default)s)")
    p.add_argument("--sizes", default="64,256",
                   help="screen sizes in pixels: the bounding sphere's diameter "
                        "(default: %(default)s)")
    p.add_argument("--kinds", metavar="K,K",
                   help="only these representations, by baker or row (default: every one "
                        "the registry can size: "
                        + ", ".join(c.label for c in shootout_candidates()) + ")")
    p.add_argument("--out", required=True, help="output folder")
    p.set_defaults(run=cmd_shootout)

    p = _command(sub, "export", "write a representation, or a mesh's LOD chain, as glTF 2.0",
                 "Write an .rk representation (or a glTF file reliefkit exported) as glTF "
                 "2.0 (.glb, or .gltf with its .bin and PNG files): a core mesh any viewer "
                 "shows, and reliefkit's RELIEFKIT_<kind> extension with the representation "
                 "and its draw plans (docs/gltf.md). With --lod, bake a mesh into the listed "
                 "representations and write them after it as an MSFT_lod chain.")
    p.add_argument("input", help=".rk file (or a .glb reliefkit wrote); with --lod a mesh "
                                 "file or demo:NAME")
    p.add_argument("-o", "--output", required=True, help="output .glb or .gltf")
    p.add_argument("--no-fallback", action="store_true",
                   help="write no core mesh, only the extension (viewers without reliefkit's "
                        "extension then show nothing)")
    p.add_argument("--embed-shaders", action="store_true",
                   help="add the GLSL ES 3.00 sources of the draw plans' programs")
    p.add_argument("--fallback-triangles", type=int, default=DEFAULT_FALLBACK_TRIANGLES,
                   metavar="N", help="triangle budget of the core mesh where the kind has one "
                                     "(default: %(default)s)")
    p.add_argument("--lod", metavar="KIND,KIND",
                   help="bake INPUT (a mesh) as these representations (" + ", ".join(table)
                        + ") and write mesh + representations as an LOD chain")
    add_options(p, [(name, b.options) for name, (_, b) in table.items()],
                "bake options (with --lod; each applies to the kinds that declare it)")
    add_options(p, [("compress", options_of(CompressOptions))], "compression (with --lod)")
    p.set_defaults(run=cmd_export)

    p = _command(sub, "view", "look at representations in the browser, drawn by their shaders",
                 "Serve a page on 127.0.0.1 that draws each input's draw plans with the "
                 "GLSL ES sources of reliefkit's shaders in WebGL2, side by side from one "
                 "camera (?view=AZ,EL,DIST&size=WxH in its URL; drag to orbit, wheel to "
                 "zoom), their plans made with the render options given (each to the "
                 "inputs that declare it); Ctrl-C stops it. docs/viewer.md.")
    p.add_argument("inputs", nargs="+", metavar="INPUT",
                   help=".rk file, a .glb reliefkit wrote, a mesh file or demo:NAME")
    p.add_argument("--port", type=int, default=None, metavar="N",
                   help="port on 127.0.0.1 (default: a free one)")
    p.add_argument("--no-browser", action="store_true", help="print the URL, open no browser")
    p.add_argument("--export-html", metavar="DIR",
                   help="write the page, its bundle and the GLB files into DIR (viewable from "
                        "any static web server) instead of serving")
    _add_render_options(p, core_drawables)
    p.set_defaults(run=cmd_view)

    names = suite_names()
    p = _command(sub, "bench", "reproduce a paper's tables (speed, iterations, errors)",
                 "Benchmarks measured side by side in one run: "
                 + "; ".join(f"{n}: {s.summary}" for n, s in suites().items()) + ".")
    p.add_argument("name", choices=names, help="which benchmark")
    p.add_argument("--quick", action="store_true", help="small sizes (a smoke run)")
    p.add_argument("--mesh", metavar="FILE",
                   help="run on this mesh file instead of the built-in assets (suites: "
                        + ", ".join(n for n, s in suites().items() if s.takes_mesh) + ")")
    p.add_argument("--size", metavar="WxH",
                   help="frame size (suites: viewer; default 1920x1080, --quick 256x256)")
    p.add_argument("--browser", choices=tuple(BROWSER_BACKENDS),
                   help="Chromium's WebGL backend (suites: viewer; default swiftshader; gpu: "
                        "the machine's GPU through its EGL driver)")
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


def _add_render_options(p, core_drawables) -> None:
    """Every drawable's render options as flags, each owner named in its help."""
    add_options(p, [("mesh", spec.option_list) for spec in core_drawables()]
                + [(_drawn_kinds(t, spec), spec.option_list) for t in techniques()
                   for spec in t.drawables], "render options")


def _add_bake_args(p: argparse.ArgumentParser, table: dict,
                   input_help: str = "mesh file, demo:NAME, or a heightmap (.png/.npy)") -> None:
    p.add_argument("input", help=input_help)
    _add_bake_options(p, table)


def _add_bake_options(p: argparse.ArgumentParser, table: dict) -> None:
    """--as KIND and every bake and compression option (`bake`, `compare`, `batch`)."""
    kinds = tuple(table)
    p.add_argument("--as", dest="kind", default=kinds[0] if kinds else None, choices=kinds,
                   help="representation to bake (default: %(default)s)")
    add_options(p, [(name, b.options) for name, (_, b) in table.items()], "bake options")
    add_options(p, [("compress", options_of(CompressOptions))], "compression (any kind)")


