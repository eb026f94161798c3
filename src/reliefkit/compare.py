"""`reliefkit compare`: a representation against its mesh, every variant its technique declares.

Each variant (a method, a mode) is rendered from the same camera with the instrumented
shaders; the core scores it against the mesh (PSNR, SSIM, IoU, position error, iterations)
and the technique adds its own metrics (such as wrong hits against an exact reference).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from . import metrics, strict_json
from .builtins import registry
from .errors import UsageError
from .io.atomic import atomic_path, written_together
from .io.inputs import kind_of
from .io.rk import array_bytes
from .pictures import TILE_BACKGROUND, contact_sheet, save_image
from .render import render, render_options
from .units import format_bytes

CORE_COLUMNS = ("psnr", "ssim", "iou", "position_mean_rel", "iterations_mean",
                "iterations_max", "bytes")


def compare(mesh, representation, camera, *, light=None, progress=None) -> dict:
    """Render ``mesh`` and every variant of ``representation``; metrics, frames, error masks.

    ``progress(done, total)`` is called after the mesh and after each variant.

    Returns ``{"metrics": {variant: row}, "frames": {"mesh": Frame, variant: Frame},
    "errors": {variant: mask or None}, "columns": table columns, "bytes": {"mesh": n,
    "representation": n}, "default": variant, "references": {variant: the mesh's Frame it
    is scored against}}`` (bytes as the .rk files store them, uncompressed; ``default`` is the
    variant that draws the representation as a plain render does, see `default_variant`;
    ``references``: see `mesh_references`).
    """
    tech = registry().technique_of(representation)
    if tech is None or not tech.compare_variants:
        raise UsageError(f"nothing to compare: kind {kind_of(representation)!r} declares no "
                         "compare variants")
    variants = [v for v in tech.compare_variants if v.available(representation)]
    advance = progress or (lambda done, total: None)
    references = mesh_references(mesh, camera, light, variants)
    advance(1, len(variants) + 1)
    rows, frames, errors, itself = {}, {"mesh": references[None]}, {}, []
    for k, variant in enumerate(variants):
        truth = references[variant.name]
        drawn = variant.derive(representation, mesh) if variant.derive else representation
        if drawn is representation:
            itself.append(variant)
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
    columns = _measured_columns(tech.compare_metrics, rows.values()) + CORE_COLUMNS
    sizes = {"mesh": sum(array_bytes(mesh).values()),
             "representation": sum(array_bytes(representation).values())}
    return {"metrics": rows, "frames": frames, "errors": errors, "columns": columns,
            "bytes": sizes, "default": default_variant(representation, itself or variants),
            "references": references}


def default_variant(representation, variants) -> str:
    """The name of the first of ``variants`` whose options are the representation's render
    defaults (what the bake produced, drawn as `reliefkit render` draws it), else the first
    one's: the coverage tile shows it, not whichever variant happens to come last."""
    defaults = {opt.name: opt.default for opt in render_options(representation)}
    for variant in variants:
        if all(defaults.get(name) == value for name, value in variant.options.items()):
            return variant.name
    return variants[0].name


def mesh_references(mesh, camera, light, variants) -> dict:
    """The mesh's frame each variant is scored against, by variant name (``None``: the
    plain mesh): rendered with the variant's options that the mesh also takes (a variant
    with ``shadows`` against the mesh's shadows), each distinct set once."""
    takes = {opt.name for opt in render_options(mesh)}
    drawn: dict[tuple, object] = {}

    def reference(options: dict):
        shared = tuple(sorted((k, v) for k, v in options.items() if k in takes))
        if shared not in drawn:
            drawn[shared] = render(mesh, camera, light=light, **dict(shared))
        return drawn[shared]

    return {None: reference({})} | {v.name: reference(v.options) for v in variants}


def _measured_columns(compare_metrics, rows) -> tuple[str, ...]:
    """The technique's metric columns in declared order, each once, that some row holds: a
    technique of several parts declares columns for kinds other than the one compared."""
    held = {key for row in rows for key in row}
    declared = dict.fromkeys(c for metric in compare_metrics for c in metric.columns)
    return tuple(c for c in declared if c in held)


def comparison_sheet(result: dict, title: str):
    """`comparison_tiles` on a contact sheet, one row per kind of tile."""
    return contact_sheet(comparison_tiles(result), columns=len(result["frames"]),
                         title=title)


def comparison_tiles(result: dict) -> list[tuple[str, np.ndarray]]:
    """(caption, RGBA) tiles: mesh and every variant; then the default variant's coverage
    against the mesh (green both, red representation only, blue mesh only), named, and per
    variant the colour error, its technique's error mask (wrong hits, ...) in red."""
    frames, truth = result["frames"], result["frames"]["mesh"]
    tiles = [(name, frame.rgba8(TILE_BACKGROUND)) for name, frame in frames.items()]
    default = result["default"]
    tiles.append((f"coverage vs mesh: {default}",
                  _rgba(metrics.error_image(frames[default], truth, "mask"))))
    for name, mask in result["errors"].items():
        reference = result.get("references", {}).get(name, truth)
        err = metrics.error_image(frames[name], reference, "color", scale=0.25)
        caption = f"{name}: error"
        if mask is not None:
            err[mask] = (1.0, 0.1, 0.1)
            caption += ", wrong in red"
        tiles.append((caption, _rgba(err)))
    return tiles


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
    rows = [[_cell(row.get(c), c) for c in cols] for row in result["metrics"].values()]
    lines += [f"| {name} | " + " | ".join(cells) + " |"
              for name, cells in zip(result["metrics"], rows, strict=True)]
    if any("n/a" in cells for cells in rows):
        lines += ["", "n/a: not measured for that variant."]
    return "\n".join(lines) + "\n"


def _measured(value):
    """None for a score with nothing to measure: missing, or NaN (the position error of a
    frame without positions, such as depth peeling's); the reports show n/a, JSON null."""
    return None if value is None or (isinstance(value, float) and math.isnan(value)) else value


def _cell(value, column: str) -> str:
    value = _measured(value)
    if value is None:
        return "n/a"
    if column == "bytes":
        return format_bytes(value)
    return f"{value:.4g}" if isinstance(value, float) else str(value)


def write_comparison(result: dict, out_dir: Path, title: str) -> dict[str, Path]:
    """compare.png, metrics.md and metrics.json in ``out_dir`` (created): all three, or none
    if one cannot be written."""
    out_dir.mkdir(parents=True, exist_ok=True)
    paths = {"picture": out_dir / "compare.png", "markdown": out_dir / "metrics.md",
             "json": out_dir / "metrics.json"}
    with written_together():
        save_image(comparison_sheet(result, title), paths["picture"])
        with atomic_path(paths["markdown"]) as tmp:
            tmp.write_text(metrics_markdown(result, title))
        with atomic_path(paths["json"]) as tmp:
            tmp.write_text(metrics_json(result, title))
    return paths


def metrics_json(result: dict, title: str) -> str:
    """``{"title", "bytes", "variants": {name: row}}`` as strict JSON: a score not measured,
    or infinite (the PSNR of identical pictures), is null."""
    return strict_json.dumps({"title": title, "bytes": result["bytes"],
                              "variants": result["metrics"]}, indent=2)
