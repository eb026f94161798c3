"""The subcommands: each loads, calls the library and prints what it wrote."""

from __future__ import annotations

import itertools
import json
import shlex
import sys
from contextlib import closing
from pathlib import Path

from .. import strict_json
from ..animation import (
    check_animation_output,
    frame_background,
    is_animation_name,
    save_animation,
)
from ..bake import bake
from ..batch.key import file_cache_key
from ..batch.report import JSONL_NAME, BatchInterrupted
from ..bench import run_suite
from ..builtins import batch
from ..compact.compact import CompressOptions, gpu_bytes
from ..compare import compare, metrics_markdown, write_comparison
from ..core.params import ANIMATION_TIME, applicable, options_of
from ..core.technique import baker, bakers, technique_of
from ..demo import build_demo
from ..errors import FormatError, MeshError, ReliefkitError, UsageError
from ..export import export, export_lod
from ..gl.context import gl_info
from ..io.atomic import atomic_path, check_writable, written_together
from ..io.gltf import representation as gltf_representation
from ..io.inputs import DEMO_PREFIX, describe, kind_of, load_input, what_it_is
from ..io.rk import array_bytes, file_sha256, load, read_manifest, save
from ..progress import progress_bar, waiting
from ..render import Scene, render, render_options
from ..scene.heightmap import is_heightmap, load_heightmap
from ..scene.light import DirectionalLight
from ..scene.views import (
    check_fov,
    framing_bounds,
    orbit_bounds,
    parse_light,
    parse_size,
    parse_view,
    turntable,
)
from ..shootout import load_meshes, parse_budgets, parse_kinds, parse_sizes, shootout
from ..units import format_bytes
from ..viewer import server as view_server
from ..viewer import site as view_site
from ..viewer.variants import Variants
from .exits import EXIT_INTERRUPTED
from .options import given_options

MAX_FRAMES = 3600  # of --turntable and --animate (streamed: memory is one frame's)


def _check_not_empty(spec: str) -> None:
    """A zero-byte input file is refused as such (before a loader guesses why it fails)."""
    path = Path(spec)
    if path.is_file() and path.stat().st_size == 0:
        raise FormatError(f"{spec}: the file is empty (0 bytes)")


def _check_mesh_file(spec: str, flag: str) -> None:
    """A mesh file (not demo:NAME, a heightmap or an .rk) that exists, refused up front."""
    from ..io.meshes import SUPPORTED_EXTENSIONS  # trimesh: slow to import

    if Path(spec).suffix.lower() not in SUPPORTED_EXTENSIONS:
        raise UsageError(f"{flag} needs a mesh file ({' '.join(SUPPORTED_EXTENSIONS)}), got "
                         f"{spec}")
    if not Path(spec).is_file():
        raise MeshError(f"{spec}: no such file" if not Path(spec).exists() else
                        f"{spec}: is not a file")
    _check_not_empty(spec)


def _bake_source(spec: str, command: str = "bake"):
    """The mesh or heightmap ``bake`` and ``compare`` start from."""
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
    _, chosen = baker(args.kind)
    given = given_options(args)
    compression = {opt.name: given.pop(opt.name) for opt in options_of(CompressOptions)
                   if opt.name in given}
    params = applicable(given, chosen.options, f"--as {args.kind}")
    source = _bake_source(args.input) if source is None else source
    try:
        with progress_bar(f"baking {args.kind}", 1) as advance:
            return bake(source, args.kind, progress=advance, compress=compression, **params)
    except ReliefkitError as exc:  # what the bake refuses of this input: name it
        if str(args.input) in str(exc):
            raise
        raise type(exc)(f"{args.input}: {exc}") from None


def cmd_bake(args) -> int:
    if Path(args.output).suffix.lower() != ".rk":
        raise UsageError(f"output must be an .rk file, got {args.output}")
    check_writable(args.output, "-o")
    rep = _bake_input(args)
    source_hash = key = None
    if Path(args.input).is_file():  # a batch over the same file writes the same bytes
        source_hash = file_sha256(args.input)
        key = file_cache_key(args.input, args.kind, given_options(args))
    save(args.output, rep, source_hash=source_hash, cache_key=key)
    gpu = _gpu_summary(rep)
    print(f"wrote {args.output}: {_arrays_summary(array_bytes(rep), args.output)}, "
          f"{format_bytes(Path(args.output).stat().st_size)} on disk{gpu}")
    if given_options(args).get("compress") == "bc" and not gpu:
        print(f"warning: --compress bc changed nothing: a {args.kind} has no colour, normal "
              "or height array that is compressed yet (docs/compact.md)", file=sys.stderr)
    for line in getattr(rep, "bake_report", lambda: [])():  # a technique's own figures
        print(line, file=sys.stderr if line.startswith("warning:") else sys.stdout)
    return 0


