"""Exact CPU references shared by several techniques (the core; a technique imports them,
they import no technique).

`heightfield`: the exact ray vs bilinear-patch heightfield intersection (docs/architecture.md,
"Heightfields"), the reference of the relief walks and of displacement-mapped polygons drawn
by slicing.
"""
