"""The drawables of representations: each technique declares a `DrawableSpec` per
representation class (its factory and the dataclass of its render options); the core
declares the mesh's. Render options are routed by name to every drawable that declares one
of that name and checked by that drawable's own declaration, so two techniques may both have
a ``method`` option with different choices; an option nobody declares is an error.
`render.draw.render` draws them.
"""

from __future__ import annotations

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


def make_drawables(objects, options: dict, *, instrument: bool = False) -> list:
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
    for (owner, spec), obj in zip(found, objects, strict=True):
        mine = {k: v for k, v in options.items() if k in {opt.name for opt in spec.option_list}}
        opts = _params.make(spec.options, mine, f"{owner} render option") \
            if spec.options is not None else None
        drawables.append(spec.factory(obj, opts, instrument))
    return drawables
