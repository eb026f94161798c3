"""The kinds the bench suites bake from the demo assets: every registered baker that takes a
mesh (one enumeration for `export`, `compact` and `viewer`)."""

from __future__ import annotations

from ..core.technique import bakers


def mesh_kinds() -> list[str]:
    """The kinds of every registered baker that bakes from a mesh, in registration order."""
    return [name for name, (_, b) in bakers().items() if "mesh" in b.sources]
