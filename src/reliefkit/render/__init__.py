"""Rendering: `render(obj, camera)` into a `Frame`; the ground-truth mesh drawable; proxies."""

from .draw import Scene, render
from .frame import Frame
from .registry import make_drawables, render_options

__all__ = ["Frame", "Scene", "render", "make_drawables", "render_options"]
