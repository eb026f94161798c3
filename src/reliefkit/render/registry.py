"""`render(obj, camera, **options)`: draws any representation (or several) into a Frame.

Each renderer registers a *drawable factory* for its representation type: a callable
``factory(ctx, obj, **options)`` returning an object with ``draw(camera, light)`` and, when
it must adjust the read-back Frame, ``finish(frame)``. Several objects passed as a list are
drawn into one framebuffer, so depth testing between them is real (used for the depth modes).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from ..errors import UsageError


@dataclass(frozen=True)
class _Entry:
    factory: Callable
    options: frozenset


_drawables: dict[type, _Entry] = {}


def register_renderer(cls: type, factory: Callable, options=()) -> None:
    """Draw instances of ``cls`` with ``factory(ctx, obj, **opts)``; ``options`` are the
    keyword arguments it accepts."""
    _drawables[cls] = _Entry(factory, frozenset(options))


def _entry(obj) -> _Entry:
    for cls in type(obj).__mro__:
        if cls in _drawables:
            return _drawables[cls]
    known = ", ".join(sorted(c.__name__ for c in _drawables))
    raise UsageError(f"no renderer for {type(obj).__name__} (known: {known})")


def make_drawables(ctx, objects, options: dict) -> list:
    """Drawables for ``objects``, each given the options it accepts; unknown options fail."""
    from . import load_renderers

    load_renderers()
    entries = [_entry(obj) for obj in objects]
    unknown = set(options) - set().union(*(e.options for e in entries))
    if unknown:
        raise UsageError(f"unknown render option(s): {', '.join(sorted(unknown))}")
    return [e.factory(ctx, obj, **{k: v for k, v in options.items() if k in e.options})
            for e, obj in zip(entries, objects, strict=True)]


def render(obj, camera, *, light=None, ctx=None, **options):
    """Render a representation, a RenderMesh (ground truth), or a list of them, into a Frame."""
    from ..gl.context import get_context
    from ..scene.light import DirectionalLight
    from .targets import draw_into_frame

    ctx = ctx or get_context()
    objects = list(obj) if isinstance(obj, list | tuple) else [obj]
    if not objects:
        raise UsageError("nothing to render")
    drawables = make_drawables(ctx, objects, options)
    light = light or DirectionalLight()
    extra = max(getattr(d, "extra_attachments", 0) for d in drawables)

    def draw_all():
        for drawable in drawables:
            drawable.draw(camera, light)

    frame = draw_into_frame(ctx, camera, draw_all, extra_attachments=extra)
    for drawable in drawables:
        finish = getattr(drawable, "finish", None)
        if finish:
            finish(frame)
    for drawable in drawables:
        release = getattr(drawable, "release", None)
        if release:
            release()
    return frame
