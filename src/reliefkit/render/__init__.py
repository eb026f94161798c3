"""Renderers, one per representation, found by `render(representation, camera)`."""

from .frame import Frame
from .registry import register_renderer, render


def load_renderers() -> None:
    """Import every renderer module so each registers itself."""
    from . import mesh, relief  # noqa: F401


__all__ = ["Frame", "render", "register_renderer", "load_renderers"]
