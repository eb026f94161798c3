"""`render(obj, camera)`: any representation (or several), from one camera or many, into
Frames; `Scene`: objects uploaded once and drawn from any number of cameras.

Several objects are drawn into one framebuffer: the opaque ones first (depth test and
write), then the transparent ones front to back (depth test against the opaque pass, no
depth write, see `reliefkit.gl.targets`). Each drawable describes what it draws as draw
plans (`render.plan`); the one `render.executor.Executor` uploads them once and draws them
per camera, so a list of cameras costs one upload.
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from ..errors import UsageError
from ..gl.context import get_context, using
from ..gl.targets import check_msaa, draw_passes
from ..scene.light import DirectionalLight
from .executor import Executor
from .frame import frame_from_passes
from .instancing import InstancedDrawable
from .registry import make_drawables


class Scene:
    """``objects`` as drawables with ``options`` routed by name, uploaded once into ``ctx``
    (default: the context in force, `get_context`; one handed in must be current while the
    scene uploads and draws: inside `reliefkit.gl.context.using`, as `render` does);
    `frame(camera)` draws them. With ``instances`` ((N, 5) placements, `render.instancing`)
    each object is drawn at every placement, one draw call per plan. Use it as a context
    manager (or call `release`)."""

    def __init__(self, objects, *, ctx=None, count_iterations: bool = False, instances=None,
                 **options):
        self.objects = list(objects) if isinstance(objects, list | tuple) else [objects]
        if not self.objects:
            raise UsageError("nothing to render")
        self.ctx = ctx or get_context()
        self.count_iterations = count_iterations
        self.executor = Executor(self.ctx)
        self.drawables = make_drawables(self.objects, options, instrument=count_iterations)
        if instances is not None:
            self.drawables = [InstancedDrawable(d, instances) for d in self.drawables]
        try:
            for drawable in self.drawables:
                self.executor.upload(drawable.plans)
        except BaseException:
            self.release()
            raise

    def __enter__(self) -> Scene:
        return self

    def __exit__(self, *exc) -> None:
        self.release()

    def release(self) -> None:
        self.executor.release()

    @property
    def extra_attachments(self) -> int:
        return max((getattr(d, "extra_attachments", 0) for d in self.drawables
                    if not _transparent(d)), default=0)

    def draw(self, drawable, camera, light, stats: dict) -> None:
        """One drawable into the bound framebuffer; its view hooks' and multi-pass kinds'
        statistics into ``stats``, and for a drawable that asks (``timed``) ``draw_seconds``:
        the wall time of its draw calls, hooks included (not the GPU's: llvmpipe draws as it
        is called, a GPU later)."""
        start = time.perf_counter()
        for plan in drawable.plans:
            stats.update(self.executor.draw(plan, camera, light))
        if getattr(drawable, "timed", False):
            stats["draw_seconds"] = time.perf_counter() - start

    def draw_opaque(self, camera, light) -> None:
        """The opaque drawables into the bound framebuffer (what benchmarks time)."""
        for drawable in self.drawables:
            if not _transparent(drawable):
                self.draw(drawable, camera, light, {})

    def frame(self, camera, light=None, *, msaa: int = 1):
        """The Frame of every object from ``camera`` (see `render`)."""
        light = light or DirectionalLight()
        check_msaa(self.ctx, msaa)
        stats = {id(d): {} for d in self.drawables}
        opaque = [d for d in self.drawables if not _transparent(d)]
        transparent = sorted((d for d in self.drawables if _transparent(d)),
                             key=lambda d: _front_distance(d, camera))

        def draw_opaque():
            for drawable in opaque:
                self.draw(drawable, camera, light, stats[id(drawable)])

        images = draw_passes(
            self.ctx, camera.size, draw_opaque,
            [lambda d=d: self.draw(d, camera, light, stats[id(d)]) for d in transparent],
            extra_attachments=self.extra_attachments, msaa=msaa)
        frame = frame_from_passes(camera, images)
        if images.msaa_color is not None:
            frame.color = _multisampled_frame_color(camera, images)
        frame.stats["covered"] = int(frame.mask.sum())
        if self.count_iterations and self.extra_attachments:
            _iteration_stats(frame, images.extra[0])
        for drawable in self.drawables:
            finish = getattr(drawable, "finish", None)
            if finish is not None:
                finish(frame, stats[id(drawable)])
        return frame


def render(obj, camera, *, light=None, ctx=None, count_iterations: bool = False,
           msaa: int = 1, instances=None, **options):
    """Render a representation, a RenderMesh (ground truth), or a list of them, into a Frame;
    with a list (or any iterable) of cameras, into a list of Frames, uploading once
    (bit-identical to one `render` per camera).

    ``count_iterations`` draws the instrumented variants and fills ``frame.stats`` with
    fragments and loop iterations per pixel (``frame.extra["iterations"]``). ``msaa`` (1, 2,
    4 or 8 samples) draws the opaque objects once more, multisampled, for the colour only:
    edge pixels get the covered fraction as alpha, every AOV stays single-sample, and
    transparent objects are composited single-sample over it. ``instances`` ((N, 5)
    placements) draws each object at every placement in one draw call per plan
    (`render.instancing`; `NotInstanceable` says why an object cannot be). ``ctx``: a
    moderngl context to draw on instead of the process-wide one (made current for the
    draw, `reliefkit.gl.context.using`).
    """
    several = not hasattr(camera, "size")  # a list, tuple or any iterable of cameras
    try:
        cameras = list(camera) if several else [camera]
    except TypeError:
        raise UsageError(f"render needs a camera or a list of cameras, got "
                         f"{type(camera).__name__}") from None
    if not cameras or not all(hasattr(c, "size") for c in cameras):
        raise UsageError("render needs a camera or a non-empty list of cameras")
    with using(ctx):  # a given context made current for the draw, the one before after
        ctx = get_context()
        check_msaa(ctx, msaa)
        with Scene(obj, ctx=ctx, count_iterations=count_iterations, instances=instances,
                   **options) as scene:
            frames = [scene.frame(cam, light, msaa=msaa) for cam in cameras]
    return frames if several else frames[0]


def _transparent(drawable) -> bool:
    return any(plan.render_pass == "transparent" for plan in drawable.plans)


def _multisampled_frame_color(camera, images) -> np.ndarray:
    """The Frame's colour with the multisampled opaque colour in place of the single-sample
    one, transparent layers composited over it by `frame_from_passes` itself (one copy of the
    compositing); only its colour is kept, the AOVs are the single-sample pass's."""
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
