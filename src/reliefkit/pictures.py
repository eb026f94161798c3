"""Pictures for people: titled contact sheets, PNG and GIF writing (atomic)."""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from .errors import UsageError
from .io.atomic import atomic_path

TILE_BACKGROUND = (0.05, 0.055, 0.065)  # linear grey behind every rendered tile and frame
SHEET_BACKGROUND = (32, 34, 38)         # sRGB bytes between the tiles of a sheet
TITLE_COLOR = (235, 235, 235)


def _font(size: int):
    from PIL import ImageFont

    try:
        return ImageFont.load_default(size=size)
    except TypeError:  # Pillow < 10.1
        return ImageFont.load_default()


def contact_sheet(tiles: list[tuple[str, np.ndarray]], columns: int = 4, *,
                  title: str | None = None, pad: int = 8, caption_height: int = 22):
    """Arrange (caption, RGBA uint8 image) tiles in a grid with captions; returns a PIL image."""
    from PIL import Image, ImageDraw

    if not tiles:
        raise UsageError("contact_sheet needs at least one tile")
    tile_h = max(img.shape[0] for _, img in tiles)
    tile_w = max(img.shape[1] for _, img in tiles)
    columns = max(1, min(columns, len(tiles)))
    rows = -(-len(tiles) // columns)
    head = 34 if title else 0
    cell_w, cell_h = tile_w + pad, tile_h + caption_height + pad
    sheet = Image.new("RGB", (columns * cell_w + pad, head + rows * cell_h + pad),
                      SHEET_BACKGROUND)
    draw = ImageDraw.Draw(sheet)
    if title:
        draw.text((pad, 8), title, fill=TITLE_COLOR, font=_font(20))
    for k, (caption, img) in enumerate(tiles):
        x = pad + (k % columns) * cell_w
        y = head + pad + (k // columns) * cell_h
        draw.text((x + 2, y + 3), caption, fill=TITLE_COLOR, font=_font(14))
        tile = Image.fromarray(img, "RGBA" if img.shape[2] == 4 else "RGB")
        sheet.paste(tile, (x, y + caption_height), tile if img.shape[2] == 4 else None)
    return sheet


def save_image(image, path) -> None:
    """Write a PIL image (format from the suffix) atomically."""
    with atomic_path(path) as tmp:
        image.save(tmp, format=_format_of(path))


def save_gif(frames: Iterable[np.ndarray], path, fps: float = 15.0) -> int:
    """Write RGBA uint8 frames as a looping animated GIF, atomically; returns their count.

    Frames are encoded as they come (each with its own 256-colour palette) and dropped, so an
    iterator of 3,600 views at 2048x2048 needs one frame's memory, not 45 GB.
    """
    from PIL import GifImagePlugin

    count = 0
    with atomic_path(path) as tmp, open(tmp, "wb") as out:
        for image in map(_gif_frame, frames):  # holds no frame while the next is made
            if count == 0:
                header, _ = GifImagePlugin.getheader(image, info={"loop": 0})
                out.write(b"".join(header))
            out.writelines(GifImagePlugin.getdata(image, duration=1000.0 / fps,
                                                  include_color_table=True))
            count += 1
        if count == 0:
            raise UsageError(f"{path}: a GIF needs at least one frame")
        out.write(b";")  # the GIF trailer
    return count


def _gif_frame(rgba: np.ndarray):
    """One frame as a PIL image of at most 256 colours (median cut)."""
    from PIL import Image

    return Image.fromarray(np.ascontiguousarray(rgba[..., :3])).quantize(256)


def _format_of(path) -> str:
    suffix = str(path).lower().rsplit(".", 1)[-1]
    return {"png": "PNG", "jpg": "JPEG", "jpeg": "JPEG", "gif": "GIF"}.get(suffix, "PNG")
