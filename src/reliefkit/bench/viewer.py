"""``reliefkit bench viewer``: the viewer page's frame time per kind, in headless Chromium.

Every kind the page draws, baked with its defaults from the first demo asset its baker takes
(`export.ASSETS` order: the vehicle, the shell volume the torus), and the meshes themselves as
the baseline, each alone in the page (`reliefkit view`'s site, served by its own server) at
``size``, driven around an orbit by ``window.reliefkit.setView``. Per input: the median and
fastest frame (the page's CPU clock around the draws and a one-pixel read back), the GPU
timer query's time where the browser has the extension, fps from the median, the ratio to
its asset's mesh in the same run, and what explains the cost on any device: the plans drawn,
the draw calls and vertices of a frame (instances included) and the texture bytes
uploaded. With ``--quick``: the vehicle's mesh and the first kind at 256 x 256, two views.
"""

from __future__ import annotations

import statistics
from pathlib import Path

from ..bake import bake
from ..errors import UsageError
from ..io.inputs import load_input
from ..units import format_bytes
from ..viewer.browser import chromium_path, launch, playwright, require_playwright
from ..viewer.server import serving
from ..viewer.site import make_input, site_files
from .export import ASSETS
from .kinds import mesh_kinds
from .report import machine, machine_line, write_report

SIZE, QUICK_SIZE = (1920, 1080), (256, 256)
ELEVATION = 20.0
VIEWS, QUICK_VIEWS = 12, 2  # azimuths evenly around the orbit
BASELINES = ("vehicle", "tree")  # meshes measured besides those the kinds are baked from
TARGET_FPS = 60.0
LOAD_TIMEOUT_MS = 600_000  # a page's load: its textures decoded and its first frame drawn
RENDERER_JS = """() => {
  const gl = document.querySelector('canvas').getContext('webgl2');
  const info = gl.getExtension('WEBGL_debug_renderer_info');
  return gl.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : gl.RENDERER);
}"""


def run_suite(quick: bool, out: Path, log, size: tuple[int, int] | None = None,
              browser: str = "swiftshader") -> tuple[str, list[Path]]:
    """The suite at ``size`` (None: 1920x1080, or 256x256 with ``quick``) on Chromium's
    ``browser`` backend (`viewer.browser.BACKENDS`)."""
    size = tuple(size or (QUICK_SIZE if quick else SIZE))
    chromium_path()  # what to install, said before anything is baked
    require_playwright()
    n = QUICK_VIEWS if quick else VIEWS
    azimuths = [360.0 * k / n for k in range(n)]
    rows, renderer = [], None
    with playwright() as p:
        chrome = launch(p, browser)
        try:
            for asset, kind, spec, obj in _inputs(quick, log):
                if obj is None:
                    rows.append({"asset": asset, "kind": kind, "refused": spec})
                    continue
                log(f"{spec}: {kind} at {size[0]}x{size[1]}, {n} views")
                row, seen = _measure(chrome, spec, obj, size, azimuths)
                renderer = renderer or seen
                rows.append({"asset": asset, "kind": kind, **row})
                if kind == "mesh" and "error" in row:  # a frame size it refuses, say
                    raise UsageError(f"the viewer page: {row['error']}")
        finally:
            chrome.close()
    _add_ratios(rows)
    data = {"size": size, "elevation": ELEVATION, "azimuths": azimuths, "backend": browser,
            "webgl_renderer": renderer, "target_fps": TARGET_FPS, "machine": machine(),
            "rows": rows}
    return _markdown(data), write_report(out, "viewer", data, _markdown)


def _inputs(quick: bool, log):
    """(asset, kind, spec, object) per input, each baked when its turn comes: the baseline
    meshes, then each kind on the first asset its baker takes, after that asset's mesh
    where it is not a baseline ((asset, kind, why, None) where no asset is taken)."""
    meshes, shown = {}, set()

    def mesh(asset):
        if asset not in meshes:
            meshes[asset] = load_input(f"demo:{asset}")
        return meshes[asset]

    def baseline(asset):  # the asset's mesh row, once
        if asset not in shown:
            shown.add(asset)
            yield asset, "mesh", f"demo:{asset}", mesh(asset)

    for asset in BASELINES[:1] if quick else BASELINES:
        yield from baseline(asset)
    for kind in mesh_kinds()[:1] if quick else mesh_kinds():
        refusals = []
        for asset in ASSETS[:1] if quick else ASSETS:
            log(f"{asset}: baking {kind}")
            try:
                rep = bake(mesh(asset), kind)
            except UsageError as exc:  # a shell volume of a mesh without uvs, say
                refusals.append(f"{asset}: {exc}")
                continue
            yield from baseline(asset)
            yield asset, kind, f"demo:{asset} {kind}", rep
            break
        else:
            yield ASSETS[0], kind, "; ".join(refusals), None


