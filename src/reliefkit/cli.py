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

EXAMPLES = """\
examples:
  reliefkit demo --out out                          contact sheet of every demo asset
  reliefkit render bunny.ply -o bunny.png           one view (default --view 30,25,2.6)
  reliefkit render car.glb --view 90,10,2 --size 800x600 -o side.png --aovs side.npz
  reliefkit render demo:tree --turntable 36 -o spin.gif
  reliefkit bake demo:terrain --as relief --depth-res 256 -o terrain.rk
  reliefkit render terrain.rk --method robust --shadows -o terrain.png
  reliefkit compare demo:vehicle --as relief-frustum --out cmp
  reliefkit info --gl                               the OpenGL renderer and its limits
  reliefkit info model.obj                          counts and bounds of a mesh (or an .rk)

inputs: a mesh file (.obj .ply .stl .off .gltf .glb), an .rk file, demo:NAME
(demo assets: terrain, blob, tree, vehicle), or for `bake --as relief` a heightmap
(8/16-bit greyscale .png or a 2D .npy array).
"""


class _Parser(argparse.ArgumentParser):
    """argparse that reports errors as one `error:` line (exit status 2)."""

    def error(self, message: str):  # noqa: D102
        self.exit(2, f"error: {message} (see {self.prog} --help)\n")


def _add_view_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--view", default=",".join(f"{x:g}" for x in DEFAULT_VIEW),
                   metavar="AZ,EL,DIST",
                   help="orbit the bounding-box centre: azimuth and elevation in degrees, "
                        "distance in bounding-sphere radii (default: %(default)s)")
    p.add_argument("--size", default="x".join(map(str, DEFAULT_SIZE)), metavar="WxH",
                   help="image size in pixels (default: %(default)s)")
    p.add_argument("--fov", type=float, default=40.0, help="vertical field of view in degrees")


def _command(sub, name: str, summary: str, description: str, *examples: str):
    """A subcommand parser whose --help ends with its examples."""
    epilog = "examples:\n" + "\n".join(f"  {line}" for line in examples)
    return sub.add_parser(name, help=summary, description=description, epilog=epilog,
                          formatter_class=argparse.RawDescriptionHelpFormatter)


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="reliefkit", description="Render geometry from textures with depth.",
                     epilog=EXAMPLES, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version", version=_version())
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

    p = _command(sub, "render", "render a mesh or an .rk representation to PNG / GIF",
                 "Render a mesh (ground truth) or an .rk representation.",
                 "reliefkit render model.glb -o model.png --aovs model.npz",
                 "reliefkit render demo:vehicle --turntable 24 -o spin.gif")
    p.add_argument("input", help="mesh file, .rk file or demo:NAME")
    _add_view_args(p)
    p.add_argument("-o", "--output", required=True, help="output .png (or .gif with --turntable)")
    p.add_argument("--aovs", metavar="OUT.npz",
                   help="also write color, mask, depth, position, normal, view, proj, viewport")
    p.add_argument("--turntable", type=int, metavar="N", help="N views around the object (GIF)")
    p.add_argument("--background", default="transparent",
                   help="'transparent' or a grey level 0..1 to composite over")
    _add_relief_args(p)
    p.set_defaults(run=cmd_render)

    p = _command(sub, "bake", "bake a mesh or heightmap into an .rk representation",
                 "Bake a mesh (or a heightmap) into a representation.",
                 "reliefkit bake model.glb --as relief --depth-res 256 --color-res 512 -o model.rk",
                 "reliefkit bake demo:vehicle --as relief-frustum -o van.rk",
                 "reliefkit bake height.png --as relief --box 2,0.4,2 -o terrain.rk")
    _add_bake_args(p)
    p.add_argument("-o", "--output", required=True, help="output .rk file")
    p.set_defaults(run=cmd_bake)

    p = _command(sub, "compare", "bake, then render mesh and every method side by side",
                 "Bake INPUT, render the mesh and each intersection method from one view; "
                 "write compare.png, metrics.md, metrics.json.",
                 "reliefkit compare demo:terrain --as relief --out cmp",
                 "reliefkit compare car.glb --as relief-frustum --view 60,15,2 --out cmp")
    _add_bake_args(p)
    _add_view_args(p)
    p.add_argument("--out", default="out/compare", help="output folder (default: %(default)s)")
    p.set_defaults(run=cmd_compare)

    p = _command(sub, "bench", "reproduce a paper's tables (speed, iterations, errors)",
                 "Benchmarks measured side by side in one run.",
                 "reliefkit bench relief --quick", "reliefkit bench relief --out docs/bench")
    p.add_argument("name", choices=("relief",), help="which benchmark")
    p.add_argument("--quick", action="store_true", help="small sizes (a smoke run)")
    p.add_argument("--out", default="out/bench", help="folder for .md and .json results")
    p.set_defaults(run=cmd_bench)

    p = _command(sub, "info", "GL capabilities, or the contents of a mesh / .rk file",
                 "Print the OpenGL renderer and limits (--gl) and/or summarise a mesh or .rk "
                 "file.", "reliefkit info --gl", "reliefkit info --json model.rk")
    p.add_argument("file", nargs="?", help="mesh file, .rk file or demo:NAME")
    p.add_argument("--gl", action="store_true", help="print renderer, GL version and limits")
    p.add_argument("--json", action="store_true", help="print JSON instead of text")
    p.set_defaults(run=cmd_info)

    p = _command(sub, "demo", "render the demo assets into a titled contact sheet",
                 "Render every demo asset (and representation) into OUT/demo.png plus one "
                 "PNG per tile.", "reliefkit demo --out out")
    p.add_argument("--out", default="out", help="output folder (default: %(default)s)")
    p.add_argument("--size", default="256x256", metavar="WxH", help="tile size")
    p.set_defaults(run=cmd_demo)
    return parser


