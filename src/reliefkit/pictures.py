"""Pictures for people: titled contact sheets and their atomic writing (animations:
`reliefkit.animation`)."""

from __future__ import annotations

import numpy as np

from .errors import UsageError
from .io.atomic import atomic_path

TILE_BACKGROUND = (0.05, 0.055, 0.065)  # linear grey behind every rendered tile and frame
SHEET_BACKGROUND = (32, 34, 38)         # sRGB bytes between the tiles of a sheet
TITLE_COLOR = (235, 235, 235)
CAPTION_SIZE, CAPTION_LINE = 14, 17  # caption font size and line height (pixels)


def _font(size: int):
    from PIL import ImageFont

    try:
        return ImageFont.load_default(size=size)
    except TypeError:  # Pillow < 10.1
        return ImageFont.load_default()


def contact_sheet(tiles: list[tuple[str, np.ndarray]], columns: int = 4, *,
                  title: str | None = None, pad: int = 8, caption_height: int = 22):
    """Arrange (caption, RGBA uint8 image) tiles in a grid with captions; returns a PIL image.

    Captions wrap to their tile's width (the caption band grows by a line for each extra
    line the longest one needs), so none runs into its neighbour or off the sheet; the
    title widens the sheet if it is wider than the tiles.
    """
    from PIL import Image, ImageDraw

    if not tiles:
        raise UsageError("contact_sheet needs at least one tile")
    tile_h = max(img.shape[0] for _, img in tiles)
    tile_w = max(img.shape[1] for _, img in tiles)
    columns = max(1, min(columns, len(tiles)))
    rows = -(-len(tiles) // columns)
    font, title_font = _font(CAPTION_SIZE), _font(20)
    captions = [wrap_text(caption, font, tile_w - 2) for caption, _ in tiles]
    caption_height += (max(len(lines) for lines in captions) - 1) * CAPTION_LINE
    head = 34 if title else 0
    cell_w, cell_h = tile_w + pad, tile_h + caption_height + pad
    width = max(columns * cell_w + pad, int(title_font.getlength(title)) + 2 * pad if title
                else 0)
    sheet = Image.new("RGB", (width, head + rows * cell_h + pad), SHEET_BACKGROUND)
    draw = ImageDraw.Draw(sheet)
    if title:
        draw.text((pad, 8), title, fill=TITLE_COLOR, font=title_font)
    for k, ((_, img), lines) in enumerate(zip(tiles, captions, strict=True)):
        x = pad + (k % columns) * cell_w
        y = head + pad + (k // columns) * cell_h
        for n, line in enumerate(lines):
            draw.text((x + 2, y + 3 + n * CAPTION_LINE), line, fill=TITLE_COLOR, font=font)
        tile = Image.fromarray(img, "RGBA" if img.shape[2] == 4 else "RGB")
        sheet.paste(tile, (x, y + caption_height), tile if img.shape[2] == 4 else None)
    return sheet


BREAK_AFTER = "/-_."  # where a word wider than a line (a path, a kind) breaks first


def wrap_text(text: str, font, width: float) -> list[str]:
    """``text`` in lines of at most ``width`` pixels in ``font``: broken at spaces, and a
    word wider than a line after its last `BREAK_AFTER` character that fits (a batch's
    ``chairs/old/armchair``: after a ``/``, not mid-name), else where it must be."""
    lines: list[str] = []
    for word in text.split():
        joined = f"{lines[-1]} {word}" if lines else word
        if lines and font.getlength(joined) <= width:
            lines[-1] = joined
            continue
        while font.getlength(word) > width and len(word) > 1:
            fits = max(k for k in range(1, len(word)) if font.getlength(word[:k]) <= width
                       or k == 1)
            soft = [k for k in range(1, fits + 1) if word[k - 1] in BREAK_AFTER]
            cut = soft[-1] if soft else fits
            lines.append(word[:cut])
            word = word[cut:]
        lines.append(word)
    return lines or [""]


def save_image(image, path) -> None:
    """Write a PIL image (format from the suffix) atomically."""
    with atomic_path(path) as tmp:
        image.save(tmp, format=_format_of(path))


def _format_of(path) -> str:
    suffix = str(path).lower().rsplit(".", 1)[-1]
    return {"png": "PNG", "jpg": "JPEG", "jpeg": "JPEG", "gif": "GIF"}.get(suffix, "PNG")
