"""`reliefkit shootout`: for a mesh, at these screen sizes and byte budgets, what to ship.

Every representation the registry can size (`core.technique.Sizing`) is baked so that its
bytes on a GPU, read back from its .rk file, fit each budget (`sizing`), the mesh is
decimated to the same compact GPU bytes (`scene.decimate`), and both are drawn from fixed
views (`views`) and measured against the full mesh (`measure`); `report` names the best per
size and budget, `plots` draws the Pareto plots and contact sheets.
"""

from __future__ import annotations

from pathlib import Path

from . import plots, report
from .run import load_meshes, run_shootout, unique_names
from .sizing import parse_budgets, parse_kinds, parse_sizes

__all__ = ["shootout", "parse_budgets", "parse_kinds", "parse_sizes", "load_meshes"]


def shootout(meshes, chosen, budgets: list[int], sizes: list[int], out) -> tuple[dict, list[Path]]:
    """Run it on loaded ``meshes`` with the ``chosen`` candidates; write the report into
    ``out``. Returns the results and the paths written."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    results, pictures = run_shootout(meshes, unique_names(meshes), chosen, budgets, sizes, out)
    results = report.finish(results)
    paths = report.write(results, out)
    for size in sizes:
        paths.append(plots.pareto(results, size, out / f"pareto-{size}.png"))
        paths.append(plots.sheet(results, pictures, size, out / f"sheet-{size}.png"))
    return results, paths