def _add_relief_args(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("relief textures")
    g.add_argument("--method", default="robust", choices=("binary", "exact", "robust"),
                   help="ray/heightfield intersection (default: %(default)s)")
    g.add_argument("--depth-mode", default="conservative", choices=("conservative", "exact"),
                   help="keep the box depth, or write the hit's depth (default: %(default)s)")
    g.add_argument("--shadows", action="store_true", help="self-shadowing (a ray to the light)")
    g.add_argument("--zero-radius", default="exact", choices=("exact", "clamp"),
                   help="robust method at zero safety radius (default: %(default)s)")
    g.add_argument("--cell-test", default="quadratic", choices=("quadratic", "linear"),
                   help="exact/robust: test each cell's exact quadratic, or assume heights "
                        "linear between centrelines as the paper does (default: %(default)s)")
    g.add_argument("--linear-steps", type=int, default=16, help="binary: fixed pre-steps")
    g.add_argument("--binary-steps", type=int, default=8, help="binary search steps")


def _relief_options(args, obj) -> dict:
    from .represent.relief import ReliefObject, ReliefTexture

    if not isinstance(obj, ReliefTexture | ReliefObject):
        return {}
    return {"method": args.method, "depth_mode": args.depth_mode, "shadows": args.shadows,
            "zero_radius": args.zero_radius, "cell_test": args.cell_test,
            "linear_steps": args.linear_steps,
            "binary_steps": args.binary_steps}


def _add_bake_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("input", help="mesh file, demo:NAME, or a heightmap (.png/.npy)")
    p.add_argument("--as", dest="kind", default="relief",
                   choices=("relief", "relief-frustum", "relief-cube"),
                   help="representation to bake (default: %(default)s)")
    p.add_argument("--depth-res", type=int, help="heightfield resolution (longest side)")
    p.add_argument("--color-res", type=int, help="colour/normal resolution (default: depth)")
    p.add_argument("--safety-tolerance", type=float, default=0.01, metavar="E",
                   help="ignored dip depth (height units, Fig. 12): larger radii and fewer "
                        "iterations for a bounded silhouette error (default: %(default)s)")
    p.add_argument("--no-safety", action="store_true", help="skip the safety radii")
    p.add_argument("--axis", default="y", help="projection axis: x, y, z, -x, -y, -z")
    p.add_argument("--spread", type=float, default=30.0,
                   help="relief-frustum: side tilt in degrees (default: %(default)s)")
    p.add_argument("--box", default="2,0.5,2", metavar="SX,SY,SZ",
                   help="heightmaps: world size of the box (default: %(default)s)")


def _bake_input(args):
    from .bake import bake
    from .progress import progress_bar
    from .scene.heightmap import is_heightmap, load_heightmap

    if args.safety_tolerance < 0 or args.safety_tolerance > 1:
        raise UsageError("--safety-tolerance must be within [0, 1]")
    extra = {}
    if is_heightmap(args.input):
        source = load_heightmap(args.input)
        try:
            extra["size"] = tuple(float(x) for x in args.box.split(","))
            assert len(extra["size"]) == 3 and min(extra["size"]) > 0
        except (ValueError, AssertionError):
            raise UsageError(f"--box must be three positive sizes, got {args.box!r}") from None
    else:
        from .inputs import load_input

        source = load_input(args.input)
        if args.kind == "relief-frustum":
            extra["spread_deg"] = args.spread
    with progress_bar("safety radii", 1, enabled=not args.no_safety) as advance:
        return bake(source, args.kind, depth_res=args.depth_res, color_res=args.color_res,
                    tolerance=args.safety_tolerance, safety=not args.no_safety,
                    axis=args.axis, progress=advance, **extra)


def cmd_bake(args) -> int:
    from .formats import file_sha256, save

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
    from .inputs import load_input
    from .pictures import save_gif
    from .render import render
    from .scene.views import orbit_bounds, parse_size, parse_view, turntable

    az, el, dist = parse_view(args.view)
    size = parse_size(args.size)
    background = _background(args.background)
    suffix = Path(args.output).suffix.lower()
    if args.turntable is not None and suffix != ".gif":
        raise UsageError("--turntable writes an animated .gif: name the output *.gif")
    if args.turntable is None and suffix != ".png":
        raise UsageError(f"output must be a .png file, got {args.output}")
    obj = load_input(args.input)
    options = _relief_options(args, obj)
    if args.turntable is not None:
        from .progress import progress_bar

        cameras = turntable(obj.bounds, args.turntable, el, dist, size, args.fov)
        frames = []
        with progress_bar("turntable", len(cameras)) as advance:
            for k, camera in enumerate(cameras):
                frames.append(render(obj, camera, **options).rgba8(
                    background or (0.12, 0.12, 0.13)))
                advance(k + 1)
        save_gif(frames, args.output)
        print(f"wrote {args.output} ({len(frames)} views)")
        return 0
    frame = render(obj, orbit_bounds(obj.bounds, az, el, dist, size, args.fov), **options)
    frame.save(args.output, background)
    print(f"wrote {args.output} ({size[0]}x{size[1]}, {int(frame.mask.sum())} pixels covered)")
    if args.aovs:
        frame.save_aovs(args.aovs)
        print(f"wrote {args.aovs}")
    return 0


def cmd_compare(args) -> int:
    from .compare import compare_relief, metrics_markdown, write_comparison
    from .inputs import load_input
    from .scene.views import orbit_bounds, parse_size, parse_view

    az, el, dist = parse_view(args.view)
    size = parse_size(args.size)
    mesh = load_input(args.input)
    if not hasattr(mesh, "triangle_count"):
        raise UsageError("compare needs a mesh (or demo:NAME) as INPUT, not an .rk file")
    relief = _bake_input(args)
    result = compare_relief(mesh, relief, orbit_bounds(mesh.bounds, az, el, dist, size,
                                                       args.fov))
    title = f"{mesh.name} as {args.kind}, view {args.view}"
    paths = write_comparison(result, Path(args.out), title)
    print(metrics_markdown(result["metrics"], title))
    print("wrote " + ", ".join(str(p) for p in paths.values()))
    return 0


def cmd_bench(args) -> int:
    from .bench import relief

    out = Path(args.out)
    cfg = relief.BenchConfig.quick(out) if args.quick else relief.BenchConfig(out=out)
    results = relief.run(cfg, log=lambda msg: print(msg, file=sys.stderr, flush=True))
    paths = relief.write(results, out)
    print(relief.markdown(results))
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
            from .formats import read_manifest

            report["file"] = read_manifest(args.file)
        else:
            from .inputs import describe, load_input

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
    parser = build_parser()
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
