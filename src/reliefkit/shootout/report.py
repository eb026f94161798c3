"""The shootout's verdicts and its report: the best row per mesh, size and budget, a summary
of who wins how often, and shootout.json / shootout.md."""

from __future__ import annotations

import math
from collections import Counter
from pathlib import Path

from .. import strict_json
from ..bench.report import machine, machine_line
from ..io.atomic import atomic_path
from ..units import format_bytes
from .run import DECIMATED
from .sizing import unsized

#: Fields that hold seconds or milliseconds: the only ones two runs may disagree on.
TIME_FIELDS = ("bake_s", "frame_ms", "mesh_ms", "frame_ratio", "machine")


def best_row(rows: list[dict], size: int, budget: int) -> dict | None:
    """The row within ``budget`` with the highest mean SSIM at ``size``, ties by mask IoU
    (then the first in the table's order); None when no row fits."""
    within = [r for r in rows if r["budget"] == budget and r["fits"]]
    if not within:
        return None
    return max(within, key=lambda r: (r["sizes"][size]["ssim"], r["sizes"][size]["iou"]))


def recommend(result: dict, sizes, budgets) -> list[dict]:
    """One recommendation per size and budget of one mesh."""
    out = []
    for size in sizes:
        for budget in budgets:
            row = best_row(result["rows"], size, budget)
            out.append({"size": size, "budget": budget,
                        "label": row["label"] if row else None,
                        "line": recommendation_line(row, size, budget)})
    return out


def recommendation_line(row: dict | None, size: int, budget: int) -> str:
    """The verdict in words, with its figures (no times: the line is the same every run)."""
    where = f"{size} px, {format_bytes(budget)}"
    if row is None:
        return f"{where}: nothing fits"
    f = row["sizes"][size]
    figures = (f"SSIM {f['ssim']:.3f}, IoU {f['iou']:.3f}, PSNR {_db(f['psnr'])}, "
               f"{format_bytes(row['bytes'])}")
    if row["label"] == DECIMATED:
        what = "the whole mesh" if row.get("whole") else "the decimated mesh"
        textures = ", textures reduced to fit" if row.get("textures_reduced") else ""
        return (f"{where}: {what} ({row['n']:,} triangles{textures}, compact; {figures}): "
                "no image-based representation beats it here")
    return f"{where}: {row['label']} ({row['knob'].split(':')[0]} {row['n']}; {figures})"


def summarize(results: dict) -> dict:
    """How often each representation is the recommendation, over meshes, sizes and budgets."""
    wins = Counter(rec["label"] for mesh in results["meshes"]
                   for rec in mesh["recommendations"] if rec["label"])
    return {"wins": dict(sorted(wins.items(), key=lambda kv: (-kv[1], kv[0]))),
            "verdicts": sum(len(m["recommendations"]) for m in results["meshes"])}


def finish(results: dict) -> dict:
    """``results`` with every mesh's recommendations, the summary and the machine."""
    for mesh in results["meshes"]:
        mesh["recommendations"] = recommend(mesh, results["sizes"], results["budgets"])
    results["summary"] = summarize(results)
    results["unsized"] = unsized()
    results["machine"] = machine()
    return results


def _db(value) -> str:
    return "inf dB" if value is None or math.isinf(value) else f"{value:.1f} dB"


def _cell(value, digits: int = 3) -> str:
    if value is None:
        return "-"
    if isinstance(value, float) and math.isnan(value):
        return "n/a"
    if isinstance(value, float) and math.isinf(value):
        return "inf"
    return f"{value:.{digits}f}"


def mesh_tables(mesh: dict, sizes, budgets) -> list[str]:
    lines = [f"## {mesh['name']}", "",
             f"{mesh['triangles']:,} triangles; the full mesh takes "
             f"{format_bytes(mesh['gpu_bytes_raw'])} raw, "
             f"{format_bytes(mesh['gpu_bytes_compact'])} compact on a GPU.", ""]
    lines += ["| size | budget | recommendation |", "|---|---|---|"]
    lines += [f"| {r['size']} px | {format_bytes(r['budget'])} | "
              f"{r['line'].split(': ', 1)[1]} |" for r in mesh["recommendations"]]
    for budget in budgets:
        rows = [r for r in mesh["rows"] if r["budget"] == budget]
        lines += ["", f"### {mesh['name']}, budget {format_bytes(budget)}", "",
                  "| representation | knob | bytes | bake s | " + " | ".join(
                      f"{s} px SSIM | IoU | PSNR | surface err | frame x" for s in sizes)
                  + " |",
                  "|---|---|---|---|" + "---|---|---|---|---|" * len(sizes)]
        for r in rows:
            if not r["fits"]:
                lines.append(f"| {r['label']} | - | - | - | cannot meet the budget: "
                             f"{r['reason']} |" + " |" * (5 * len(sizes) - 1))
                continue
            raw = f" ({format_bytes(r['raw_bytes'])} raw)" if "raw_bytes" in r else \
                f" (file {format_bytes(r['file_bytes'])})" if "file_bytes" in r else ""
            cells = []
            for s in sizes:
                f = r["sizes"][s]
                cells += [_cell(f["ssim"]), _cell(f["iou"]), _cell(f["psnr"], 1),
                          _cell(f["position_mean_rel"], 4), _cell(f["frame_ratio"], 2)]
            lines.append(f"| {r['label']} | {r['n']:,} | {format_bytes(r['bytes'])}{raw} | "
                         f"{r['bake_s']:.1f} | " + " | ".join(cells) + " |")
    return lines


def markdown(results: dict) -> str:
    sizes, budgets = results["sizes"], results["budgets"]
    views = ", ".join(f"{v['name']} ({v['azimuth']:g}°, {v['elevation']:g}°)"
                      for v in results["views"])
    lines = ["# reliefkit shootout", "",
             "Every representation sized so that its bytes on a GPU (textures block-"
             "compressed, read back from its .rk file; the file's size beside) fit each "
             "budget, and the mesh decimated to the same compact GPU bytes, against the full "
             "mesh. Figures are "
             f"means over {len(results['views'])} views: {views}; the bounding sphere spans "
             "the size in pixels. Surface err: world position error where both cover, per "
             "bounding radius; frame x: frame time over the full mesh's, timed side by "
             "side.", "", machine_line(results["machine"]), ""]
    if results["unsized"]:
        lines += [f"Not in the shootout (their bakers declare no sizing: they do not stand in "
                  f"for a whole mesh): {', '.join(results['unsized'])}.", ""]
    if len(results["meshes"]) > 1:
        wins = results["summary"]["wins"]
        lines += ["## Summary", "", f"Of {results['summary']['verdicts']} verdicts (mesh x "
                  "size x budget):", ""]
        lines += [f"- {label}: best {count} times" for label, count in wins.items()]
        lines.append("")
    for mesh in results["meshes"]:
        lines += mesh_tables(mesh, sizes, budgets) + [""]
    return "\n".join(lines)


def write(results: dict, out: Path) -> list[Path]:
    """shootout.json (every figure; null for NaN and infinities) and shootout.md, atomically."""
    paths = [out / "shootout.json", out / "shootout.md"]
    with atomic_path(paths[0]) as tmp:
        tmp.write_text(strict_json.dumps(results, indent=2))
    with atomic_path(paths[1]) as tmp:
        tmp.write_text(markdown(results))
    return paths
