"""The shootout's pictures: a Pareto plot (error against bytes) and a contact sheet (every
representation beside the mesh) per screen size."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..bench.report import save_figure
from ..pictures import contact_sheet, save_image
from ..units import format_bytes
from .run import DECIMATED

SHEET_TILE = 160   # the longest side of a tile on a contact sheet, in pixels
MARKERS = "osD^vP*Xh<>p"


def pareto(results: dict, size: int, path: Path) -> Path:
    """1 - SSIM against bytes (log) at ``size``, one panel per mesh: one marker per
    representation and budget, the decimated mesh's curve through its budgets."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    meshes = results["meshes"]
    fig, axes = plt.subplots(1, len(meshes), figsize=(6.4 * len(meshes), 4.6), squeeze=False)
    labels = sorted({r["label"] for m in meshes for r in m["rows"]} - {DECIMATED})
    style = {label: (f"C{k % 10}", MARKERS[k % len(MARKERS)]) for k, label in enumerate(labels)}
    for ax, mesh in zip(axes[0], meshes, strict=True):
        fitted = [r for r in mesh["rows"] if r["fits"]]
        for label in labels:
            rows = [r for r in fitted if r["label"] == label]
            if rows:
                color, marker = style[label]
                ax.scatter([r["bytes"] for r in rows],
                           [1.0 - r["sizes"][size]["ssim"] for r in rows],
                           color=color, marker=marker, label=label, zorder=3)
        mesh_rows = sorted((r for r in fitted if r["label"] == DECIMATED),
                           key=lambda r: r["bytes"])
        if mesh_rows:
            ax.plot([r["bytes"] for r in mesh_rows],
                    [1.0 - r["sizes"][size]["ssim"] for r in mesh_rows], "-k", lw=2,
                    marker="o", label="decimated mesh (compact)", zorder=4)
        for budget in results["budgets"]:
            ax.axvline(budget, color="0.75", lw=0.8, ls=":", zorder=1)
        ax.set(xscale="log", xlabel="bytes on a GPU (compact)",
               ylabel="1 - SSIM (mean over the views)",
               title=f"{mesh['name']}: {size} px")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    save_figure(fig, path)
    return path


def thumbnail(image: np.ndarray) -> np.ndarray:
    """An RGBA tile about `SHEET_TILE` on its longest side: larger pictures box filtered,
    smaller ones enlarged by a whole factor, each pixel a square (what S pixels show)."""
    from PIL import Image

    h, w = image.shape[:2]
    if max(h, w) <= SHEET_TILE:
        factor = SHEET_TILE // max(h, w)
        return np.repeat(np.repeat(image, factor, axis=0), factor, axis=1)
    scale = SHEET_TILE / max(h, w)
    small = Image.fromarray(image, "RGBA").resize(
        (max(1, round(w * scale)), max(1, round(h * scale))), Image.Resampling.BOX)
    return np.asarray(small)


def sheet(results: dict, pictures: dict, size: int, path: Path) -> Path:
    """Per mesh and budget, one row: the full mesh, then every representation that fits."""
    tiles, columns = [], 1
    for mesh in results["meshes"]:
        for budget in results["budgets"]:
            shots = pictures[size].get((mesh["name"], budget), [])
            (_, reference), = pictures[size][(mesh["name"], None)]
            row = [(f"{mesh['name']}, full mesh; budget {format_bytes(budget)}", reference)]
            for label, image in shots:
                got = next(r for r in mesh["rows"] if r["label"] == label
                           and r["budget"] == budget)
                row.append((f"{label} {format_bytes(got['bytes'])}, SSIM "
                            f"{got['sizes'][size]['ssim']:.3f}", image))
            tiles.append(row)
            columns = max(columns, len(row))
    blank = np.zeros_like(thumbnail(tiles[0][0][1]))
    flat = [(caption, thumbnail(image)) for row in tiles
            for caption, image in row + [("", blank)] * (columns - len(row))]
    picture = contact_sheet(flat, columns=columns, title=f"shootout at {size} px: each row one "
                            f"budget ({', '.join(format_bytes(b) for b in results['budgets'])})")
    save_image(picture, path)
    return path