def cmd_batch(args) -> int:
    try:
        report = batch(args.inputs, args.kind, args.out, args.executor, workers=args.workers,
                       force=args.force, export=args.export, timeout=args.timeout,
                       max_memory=args.max_memory, address=args.address, sheet=args.sheet,
                       **given_options(args))
    except BatchInterrupted as stopped:
        done = stopped.report
        print(f"error: interrupted after {len(done.records)} of {done.total} assets "
              f"({len(done.ok)} baked); every output written is whole: rerun the same "
              "command to go on", file=sys.stderr)
        return EXIT_INTERRUPTED
    for line in report.summary():
        print(line, file=sys.stderr if line.startswith("warning:") else sys.stdout)
    print(f"wrote {Path(args.out) / JSONL_NAME}")
    return report.exit_status


def cmd_export(args) -> int:
    out = Path(args.output)
    if out.suffix.lower() not in (".glb", ".gltf"):
        raise UsageError(f"-o must name a .glb or .gltf file, got {args.output}")
    check_writable(args.output, "-o")
    if args.fallback_triangles < 2:
        raise UsageError(f"--fallback-triangles must be at least 2, got {args.fallback_triangles}")
    given = given_options(args)
    common = {"fallback_triangles": args.fallback_triangles,
              "embed_shaders": args.embed_shaders}
    if args.lod:
        if args.no_fallback:
            raise UsageError("--no-fallback does not apply to --lod: every LOD is shown "
                             "through its core mesh")
        mesh, kinds, reps = _bake_lods(args, given)
        source_hash = file_sha256(args.input) if Path(args.input).is_file() else None
        with waiting(f"measuring {len(reps)} LOD(s) against the mesh"):
            path, lods = export_lod(mesh, reps, out, source_hash=source_hash, names=kinds,
                                    **common)
        print("LODs from the most to the least accurate (each one's error: docs/gltf.md):")
        upper = 1.0
        for lod in lods:
            lower = lod["screen_coverage"]
            shown = (f"shown while it covers {lower:.3g} to {upper:.3g} of the screen's height"
                     if lower < upper else "never shown: the next LOD is as accurate")
            print(f"LOD {lod['level']}: {lod['kind']:<20} surface error "
                  f"{lod['surface_error']:.4g}, {shown}")
            upper = lower
    else:
        if given:
            flags = ", ".join("--" + k.replace("_", "-") for k in given)
            raise UsageError(f"bake options ({flags}) need --lod and a mesh; to export an "
                             ".rk baked with them, bake it with them first")
        rep = _load(args.input)
        source_hash, key = _provenance_of(args.input)
        with waiting(f"exporting {what_it_is(args.input, rep)}"):
            path = export(rep, out, fallback=not args.no_fallback, source_hash=source_hash,
                          cache_key=key, **common)
    print(f"wrote {path}: {format_bytes(_written_bytes(path))}")
    return 0


def _provenance_of(spec: str) -> tuple[str | None, str | None]:
    """The source hash and cache key an .rk (or a glTF reliefkit exported) records, so its
    export records them too; None for what it lacks."""
    suffix = Path(spec).suffix.lower()
    if suffix == ".rk":
        manifest = read_manifest(spec)
    elif suffix in (".glb", ".gltf") and gltf_representation.exported_by_reliefkit(spec):
        manifest = gltf_representation.read_manifest(spec)
    else:
        return None, None
    return manifest.get("source_hash"), manifest.get("cache_key")


