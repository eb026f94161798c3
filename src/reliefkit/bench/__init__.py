"""Benchmarks: ``reliefkit bench NAME`` runs a suite registered by a technique.

Suites measure side by side in one run (ratios) and report device-independent counts;
`timing` has the shared frame-timing helper.
"""

from __future__ import annotations

import sys
from pathlib import Path


def run_suite(name: str, *, quick: bool = False, out: Path = Path("out/bench"),
              log=None) -> tuple[str, list[Path]]:
    """Run the suite ``name``; returns its markdown report and the files it wrote."""
    from ..core.technique import bench_suite

    suite = bench_suite(name)
    log = log or (lambda msg: print(msg, file=sys.stderr, flush=True))
    return suite.run(quick, Path(out), log)


def suite_names() -> tuple[str, ...]:
    from ..core.technique import bench_suites

    return tuple(bench_suites())
