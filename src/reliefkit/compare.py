"""`reliefkit compare`: a representation against its mesh, every variant its technique declares.

Each variant (a method, a mode) is rendered from the same camera with the instrumented
shaders; the core scores it against the mesh (PSNR, SSIM, IoU, position error, iterations)
and the technique adds its own metrics (such as wrong hits against an exact reference).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from .io.atomic import atomic_path, written_together
from .pictures import TILE_BACKGROUND
from .units import format_bytes

CORE_COLUMNS = ("psnr", "ssim", "iou", "position_mean_rel", "iterations_mean",
                "iterations_max", "bytes")


def compare(mesh, representation, camera, *, light=None, progress=None) -> dict:
    """Render ``mesh`` and every variant of ``representation``; metrics, frames, error masks.

    ``progress(done, total)`` is called after the mesh and after each variant.

    Returns ``{"metrics": {variant: row}, "frames": {"mesh": Frame, variant: Frame},
    "errors": {variant: mask or None}, "columns": table columns, "bytes": {"mesh": n,
    "representation": n}}`` (bytes as the .rk files store them, uncompressed).
    """
    from . import metrics
    from .core.technique import technique_of
    from .errors import UsageError
    from .io.rk import array_bytes
    from .render import render

    tech = technique_of(representation)
    if tech is None or not tech.compare_variants:
        raise UsageError(f"nothing to compare: {type(representation).__name__} declares no "
                         "compare variants")
    variants = [v for v in tech.compare_variants if v.available(representation)]
    advance = progress or (lambda done, total: None)
    truth = render(mesh, camera, light=light)
    advance(1, len(variants) + 1)
    rows, frames, errors = {}, {"mesh": truth}, {}
    for k, variant in enumerate(variants):
        drawn = variant.derive(representation, mesh) if variant.derive else representation
        plain = render(drawn, camera, light=light, **variant.options)
        counted = render(drawn, camera, light=light, count_iterations=True, **variant.options)
        scores = metrics.compare(plain, truth, scene_size=mesh.radius)
        row = {key: scores[key] for key in ("psnr", "ssim", "iou", "position_mean_rel")}
        row |= {key: counted.stats.get(key, 0) for key in
                ("iterations_mean", "iterations_max", "fragments")}
        row["covered"] = plain.stats["covered"]
        row["bytes"] = sum(array_bytes(drawn).values())
        error_mask = None
        for metric in tech.compare_metrics:
            extra, mask = (metric.measure(plain, drawn, camera, truth) if metric.against_mesh
                           else metric.measure(plain, drawn, camera))
            row |= extra
            error_mask = mask if error_mask is None or mask is None else error_mask | mask
        rows[variant.name] = row
        frames[variant.name] = plain
        errors[variant.name] = error_mask
        advance(k + 2, len(variants) + 1)
    columns = tuple(c for m in tech.compare_metrics for c in m.columns) + CORE_COLUMNS
    sizes = {"mesh": sum(array_bytes(mesh).values()),
             "representation": sum(array_bytes(representation).values())}
    return {"metrics": rows, "frames": frames, "errors": errors, "columns": columns,
            "bytes": sizes}


def comparison_sheet(result: dict, title: str):
    """mesh and every variant on top; below, coverage against the mesh (green both, red
    representation only, blue mesh only) and per variant the colour error, its technique's
    error mask (wrong hits, ...) in red."""
    from . import metrics
    from .pictures import contact_sheet

    frames, truth = result["frames"], result["frames"]["mesh"]
    tiles = [(name, frame.rgba8(TILE_BACKGROUND)) for name, frame in frames.items()]
    last = frames[list(result["errors"])[-1]]
    tiles.append(("coverage vs mesh", _rgba(metrics.error_image(last, truth, "mask"))))
    for name, mask in result["errors"].items():
        err = metrics.error_image(frames[name], truth, "color", scale=0.25)
        caption = f"{name}: error"
        if mask is not None:
            err[mask] = (1.0, 0.1, 0.1)
            caption += ", wrong in red"
        tiles.append((caption, _rgba(err)))
    return contact_sheet(tiles, columns=len(frames), title=title)


def _rgba(rgb: np.ndarray) -> np.ndarray:
    out = np.ones(rgb.shape[:2] + (4,), np.uint8) * 255
    out[..., :3] = np.round(np.clip(rgb, 0, 1) * 255)
    return out


def metrics_markdown(result: dict, heading: str) -> str:
    cols = result["columns"]
    sizes = result["bytes"]
    lines = [f"### {heading}", "", f"Memory: representation {format_bytes(sizes['representation'])}"
             f", mesh {format_bytes(sizes['mesh'])}.", "",
             "| variant | " + " | ".join(cols) + " |",
             "|---" * (len(cols) + 1) + "|"]
    for name, row in result["metrics"].items():
        cells = [format_bytes(row[c]) if c == "bytes" else
                 f"{row[c]:.4g}" if isinstance(row.get(c), float) else str(row.get(c, ""))
                 for c in cols]
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def write_comparison(result: dict, out_dir: Path, title: str) -> dict[str, Path]:
    """compare.png, metrics.md and metrics.json in ``out_dir`` (created): all three, or none
    if one cannot be written."""
    from .pictures import save_image

    out_dir.mkdir(parents=True, exist_ok=True)
    paths = {"picture": out_dir / "compare.png", "markdown": out_dir / "metrics.md",
             "json": out_dir / "metrics.json"}
    with written_together():
        save_image(comparison_sheet(result, title), paths["picture"])
        with atomic_path(paths["markdown"]) as tmp:
            tmp.write_text(metrics_markdown(result, title))
        with atomic_path(paths["json"]) as tmp:
            tmp.write_text(json.dumps({"title": title, "bytes": result["bytes"],
                                       "variants": result["metrics"]}, indent=2))
    return paths
