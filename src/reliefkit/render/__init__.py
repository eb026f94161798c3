"""Rendering: `render(obj, camera)` into a `Frame`; the ground-truth mesh drawable; proxies."""

from .frame import Frame
from .registry import make_drawables, render, render_options

__all__ = ["Frame", "render", "make_drawables", "render_options"]