def _measure(chrome, spec: str, obj, size, azimuths) -> tuple[dict, str | None]:
    """One input alone in the page: its frames around the orbit, counts and the renderer."""
    files = site_files([make_input(spec, obj)])
    lines: list[str] = []
    with serving(files, lines.append) as url:
        page = chrome.new_page(viewport={"width": size[0], "height": size[1]})
        try:
            page.goto(f"{url}?size={size[0]}x{size[1]}")
            page.wait_for_function("window.reliefkit && window.reliefkit.loaded",
                                   timeout=LOAD_TIMEOUT_MS)
            errors = page.evaluate("window.reliefkit.errors")
            if errors or not page.evaluate("window.reliefkit.ready"):
                return {"error": errors[0] if errors else "no frame drawn"}, None
            renderer = page.evaluate(RENDERER_JS)
            view = "([a, e]) => window.reliefkit.setView(a, e)"
            page.evaluate(view, [azimuths[-1], ELEVATION])  # a warm-up: not measured
            times = [page.evaluate(view, [az, ELEVATION]) for az in azimuths]
            counts = page.evaluate("window.reliefkit.counts[0]")
        finally:
            page.close()
    frame = [t["frameMs"] for t in times]
    gpu = [t["gpuMs"] for t in times if t["gpuMs"] is not None]
    median = statistics.median(frame)
    return {"frame_ms": frame, "gpu_ms": gpu, "median_ms": median, "fastest_ms": min(frame),
            "gpu_median_ms": statistics.median(gpu) if gpu else None,
            "fps": 1000.0 / median if median > 0 else None,
            "meets_target": median > 0 and 1000.0 / median >= TARGET_FPS,
            "plans": counts["plans"], "draw_calls": counts["drawCalls"],
            "vertices": counts["vertices"], "texture_bytes": counts["textureBytes"]}, renderer


def _add_ratios(rows: list[dict]) -> None:
    """Each measured row's median against its asset's mesh, measured in the same run."""
    mesh = {r["asset"]: r["median_ms"] for r in rows if r["kind"] == "mesh" and "median_ms" in r}
    for r in rows:
        if "median_ms" in r and mesh.get(r["asset"]):
            r["mesh_ratio"] = r["median_ms"] / mesh[r["asset"]]


def _ms(value) -> str:
    return "n/a" if value is None else f"{value:.1f} ms"


def _markdown(data: dict) -> str:
    w, h = data["size"]
    lines = [f"# The viewer page's frame time per kind ({w}x{h}, {len(data['azimuths'])} views "
             f"around the orbit at elevation {data['elevation']:g})", "",
             f"Browser: headless Chromium, backend {data['backend']}, WebGL renderer "
             f"{data['webgl_renderer'] or 'unknown'}.", machine_line(data["machine"]), "",
             "| asset | kind | median frame | fastest | GPU (timer query) | fps | x mesh | "
             f"{data['target_fps']:g} fps | plans | draw calls | vertices | texture bytes |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in data["rows"]:
        if "refused" in r or "error" in r:
            why = f"refused: {r['refused']}" if "refused" in r else f"error: {r['error']}"
            lines.append(f"| {r['asset']} | {r['kind']} | {why} | | | | | | | | | |")
            continue
        fps = "n/a" if r["fps"] is None else f"{r['fps']:.1f}"
        ratio = f"{r['mesh_ratio']:.2f}" if "mesh_ratio" in r else "n/a"
        lines.append(f"| {r['asset']} | {r['kind']} | {_ms(r['median_ms'])} | "
                     f"{_ms(r['fastest_ms'])} | {_ms(r['gpu_median_ms'])} | {fps} | {ratio} | "
                     f"{'yes' if r['meets_target'] else 'no'} | {r['plans']} | "
                     f"{r['draw_calls']} | {r['vertices']:,} | "
                     f"{format_bytes(r['texture_bytes'])} |")
    return "\n".join(lines) + "\n"
