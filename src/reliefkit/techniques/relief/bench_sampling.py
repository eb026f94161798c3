"""`reliefkit bench relief-sampling`: what the safety radii's sampling costs and what it buys.

The baker is exact along each sampled line but samples the projected directions and the walk
positions within a texel (`safety.py`); the independent checker (`safety_check.py`) fires
rays with continuous parameters at its result. This suite bakes each field with each
sampling, one after the other in one run, and sets the cost (seconds, the ratio to the
default sampling's, walk positions visited per texel) beside the checker's violating rays
and their deepest dip past the tolerance: the evidence for the defaults, and for what a
cheaper sampling would give up.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...bench.report import machine, machine_line, save_figure, write_report
from ...scene.assets import make_asset
from .bake import DEFAULT_TOLERANCE, bake_relief
from .safety import safety_radii
from .safety_check import check_safety

#: (directions, offsets, margin); the first is `safety_radii`'s default.
SAMPLINGS = ((64, 4, 0.25), (32, 4, 0.25), (64, 2, 0.5), (32, 2, 0.5), (16, 2, 0.5),
             (16, 2, 1.0), (16, 1, 1.0))
#: At 1024² the checker takes half a minute per sampling: the default and the two that
#: come closest to 10 s.
LARGE_SAMPLINGS = ((64, 4, 0.25), (32, 2, 0.5), (16, 2, 0.5))


@dataclass
class SamplingConfig:
    #: (model, depth resolution, samplings)
    fields: tuple = (("terrain", 256, SAMPLINGS), ("blob", 256, SAMPLINGS),
                     ("vehicle", 256, SAMPLINGS), ("terrain", 1024, LARGE_SAMPLINGS))
    rays: int = 1_000_000
    seed: int = 11
    tolerance: float = DEFAULT_TOLERANCE

    @classmethod
    def quick(cls) -> SamplingConfig:
        return cls(fields=(("terrain", 64, SAMPLINGS[:4:3]), ("vehicle", 64, SAMPLINGS[:4:3])),
                   rays=100_000)


def study_field(height, samplings, *, tolerance: float, rays: int, seed: int) -> list[dict]:
    """Bake ``height`` with each sampling and check each result with the same rays.

    ``ratio`` is a sampling's time over the first sampling's; ``excess`` the deepest
    violating dip past the tolerance, as a fraction of the tolerance (0 without violations).
    """
    rows = []
    for directions, offsets, margin in samplings:
        work = {}
        start = time.perf_counter()
        radii = safety_radii(height, tolerance=tolerance, directions=directions,
                             offsets=offsets, margin=margin, work=work)
        seconds = time.perf_counter() - start
        bad = check_safety(height, radii, tolerance=tolerance, rays=rays, seed=seed)
        deepest = max((v.depth for v in bad), default=tolerance)
        rows.append({"directions": directions, "offsets": offsets, "margin": margin,
                     "seconds": seconds, "ratio": seconds / (rows[0]["seconds"] if rows
                                                             else seconds),
                     "visits": work["visits"], "mean_radius": float(radii.mean()),
                     "violations": len(bad), "per_million": len(bad) * 1e6 / rays,
                     "excess": (deepest - tolerance) / tolerance if tolerance > 0 else deepest})
    return rows


def run(cfg: SamplingConfig, log=print) -> dict:
    safety_radii(np.zeros((8, 8), np.float32))  # compile before measuring
    results = {"machine": machine(),
               "config": {"rays": cfg.rays, "seed": cfg.seed, "tolerance": cfg.tolerance},
               "rows": []}
    for model, res, samplings in cfg.fields:
        relief = bake_relief(make_asset(model), depth_res=res, safety=False)
        for row in study_field(relief.height, samplings, tolerance=cfg.tolerance,
                               rays=cfg.rays, seed=cfg.seed):
            row = {"model": model, "res": res, **row}
            results["rows"].append(row)
            log(f"sampling: {model} {res}^2, {row['directions']} directions x "
                f"{row['offsets']} offsets, margin {row['margin']}: {row['seconds']:.2f} s, "
                f"{row['violations']} violating rays")
    results["verdicts"] = verdicts(results["rows"])
    return results


def verdicts(rows: list[dict]) -> list[dict]:
    """Per field: the cheapest sampling whose checker finds no more violating rays than the
    default's (the first sampling of the field), and its time ratio."""
    out = []
    for key in dict.fromkeys((r["model"], r["res"]) for r in rows):
        field = [r for r in rows if (r["model"], r["res"]) == key]
        default = field[0]
        keeps = [r for r in field if r["violations"] <= default["violations"]]
        best = min(keeps, key=lambda r: r["seconds"])
        out.append({"model": key[0], "res": key[1],
                    "sampling": (best["directions"], best["offsets"], best["margin"]),
                    "ratio": best["ratio"], "default_violations": default["violations"]})
    return out


