"""``--sheet``: every output's thumbnail beside its mesh's, as a contact sheet PNG and an
``index.html`` in OUT. Workers render the thumbnails where the mesh and the bake are at
hand (`task.run_task`); the driver keeps them under ``OUT/thumbnails/`` and arranges them."""

from __future__ import annotations

import html
import urllib.parse
from pathlib import Path, PurePosixPath

import numpy as np

from ..io.atomic import atomic_path
from ..pictures import contact_sheet, save_image
from .report import BatchReport

THUMBNAIL_SIZE = 128     # pixels, square, from the default view
THUMBNAIL_FOLDER = "thumbnails"
SHEET_NAME, INDEX_NAME = "sheet.png", "index.html"
SHEET_MAX_ASSETS = 200   # the PNG shows the first ones by output; index.html lists all
SHEET_COLUMNS = 8        # four assets a row: mesh, then output
KEY_CHUNK = "reliefkit:cache_key"  # a thumbnail's PNG text chunk: the bake it shows


def thumbnail_paths(out: Path, output: str) -> tuple[Path, Path]:
    """Where the mesh's and the output's thumbnails of ``output`` (an .rk path relative to
    ``out``) are kept."""
    stem = PurePosixPath(output).with_suffix("")
    base = out / THUMBNAIL_FOLDER / Path(*stem.parts)
    return base.with_name(base.name + ".mesh.png"), base.with_name(base.name + ".png")


def keyed_png_info(key: str):
    """PNG text chunks that record the cache key of the bake a thumbnail shows."""
    from PIL.PngImagePlugin import PngInfo

    info = PngInfo()
    info.add_text(KEY_CHUNK, key)
    return info


def thumbnail_key(path: Path) -> str | None:
    """The cache key a thumbnail records; None when it has none or cannot be read (its
    text chunks come before the pixels: the image data is not decoded)."""
    from PIL import Image, UnidentifiedImageError

    try:
        with Image.open(path) as image:
            key = getattr(image, "text", {}).get(KEY_CHUNK)
    except (OSError, UnidentifiedImageError, ValueError):
        return None
    return key if isinstance(key, str) else None


def write_sheet(out: Path, report: BatchReport) -> tuple[Path, ...]:
    """sheet.png (when any asset has an output) and index.html over the assets of
    ``report`` that have one (baked now or skipped as up to date), by output path; the
    files written."""
    from PIL import Image

    shown = sorted((r for r in report.records if r.status != "failed"),
                   key=lambda r: r.output)
    tiles = []
    for record in shown[:SHEET_MAX_ASSETS]:
        stem = str(PurePosixPath(record.output).with_suffix(""))
        for path, caption in zip(thumbnail_paths(out, record.output),
                                 (f"{stem}: mesh", f"{stem}: {record.kind}"), strict=True):
            with Image.open(path) as image:
                tiles.append((caption, np.asarray(image.convert("RGBA"))))
    title = f"reliefkit batch: {len(shown)} outputs beside their meshes"
    if len(shown) > SHEET_MAX_ASSETS:
        title += f" (the first {SHEET_MAX_ASSETS}; {INDEX_NAME} lists all)"
    written = []
    if tiles:
        written.append(out / SHEET_NAME)
        save_image(contact_sheet(tiles, SHEET_COLUMNS, title=title), written[-1])
    written.append(out / INDEX_NAME)
    with atomic_path(written[-1]) as tmp:
        tmp.write_text(_index_html(out, report, shown), encoding="utf-8")
    return tuple(written)


def _index_html(out: Path, report: BatchReport, shown) -> str:
    def image(path: Path) -> str:
        url = urllib.parse.quote(path.relative_to(out).as_posix())
        return f'<img src="{url}" width="{THUMBNAIL_SIZE}" height="{THUMBNAIL_SIZE}" alt="">'

    rows = []
    for record in shown:
        mesh, output = thumbnail_paths(out, record.output)
        link = urllib.parse.quote(record.output)
        rows.append(f"<tr><td>{image(mesh)}</td><td>{image(output)}</td>"
                    f'<td>{html.escape(record.input)}<br><a href="{link}">'
                    f"{html.escape(record.output)}</a><br>{html.escape(record.kind)}, "
                    f"{record.status}</td></tr>")
    failed = "".join(f"<li>{html.escape(r.error or r.input)}</li>" for r in report.failed)
    return ("<!doctype html>\n<html><head><meta charset=\"utf-8\"><title>reliefkit batch"
            "</title><style>body{font-family:sans-serif;background:#202226;color:#ebebeb}"
            "td{padding:4px;vertical-align:top}a{color:#9cf}</style></head><body>\n"
            f"<h1>reliefkit batch</h1>\n<p>{len(shown)} outputs beside their meshes; "
            f"{len(report.failed)} failed.</p>\n<table>\n" + "\n".join(rows) + "\n</table>\n"
            + (f"<h2>Failed</h2><ul>{failed}</ul>\n" if failed else "") + "</body></html>\n")
