"""`Part`: what one half of the slicing technique contributes (the displacement maps of §3,
the depth objects and visual hulls of §4-§5); `__init__` merges the halves into the one
`Technique` record, so each half lives in its own modules."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field


@dataclass(frozen=True)
class Part:
    codecs: tuple = ()
    representations: tuple = ()
    bakers: tuple = ()
    drawables: tuple = ()
    compare_variants: tuple = ()
    compare_metrics: tuple = ()
    programs: tuple = ()
    demo_tiles: Callable[[], list] | None = None
    samples: Callable[[], dict] | None = None
    cli_examples: dict = field(default_factory=dict)