def _bake_lods(args, given: dict):
    table = bakers()
    kinds = [k.strip() for k in args.lod.split(",") if k.strip()]
    unknown = [k for k in kinds if k not in table]
    if not kinds or unknown:
        what = f"unknown {', '.join(unknown)}" if unknown else f"got {args.lod!r}"
        raise UsageError(f"--lod takes representations from {', '.join(table)} ({what})")
    compression = {opt.name: given.pop(opt.name) for opt in options_of(CompressOptions)
                   if opt.name in given}
    declared = {opt.name for k in kinds for opt in table[k][1].options}
    stray = [k for k in given if k not in declared]
    if stray:
        raise UsageError(f"{', '.join('--' + k.replace('_', '-') for k in stray)} applies to "
                         f"none of --lod {args.lod}")
    source = _bake_source(args.input, "export --lod")
    if kind_of(source) != "mesh":
        raise UsageError(f"export --lod needs a mesh (a mesh file or demo:NAME), not "
                         f"{what_it_is(args.input, source)}")
    reps = []
    for kind in kinds:
        params = applicable({k: v for k, v in given.items()
                             if k in {o.name for o in table[kind][1].options}},
                            table[kind][1].options, f"--lod {kind}")
        with progress_bar(f"baking {kind}", 1) as advance:
            reps.append(bake(source, kind, progress=advance, compress=compression, **params))
    return source, kinds, reps


def _written_bytes(path: Path) -> int:
    """Bytes of an export: the .glb, or a .gltf with its .bin and image files."""
    if path.suffix.lower() != ".gltf":
        return path.stat().st_size
    stem = path.stem
    return sum(p.stat().st_size for p in path.parent.iterdir()
               if p == path or p.name == f"{stem}.bin"
               or (p.name.startswith(f"{stem}_") and p.suffix == ".png"))


def _gpu_summary(rep) -> str:
    """``; on the GPU RAW -> COMPACT`` for a compressed representation, else nothing."""
    sizes = gpu_bytes(rep).values()
    if all(fmt == "raw" for fmt, _, _ in sizes):
        return ""
    return (f"; on the GPU {format_bytes(sum(raw for _, _, raw in sizes))} raw -> "
            f"{format_bytes(sum(gpu for _, gpu, _ in sizes))} compact")


def _arrays_summary(sizes: dict[str, int], path: str, shown: int = 3) -> str:
    """``N arrays, TOTAL (the largest ...)``: a cube's or a cloud's dozens of arrays in one
    short line; `reliefkit info` lists every one."""
    import shlex

    largest = sorted(sizes.items(), key=lambda item: -item[1])[:shown]
    named = ", ".join(f"{name} {format_bytes(n)}" for name, n in largest)
    total = f"{len(sizes)} array{'s' if len(sizes) != 1 else ''}, " \
            f"{format_bytes(sum(sizes.values()))}"
    if len(sizes) <= shown:
        return f"{total} ({named})"
    return f"{total} (the largest: {named}; `reliefkit info {shlex.quote(path)}` lists all)"


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
    return DirectionalLight.from_angles(*parse_light(args.light))


def _warn_nothing_visible(what: str) -> None:
    """A picture with nothing in it is written, but never silently (exit status 0 still)."""
    print(f"warning: {what} 0 pixels: nothing visible (check --view, --fov, the input's "
          "bounds and its materials' opacity)", file=sys.stderr)


def _print_frame_warnings(per_frame: list, noun: str = "") -> None:
    """What the drawables said of the pictures (`Frame.warnings`), one ``warning:`` line
    each: of a single picture all; of a sequence (``noun`` "view" or "frame") the first
    picture's, and how many others have some."""
    warned = [(k, lines) for k, lines in enumerate(per_frame) if lines]
    if not warned:
        return
    first, lines = warned[0]
    for line in lines:
        print(f"warning: {noun} {first + 1}: {line}" if noun else f"warning: {line}",
              file=sys.stderr)
    if len(warned) > 1:
        print(f"warning: {len(warned) - 1} more of the {len(per_frame)} {noun}s have "
              "warnings like this", file=sys.stderr)


