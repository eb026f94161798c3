"""`render(obj, camera, **options)`: draws any representation (or several) into a Frame.

Each technique declares a `DrawableSpec` per representation class (its factory and the
dataclass of its render options); the core declares the mesh's. Several objects passed as a
list are drawn into one framebuffer: the opaque ones first (depth test and write), then the
transparent ones front to back (depth test against the opaque pass, no depth write, see
`reliefkit.gl.targets`). Render options are routed by name to every drawable that declares
one of that name and checked by that drawable's own declaration, so two techniques may both
have a ``method`` option with different choices; an option nobody declares is an error.
"""

from __future__ import annotations

import numpy as np

from ..core import params as _params
from ..core.technique import REGISTRY
from ..errors import UsageError


def _spec_for(obj):
    tech, spec = REGISTRY.drawable_spec(obj)
    if spec is None:
        known = [s.cls.__name__ for s in REGISTRY.drawable_specs()]
        raise UsageError(f"no renderer for {type(obj).__name__} (known: {', '.join(known)})")
    return (tech.name if tech else "mesh"), spec


def render_options(obj) -> tuple:
    """The render options ``obj``'s drawable declares (`reliefkit.core.params.Option`)."""
    return _spec_for(obj)[1].option_list


def make_drawables(ctx, objects, options: dict, *, instrument: bool = False) -> list:
    """Drawables for ``objects``, each given the options it declares; unknown options fail."""
    found = [_spec_for(obj) for obj in objects]
    declared = {opt.name for _, spec in found for opt in spec.option_list}
    unknown = sorted(set(options) - declared)
    if unknown:
        offered = ", ".join(sorted(declared)) or "none"
        raise UsageError(f"unknown render option(s) {', '.join(unknown)} for "
                         f"{', '.join(sorted({type(o).__name__ for o in objects}))} "
                         f"(options: {offered})")
    drawables = []
    try:
        for (owner, spec), obj in zip(found, objects, strict=True):
            mine = {k: v for k, v in options.items()
                    if k in {opt.name for opt in spec.option_list}}
            opts = _params.make(spec.options, mine, f"{owner} render option") \
                if spec.options is not None else None
            drawables.append(spec.factory(ctx, obj, opts, instrument))
    except BaseException:
        release_all(drawables)
        raise
    return drawables


def release_all(drawables) -> None:
    for drawable in drawables:
        release = getattr(drawable, "release", None)
        if release:
            release()


def render(obj, camera, *, light=None, ctx=None, count_iterations: bool = False,
           msaa: int = 1, **options):
    """Render a representation, a RenderMesh (ground truth), or a list of them, into a Frame.

    ``count_iterations`` draws the instrumented variants and fills ``frame.stats`` with
    fragments and loop iterations per pixel (``frame.extra["iterations"]``). ``msaa`` (1, 2,
    4 or 8 samples) draws the opaque objects once more, multisampled, for the colour only:
    edge pixels get the covered fraction as alpha, every AOV stays single-sample, and
    transparent objects are composited single-sample over it.
    """
    from ..gl.context import get_context
    from ..gl.targets import check_msaa, draw_passes
    from ..scene.light import DirectionalLight
    from .frame import frame_from_passes

    objects = list(obj) if isinstance(obj, list | tuple) else [obj]
    if not objects:
        raise UsageError("nothing to render")
    ctx = ctx or get_context()
    light = light or DirectionalLight()
    check_msaa(ctx, msaa)
    drawables = make_drawables(ctx, objects, options, instrument=count_iterations)
    try:
        opaque = [d for d in drawables if not getattr(d, "transparent", False)]
        transparent = sorted((d for d in drawables if getattr(d, "transparent", False)),
                             key=lambda d: _front_distance(d, camera))
        extra = max((getattr(d, "extra_attachments", 0) for d in opaque), default=0)

        def draw_opaque():
            for drawable in opaque:
                drawable.draw(camera, light)

        images = draw_passes(ctx, camera.size, draw_opaque,
                             [lambda d=d: d.draw(camera, light) for d in transparent],
                             extra_attachments=extra, msaa=msaa)
        frame = frame_from_passes(camera, images)
        if images.msaa_color is not None:
            frame.color = _multisampled_frame_color(camera, images)
        frame.stats["covered"] = int(frame.mask.sum())
        if count_iterations and extra:
            _iteration_stats(frame, images.extra[0])
        for drawable in drawables:
            finish = getattr(drawable, "finish", None)
            if finish:
                finish(frame)
        return frame
    finally:
        release_all(drawables)


def _multisampled_frame_color(camera, images) -> np.ndarray:
    """The Frame's colour with the multisampled opaque colour in place of the single-sample
    one, transparent layers composited over it by `frame_from_passes` itself (one copy of the
    compositing); only its colour is kept, the AOVs are the single-sample pass's."""
    from dataclasses import replace

    from .frame import frame_from_passes

    color = images.msaa_color
    position = images.position.copy()
    position[..., 3] = np.where(color[..., 3] > 0, 1.0, 0.0)  # any covered sample counts
    return frame_from_passes(camera, replace(images, color=color, position=position)).color


def _front_distance(drawable, camera) -> float:
    """Sort key of transparent drawables: distance of their nearest bound from the eye."""
    key = getattr(drawable, "sort_distance", None)
    return float(key(camera)) if key else 0.0


def _iteration_stats(frame, counts: np.ndarray) -> None:
    """Counters of shaders/include/iterations.glsl: (primary, secondary, ran, hit)."""
    ran = counts[..., 2] > 0.5
    covered = frame.mask
    primary, secondary = counts[..., 0], counts[..., 1]
    frame.stats.update({
        "fragments": int(ran.sum()),
        "iterations_mean": float(primary[ran].mean()) if ran.any() else 0.0,
        "iterations_max": int(primary[ran].max()) if ran.any() else 0,
        "iterations_mean_covered": float(primary[covered].mean()) if covered.any() else 0.0,
        "secondary_iterations_mean": float(secondary[covered].mean()) if covered.any()
        else 0.0,
    })
    frame.extra["iterations"] = np.where(ran, primary, np.nan).astype(np.float32)
