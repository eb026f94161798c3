"""`reliefkit compare`: one representation against its mesh, every method side by side."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from .fileio import atomic_path

METHODS = ("binary", "exact", "robust")
BACKGROUND = (0.05, 0.055, 0.065)


def compare_relief(mesh, relief, camera, *, light=None) -> dict:
    """Render ``mesh`` and ``relief`` with each method; metrics, frames and error images."""
    from . import metrics
    from .reference.relief import wrong_hits
    from .render import render

    truth = render(mesh, camera, light=light)
    methods = [m for m in METHODS if m != "robust" or _has_safety(relief)]
    results, frames, wrong_maps = {}, {"mesh": truth}, {}
    for method in methods:
        frame = render(relief, camera, light=light, method=method, count_iterations=True)
        wrong = wrong_hits(frame, relief, camera)
        scores = metrics.compare(frame, truth, scene_size=mesh.radius)
        results[method] = {
            "wrong_hit_fraction": wrong["wrong_fraction"], "wrong_pixels": wrong["wrong_pixels"],
            "psnr": scores["psnr"], "ssim": scores["ssim"], "iou": scores["iou"],
            "position_mean_rel": scores["position_mean_rel"],
            "iterations_mean": frame.stats["iterations_mean"],
            "iterations_max": frame.stats["iterations_max"],
            "fragments": frame.stats["fragments"], "covered": frame.stats["covered"],
        }
        frames[method] = frame
        wrong_maps[method] = wrong["wrong"]
    return {"metrics": results, "frames": frames, "wrong": wrong_maps}


def _has_safety(relief) -> bool:
    parts = getattr(relief, "parts", [relief])
    return all(p.safety is not None for p in parts)


def comparison_sheet(result: dict, title: str):
    """mesh | binary | exact | robust on top; below, coverage (green both, red relief only,
    blue mesh only) and per method the colour error with wrong hits in red."""
    from . import metrics
    from .pictures import contact_sheet

    frames, truth = result["frames"], result["frames"]["mesh"]
    tiles = [(name, frame.rgba8(BACKGROUND)) for name, frame in frames.items()]
    tiles.append(("coverage vs mesh",
                  _rgba(metrics.error_image(frames[list(result["wrong"])[-1]], truth, "mask"))))
    for method, wrong in result["wrong"].items():
        err = metrics.error_image(frames[method], truth, "color", scale=0.25)
        err[wrong] = (1.0, 0.1, 0.1)
        tiles.append((f"{method}: error, wrong hits red", _rgba(err)))
    return contact_sheet(tiles, columns=len(frames), title=title)


def _rgba(rgb: np.ndarray) -> np.ndarray:
    out = np.ones(rgb.shape[:2] + (4,), np.uint8) * 255
    out[..., :3] = np.round(np.clip(rgb, 0, 1) * 255)
    return out


def metrics_markdown(metrics_by_method: dict, heading: str) -> str:
    cols = ("wrong_hit_fraction", "psnr", "ssim", "iou", "position_mean_rel",
            "iterations_mean", "iterations_max")
    lines = [f"### {heading}", "", "| method | " + " | ".join(cols) + " |",
             "|---" * (len(cols) + 1) + "|"]
    for method, row in metrics_by_method.items():
        cells = [f"{row[c]:.4g}" if isinstance(row[c], float) else str(row[c]) for c in cols]
        lines.append(f"| {method} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def write_comparison(result: dict, out_dir: Path, title: str) -> dict[str, Path]:
    """compare.png, metrics.md and metrics.json in ``out_dir`` (created)."""
    from .pictures import save_image

    out_dir.mkdir(parents=True, exist_ok=True)
    paths = {"picture": out_dir / "compare.png", "markdown": out_dir / "metrics.md",
             "json": out_dir / "metrics.json"}
    save_image(comparison_sheet(result, title), paths["picture"])
    with atomic_path(paths["markdown"]) as tmp:
        tmp.write_text(metrics_markdown(result["metrics"], title))
    with atomic_path(paths["json"]) as tmp:
        tmp.write_text(json.dumps({"title": title, "methods": result["metrics"]}, indent=2))
    return paths