def cmd_render(args) -> int:
    az, el, dist = parse_view(args.view)
    size = parse_size(args.size)
    check_fov(args.fov)
    background = _background(args.background)
    light = _light(args)
    _check_render_outputs(args)
    _check_not_empty(args.input)
    obj = _load(args.input)
    options = applicable(given_options(args), render_options(obj),
                          what_it_is(args.input, obj))

    def draw(camera, msaa=args.msaa, **core):
        return render(obj, camera, light=light, msaa=msaa, **core, **options)

    if args.turntable is not None:
        def views(cameras):  # one upload for every view (`render.Scene`)
            with Scene(obj, **options) as scene:
                for camera in cameras:
                    yield scene.frame(camera, light, msaa=args.msaa)

        return _render_turntable(args, framing_bounds(obj), views, el, dist, size, background)
    camera = orbit_bounds(framing_bounds(obj), az, el, dist, size, args.fov)
    if args.animate is not None:
        return _render_animation(args, obj, camera, draw, background)

    with waiting("render"):  # silent unless it takes long (a peeled shell: 46 s)
        frame = draw(camera)
        counted = draw(camera, msaa=1, count_iterations=True) if args.stats else None
    _write_render_outputs(args, frame, counted, background)
    print(f"wrote {args.output} ({size[0]}x{size[1]}, {frame.stats['covered']} pixels covered)")
    if frame.stats["covered"] == 0:
        _warn_nothing_visible("the render covers")
    _print_frame_warnings([frame.warnings])
    for path in (args.aovs, args.stats):
        if path:
            print(f"wrote {path}")
    return 0


def _write_render_outputs(args, frame, counted, background) -> None:
    """The picture, --aovs and --stats: all of them or, if one cannot be written, none."""
    with written_together():
        frame.save(args.output, background)
        if args.aovs:
            frame.save_aovs(args.aovs)
        if args.stats:
            _write_stats(args, frame, counted)


def _check_render_outputs(args) -> None:
    """The output names fit what is written; per-frame outputs do not go with --turntable
    or --animate."""
    suffix = Path(args.output).suffix.lower()
    if args.turntable is not None and args.animate is not None:
        raise UsageError("--turntable and --animate both write an animation: give one of them")
    sequence = "--turntable" if args.turntable is not None else \
        "--animate" if args.animate is not None else None
    if sequence:
        count = args.turntable if args.turntable is not None else args.animate
        if not 1 <= count <= MAX_FRAMES:
            raise UsageError(f"{sequence} takes 1..{MAX_FRAMES} frames, got {count}")

        check_animation_output(args.output, parse_size(args.size), count)
        given = [flag for flag, value in (("--aovs", args.aovs), ("--stats", args.stats))
                 if value]
        if given:
            raise UsageError(f"{' and '.join(given)} {'does' if len(given) == 1 else 'do'} not "
                             f"apply to {sequence} (one frame's arrays and counters): render "
                             "a single --view for them")
    else:
        check_writable(args.output, "-o")  # a folder or a name ending in '/' is named so
    if not sequence and (suffix != ".png" or is_animation_name(args.output)):
        hint = (": an animation (.gif, .png/.apng, .webp, .mp4 or a PNG per frame) needs "
                "--turntable N or --animate N" if is_animation_name(args.output) else "")
        raise UsageError(f"output must be a .png file, got {args.output}{hint}")
    if args.stats and Path(args.stats).suffix.lower() != ".json":
        raise UsageError(f"--stats writes JSON: name the file *.json, got {args.stats}")
    if args.aovs and Path(args.aovs).suffix.lower() != ".npz":
        raise UsageError(f"--aovs writes NumPy arrays: name the file *.npz, got {args.aovs}")
    for flag, value in (("--aovs", args.aovs), ("--stats", args.stats)):
        if value:
            check_writable(value, flag)


def _render_turntable(args, bounds, views, elevation, distance, size, background) -> int:
    """``args.turntable`` views (``views(cameras)`` yields their Frames) into an animation,
    warning about empty views."""
    cameras = turntable(bounds, args.turntable, elevation, distance, size, args.fov)
    with closing(views(cameras)) as frames:
        empty, warned, written = _stream_frames(args.output, "turntable", frames,
                                                len(cameras), background)
    print(f"wrote {written} ({len(cameras)} views)")
    if empty:
        many = len(empty) > 1
        _warn_nothing_visible(f"view{'s' if many else ''} {', '.join(empty)} of "
                              f"{len(cameras)} cover{'' if many else 's'}")
    _print_frame_warnings(warned, "view")
    return 0