def markdown(results: dict) -> str:
    c = results["config"]
    lines = [machine_line(results["machine"]),
             f"Tolerance {c['tolerance']}, {c['rays']} checker rays per bake (seed {c['seed']}, "
             "the same rays for every sampling of a field).", "",
             "| model | resolution | directions | offsets | margin | visits per texel | "
             "seconds | time / default | mean radius | violating rays | per million | "
             "deepest dip past the tolerance |", "|---" * 12 + "|"]
    for r in results["rows"]:
        lines.append(f"| {r['model']} | {r['res']}² | {r['directions']} | {r['offsets']} | "
                     f"{r['margin']} | {r['visits']:.0f} | {r['seconds']:.2f} | "
                     f"{r['ratio']:.2f} | {r['mean_radius']:.2f} | {r['violations']} | "
                     f"{r['per_million']:.0f} | {r['excess']:.0%} |")
    lines += ["", "Cheapest sampling with no more violating rays than the default:", ""]
    for v in results["verdicts"]:
        d, o, m = v["sampling"]
        lines.append(f"- {v['model']} {v['res']}²: {d} directions x {o} offsets, margin {m} "
                     f"({v['ratio']:.2f}x the default's time; the default leaves "
                     f"{v['default_violations']})")
    return "\n".join(lines) + "\n"


def plot(results: dict, path: Path) -> None:
    """Time against violating rays, one marker per bake, one colour per field."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import NullFormatter

    fig, ax = plt.subplots(figsize=(7, 4.5))
    fields = list(dict.fromkeys((r["model"], r["res"]) for r in results["rows"]))
    for i, key in enumerate(fields):
        rows = [r for r in results["rows"] if (r["model"], r["res"]) == key]
        ax.plot([r["ratio"] for r in rows], [r["per_million"] + 0.5 for r in rows], "o",
                color=f"C{i}", label=f"{key[0]} {key[1]}²")
        for r in rows:
            ax.annotate(f"{r['directions']}x{r['offsets']}/{r['margin']}",
                        (r["ratio"], r["per_million"] + 0.5), fontsize=6,
                        textcoords="offset points", xytext=(3, 2))
    ax.set(xscale="log", yscale="log", xlabel="time / default sampling's",
           xticks=[0.1, 0.2, 0.5, 1.0], xticklabels=["0.1", "0.2", "0.5", "1"],
           ylabel="violating checker rays per million (+0.5)",
           title="Safety radii: sampling (directions x offsets / margin) vs guarantee")
    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.legend(fontsize=8)
    save_figure(fig, path)


def write(results: dict, out: Path) -> list[Path]:
    paths = write_report(out, "relief-sampling", results, markdown)
    paths.append(Path(out) / "relief-sampling.png")
    plot(results, paths[-1])
    return paths


def run_suite(quick: bool, out: Path, log) -> tuple[str, list[Path]]:
    """The ``relief-sampling`` suite: run, write json/md/png into ``out``."""
    cfg = SamplingConfig.quick() if quick else SamplingConfig()
    results = run(cfg, log=log)
    return markdown(results), write(results, out)
