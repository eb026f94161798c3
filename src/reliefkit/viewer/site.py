"""The viewer's static site: the page (static/index.html), its bundle (static/viewer.js,
built from web/src/ by web/build.mjs), one GLB per input, exported in memory with its
shaders, and inputs.json, which names them with their kind and framing bounds and carries
the camera's and the light's defaults the page shares with `reliefkit render`, and each
input's render options (their declarations and the values its GLB was made with), from which
the page builds its controls.

Everything the page computes per view comes from these files, so the folder that
`export_html` writes is viewable from any static web server.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path, PurePath

from ..errors import UsageError
from ..export.gltf import export_bytes
from ..gl.shaders import stage_sources
from ..io.atomic import atomic_path, written_together
from ..io.inputs import kind_of, load_input
from ..metrics import heat_ramp_stops
from ..render import render_options
from ..scene.light import DEFAULT_LIGHT_ANGLES, DirectionalLight
from ..scene.views import DEFAULT_FOV, DEFAULT_SIZE, DEFAULT_VIEW, FIT_MARGIN, framing_bounds

PAGE_FILES = ("index.html", "viewer.js")


@dataclass(frozen=True)
class Input:
    """One input as the page gets it; ``obj`` (the loaded input) and the render ``options``
    its GLB was made with let the server make it again with others."""

    name: str
    kind: str
    glb: bytes
    bounds: list
    obj: object = None
    options: dict = field(default_factory=dict)


def load_inputs(specs) -> list[Input]:
    """Each input (``.rk``, a reliefkit ``.glb``, a mesh file, ``demo:NAME``) loaded and
    made an `Input` with its render defaults."""
    if not specs:
        raise UsageError("view needs at least one input")
    return [make_input(spec, load_input(spec)) for spec in specs]


def make_input(spec: str, obj, options: dict | None = None) -> Input:
    """``obj`` (loaded from ``spec``) exported in memory with its draw plans, made with the
    render ``options`` it declares (checked by the caller), and their GLSL ES sources; no
    fallback mesh: the page draws the plans (and, where it counts them, the iteration-counting
    plans of its heat map)."""
    return Input(str(spec), kind_of(obj), glb_of(obj, options), framing_bounds(obj).tolist(),
                 obj, dict(options or {}))


def glb_of(obj, options: dict | None) -> bytes:
    """``obj``'s GLB as the page draws it: its plans made with ``options``, their sources
    and the iteration-counting plans (the heat map)."""
    return export_bytes(obj, fallback=False, embed_shaders=True, options=options,
                        instrumented=True)


def option_controls(item: Input) -> list[dict]:
    """The render options ``item`` declares (`render_options`: what the CLI's flags are made
    of), each with the value its GLB was made with: the page's controls are built from them."""
    if item.obj is None:
        return []
    return [{"name": opt.name, "flag": opt.flag, "kind": opt.kind, "choices": opt.choices,
             "lo": opt.lo, "hi": opt.hi, "count": opt.count, "default": opt.default,
             "help": opt.help, "value": item.options.get(opt.name, opt.default)}
            for opt in render_options(item.obj)]


#: The page's own programs (the picture or a debug view it shows, the opaque depth it
#: copies), in the core shader namespace: built as GLSL ES by the shader loader like every
#: plan's program, with the defines each takes.
PAGE_PROGRAMS = {
    "present": ("core:viewer/present.glsl", {"HEAT_RAMP_STOPS": len(heat_ramp_stops())}),
    "copy_depth": ("core:viewer/copy_depth.glsl", {})}


def page_programs() -> dict:
    """Each of `PAGE_PROGRAMS` as its GLSL ES vertex and fragment sources."""
    out = {}
    for key, (name, defines) in PAGE_PROGRAMS.items():
        sources = stage_sources(name, defines, es=True)
        out[key] = {"name": name, "defines": defines, "vertex": sources["vertex_shader"],
                    "fragment": sources["fragment_shader"]}
    return out


def manifest(inputs: list[Input], live: bool = False) -> dict:
    """inputs.json: the inputs with their render options, the page's own programs and the
    defaults of `reliefkit render` the page uses (camera, light, the heat ramp of
    `reliefkit.metrics`); ``live``: a server makes each input again
    with other options (`viewer.variants`), which a static export cannot."""
    light = DirectionalLight().uniforms()
    light.pop("u_light_dir")  # the page computes it from the angles (`--light`)
    az, el, _ = DEFAULT_VIEW
    return {"live": live,
            "inputs": [{"name": i.name if live else _published(i.name), "kind": i.kind,
                        "file": _glb_name(k),
                        "bounds": i.bounds, "options": option_controls(i)}
                       for k, i in enumerate(inputs)],
            "camera": {"default_view": f"{az:g},{el:g}",
                       "default_size": f"{DEFAULT_SIZE[0]}x{DEFAULT_SIZE[1]}",
                       "fov": DEFAULT_FOV, "fit_margin": FIT_MARGIN},
            "light": {"angles": ",".join(f"{a:g}" for a in DEFAULT_LIGHT_ANGLES),
                      "uniforms": light},
            "programs": page_programs(),
            # the debug views' heat ramp (metrics.heat_ramp), u_heat_ramp of present.glsl
            "heat_ramp": heat_ramp_stops().tolist()}


def site_files(inputs: list[Input], live: bool = False) -> dict[str, bytes]:
    """Every file of the site by its name (``live``: see `manifest`)."""
    static = resources.files(__package__) / "static"
    files = {name: (static / name).read_bytes() for name in PAGE_FILES}
    files["inputs.json"] = json.dumps(manifest(inputs, live), indent=1).encode()
    files.update({_glb_name(k): i.glb for k, i in enumerate(inputs)})
    return files


def export_html(files: dict[str, bytes], folder) -> list[Path]:
    """Write the site into ``folder`` (created), all files or none; their paths. The input
    GLBs of an earlier export into the same folder that this one does not write go (a
    site of fewer inputs left the others' megabytes behind)."""
    folder = Path(folder)
    if folder.exists() and not folder.is_dir():
        raise UsageError(f"--export-html {folder}: exists and is not a folder")
    folder.mkdir(parents=True, exist_ok=True)
    paths = [folder / name for name in files]
    stale = [p for p in folder.glob("input-*.glb")
             if _GLB_NAME.fullmatch(p.name) and p.name not in files] \
        if (folder / "inputs.json").is_file() else []
    with written_together():
        for path in paths:
            with atomic_path(path) as tmp:
                Path(tmp).write_bytes(files[path.name])
    for path in stale:
        path.unlink(missing_ok=True)
    return paths


_GLB_NAME = re.compile(r"input-\d+\.glb")


def _published(name: str) -> str:
    """An input's name as a static export shows it: a file's name without the folders of
    the machine it was exported on."""
    return name if name.startswith("demo:") else PurePath(name).name


def _glb_name(index: int) -> str:
    return f"input-{index}.glb"