def _render_animation(args, obj, camera, draw, background) -> int:
    """``args.animate`` frames of ``obj``'s animation (its ``time`` render option)."""
    if ANIMATION_TIME not in {opt.name for opt in render_options(obj)}:
        raise UsageError(f"--animate: {what_it_is(args.input, obj)}, has no animation "
                         "(no --time option); use --turntable for views around it")
    if given_options(args).get(ANIMATION_TIME) is not None:
        raise UsageError("--animate sets the time of each frame itself: leave out --time")
    count = args.animate
    frames = (draw(camera, **{ANIMATION_TIME: k / count}) for k in range(count))
    _, warned, written = _stream_frames(args.output, "animate", frames, count, background)
    print(f"wrote {written} ({count} frames)")
    _print_frame_warnings(warned, "frame")
    return 0


def _stream_frames(path, description: str, frames, count: int, background):
    """Draw ``frames`` (an iterator of ``count`` Frames) into the animation at ``path`` one
    at a time, with progress, so streamed formats hold one frame at a time; returns the
    numbers (from 1) of the frames that cover no pixel, each frame's warnings and what was
    written."""
    empty, warned = [], []
    over = frame_background(path, background)
    with progress_bar(description, count) as advance:
        def picture(k: int, frame):
            if frame.stats["covered"] == 0:
                empty.append(str(k + 1))
            warned.append(frame.warnings)
            advance(k + 1)
            return frame.rgba8(over)

        written = save_animation(itertools.starmap(picture, enumerate(frames)), path, count)
    return empty, warned, written


def _write_stats(args, frame, counted) -> None:
    """The plain frame's counters plus the instrumented pass's (fragments, iterations)."""
    stats = {"input": args.input, "size": list(frame.size), "view": args.view,
             **counted.stats, **frame.stats}
    with atomic_path(args.stats) as tmp:
        tmp.write_text(json.dumps(stats, indent=2) + "\n")


def cmd_compare(args) -> int:
    az, el, dist = parse_view(args.view)
    size = parse_size(args.size)
    check_fov(args.fov)
    light = _light(args)

    check_writable(args.out, "--out", folder=True)
    mesh = _bake_source(args.input, "compare")
    rep = _bake_input(args, mesh)
    camera = orbit_bounds(mesh.bounds, az, el, dist, size, args.fov)
    result = _compare_with_progress(mesh, rep, camera, light)
    title = f"{mesh.name} as {args.kind}, view {args.view}"
    paths = write_comparison(result, Path(args.out), title)
    print(metrics_markdown(result, title))
    print("wrote " + ", ".join(str(p) for p in paths.values()))
    for name, frame in result["frames"].items():  # what each variant's drawables said
        for line in frame.warnings:
            print(f"warning: {name}: {line}", file=sys.stderr)
    return 0


def _compare_with_progress(mesh, rep, camera, light) -> dict:
    """`compare` with a progress line per variant (the mesh, then each available variant)."""
    tech = technique_of(rep)
    variants = [v for v in (tech.compare_variants if tech else ()) if v.available(rep)]
    with progress_bar("compare", len(variants) + 1) as advance:
        return compare(mesh, rep, camera, light=light, progress=advance)


def cmd_bench(args) -> int:
    check_writable(args.out, "--out", folder=True)
    if args.mesh is not None:
        _check_mesh_file(args.mesh, "--mesh")
    report, paths = run_suite(args.name, quick=args.quick, out=Path(args.out), mesh=args.mesh,
                              size=args.size and parse_size(args.size), browser=args.browser)
    print(report)
    print("wrote " + ", ".join(map(str, paths)))
    return 0


def cmd_shootout(args) -> int:
    """Every argument checked and every mesh loaded before any work."""
    budgets, sizes = parse_budgets(args.budgets), parse_sizes(args.sizes)
    chosen = parse_kinds(args.kinds)
    check_writable(args.out, "--out", folder=True)
    for spec in args.meshes:
        if not spec.startswith(DEMO_PREFIX):
            _check_mesh_file(spec, "shootout")
    results, paths = shootout(load_meshes(args.meshes), chosen, budgets, sizes, Path(args.out))
    for mesh in results["meshes"]:
        for rec in mesh["recommendations"]:
            print(f"{mesh['name']}: {rec['line']}")
    print("wrote " + ", ".join(str(p) for p in paths))
    return 0


