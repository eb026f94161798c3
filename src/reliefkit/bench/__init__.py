"""Benchmarks: ``reliefkit bench NAME`` runs a suite registered by a technique.

Suites measure side by side in one run (ratios) and report device-independent counts;
`timing` has the shared frame-timing helper.
"""

from __future__ import annotations

from pathlib import Path


def run_suite(name: str, *, quick: bool = False, out: Path = Path("out/bench"),
              log=None) -> tuple[str, list[Path]]:
    """Run the suite ``name``; returns its markdown report and the files it wrote.

    Without ``log`` the suite's step messages are its progress (`reliefkit.progress.activity`:
    ``bench NAME: ...`` lines on stderr, a spinner on a terminal).
    """
    from ..core.technique import bench_suite
    from ..progress import activity

    suite = bench_suite(name)
    if log is not None:
        return suite.run(quick, Path(out), log)
    with activity(f"bench {name}") as progress_log:
        return suite.run(quick, Path(out), progress_log)


def suite_names() -> tuple[str, ...]:
    from ..core.technique import bench_suites

    return tuple(bench_suites())
