"""`render(representation, camera, **options)`: finds the renderer registered for its type."""

from __future__ import annotations

from collections.abc import Callable

from ..errors import UsageError

_renderers: dict[type, Callable] = {}


def register_renderer(cls: type, fn: Callable) -> None:
    """Make ``render`` call ``fn(rep, camera, **options)`` for instances of ``cls``."""
    _renderers[cls] = fn


def render(representation, camera, **options):
    """Render any representation (or a RenderMesh as ground truth) into a Frame."""
    from . import load_renderers

    load_renderers()
    for cls in type(representation).__mro__:
        if cls in _renderers:
            return _renderers[cls](representation, camera, **options)
    known = ", ".join(sorted(c.__name__ for c in _renderers))
    raise UsageError(f"no renderer for {type(representation).__name__} (known: {known})")