def cmd_info(args) -> int:
    if not args.gl and not args.file:
        raise UsageError("info needs --gl and/or a FILE")
    report = {}
    if args.gl:
        report["gl"] = gl_info()
    if args.file:
        report["file"] = _describe_file(args.file)
    if args.json:
        print(strict_json.dumps(report, indent=2))
    else:
        for section in report.values():
            _print_section(section)
    return 0


def _print_section(section: dict) -> None:
    """``key: value`` lines; an .rk's arrays one per line (dtype and shape, the format and
    bytes it has on the GPU against its raw bytes; ``--json`` also has their checksums and
    encodings), so a six-part cube reads as a list rather than a wall of JSON."""
    for key, value in section.items():
        if key == "arrays" and isinstance(value, dict):
            print(f"{key:>24}: {len(value)}")
            for name, record in value.items():
                record = record | record.get("encoding", {})  # an encoded one: as decoded
                shape = "x".join(map(str, record.get("shape", []))) or "scalar"
                gpu = record.get("gpu", {})
                on_gpu = f"  on the GPU {gpu['format']} {format_bytes(gpu['bytes'])} (raw " \
                         f"{format_bytes(gpu['raw_bytes'])})" if gpu else ""
                print(f"{name:>26}  {record.get('dtype')} {shape}{on_gpu}")
            continue
        shown = json.dumps(value) if isinstance(value, dict | list) else value
        print(f"{key:>24}: {shown}")


def _describe_file(spec: str) -> dict:
    """A mesh's counts and bounds, or an .rk file's manifest once every array is read and its
    checksum verified (so "checksums: ok" is only ever printed for a file that loads)."""
    _check_not_empty(spec)
    suffix = Path(spec).suffix.lower()
    exported = suffix in (".glb", ".gltf") and gltf_representation.exported_by_reliefkit(spec)
    if suffix == ".rk" or exported:
        # every check render makes: checksums, then the representation's own
        rep = gltf_representation.load(spec) if exported else load(spec)
        manifest = (gltf_representation.read_manifest if exported else read_manifest)(spec)
        for name, (fmt, gpu, raw) in gpu_bytes(rep).items():
            if name in manifest["arrays"]:
                manifest["arrays"][name]["gpu"] = {"format": fmt, "bytes": gpu, "raw_bytes": raw}
        return {**manifest, "checksums": "ok", "valid": "ok"}

    return describe(_load(spec))


def cmd_demo(args) -> int:
    size = parse_size(args.size)
    check_writable(args.out, "--out", folder=True)
    sheet = build_demo(Path(args.out), tile_size=size)
    print(f"wrote {sheet}")
    return 0



def cmd_view(args) -> int:
    if args.export_html and args.port is not None:
        raise UsageError("--port serves the page, --export-html writes it into a folder instead: "
                         "give one of them")
    port = 0 if args.port is None else args.port
    if not 0 <= port <= 65535:
        raise UsageError(f"--port must be within 0..65535, got {port}")
    for spec in args.inputs:
        _check_not_empty(spec)
    objects = [load_input(spec) for spec in args.inputs]
    routed = _routed_options(given_options(args), args.inputs, objects)
    with waiting("exporting the inputs"):
        inputs = [view_site.make_input(spec, obj, options) for spec, obj, options
                  in zip(args.inputs, objects, routed, strict=True)]
    if args.export_html:
        paths = view_site.export_html(view_site.site_files(inputs), args.export_html)
        print(f"wrote {len(paths)} files into {args.export_html} (index.html: serve the folder, "
              "e.g. python -m http.server -d " + shlex.quote(args.export_html) + ")")
        return 0
    view_server.serve(view_site.site_files(inputs, live=True), port,
                      open_browser=not args.no_browser, variants=Variants(inputs))
    return 0


def _routed_options(given: dict, specs, objects) -> list[dict]:
    """The render options each input gets: those of ``given`` it declares, checked; one that
    no input declares is an error (as `render` routes them to several drawables)."""
    declared = [{opt.name for opt in render_options(obj)} for obj in objects]
    unused = sorted(set(given) - set().union(*declared))
    if unused:
        flags = ", ".join("--" + name.replace("_", "-") for name in unused)
        raise UsageError(f"{flags} applies to none of the inputs")
    return [applicable({k: v for k, v in given.items() if k in names}, render_options(obj),
                       what_it_is(spec, obj))
            for spec, obj, names in zip(specs, objects, declared, strict=True)]
