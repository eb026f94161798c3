"""Turntables and animations, written in the format the output's name asks for.

- a PNG per frame: a name with a ``%d`` pattern (``frames/%04d.png``) or a folder (a name
  ending in ``/``, or an existing folder: ``0000.png``, ``0001.png``, ...), numbered from 0,
  the folder made if needed;
- ``.png`` / ``.apng``: an animated PNG; ``.webp``: an animated WebP (lossless);
- ``.gif``: 255 colours and one transparent index where a frame is less than half covered;
- ``.mp4``: H.264 through the ffmpeg binary that imageio-ffmpeg ships; no alpha.

Every format but MP4 keeps a transparent background (PNG, APNG and WebP keep alpha
exactly); MP4 frames are composited over the tile background unless ``--background`` is
given. Each file is written atomically. PNG sequences, GIF and MP4 are written a frame at a
time as the frames are drawn (memory is one frame's at any length); Pillow's APNG and WebP
writers take every frame at once, so those are refused up front when the frames would not
fit in `held_limit` (name a .gif, .mp4 or a PNG sequence instead).
"""

from __future__ import annotations

import errno
import os
import re
from pathlib import Path

import numpy as np

from .errors import UsageError
from .gl.targets import host_limit
from .io.atomic import atomic_path, check_writable, written_together
from .pictures import TILE_BACKGROUND

FPS = 15.0
#: Animated files by suffix (a PNG sequence is named by a pattern or a folder instead).
FORMATS = {".gif": "gif", ".png": "apng", ".apng": "apng", ".webp": "webp", ".mp4": "mp4"}
SEQUENCE, FOLDER = "png-sequence", "png-folder"
NAMES = "*.gif, *.png or *.apng (APNG), *.webp, *.mp4, frames/%04d.png or a folder/"
_PATTERN = re.compile(r"%0?\d*d")
_HELD = ("apng", "webp")  # formats whose writer takes every frame at once


def animation_format(path) -> str:
    """The format ``path`` names: `SEQUENCE`, `FOLDER` or a value of `FORMATS`."""
    name = str(path)
    if "%" in Path(name).name:
        if len(_PATTERN.findall(name)) != 1 or name.count("%") != 1 \
                or not name.lower().endswith(".png"):
            raise UsageError(f"a PNG sequence is named with one %d pattern and .png, such as "
                             f"frames/%04d.png; got {name}")
        return SEQUENCE
    if name.endswith(("/", os.sep)) or Path(name).is_dir():
        return FOLDER
    found = FORMATS.get(Path(name).suffix.lower())
    if found is None:
        raise UsageError(f"an animation is written as {NAMES}; got {name}")
    return found


def is_animation_name(path) -> bool:
    """Whether ``path`` names an animated output rather than one .png."""
    try:
        found = animation_format(path)
    except UsageError:
        return "%" in Path(str(path)).name
    return found != "apng" or Path(str(path)).suffix.lower() == ".apng"


def check_animation_output(path, size: tuple[int, int], count: int = 1,
                           flag: str = "-o") -> str:
    """Refuse before any work a name no format matches, an MP4 of odd size (H.264 in
    yuv420p halves both), APNG or WebP frames that would not fit in memory together, or an
    output that cannot be written; returns the format."""
    found = animation_format(path)
    if found == "mp4" and (size[0] % 2 or size[1] % 2):
        raise UsageError(f"an .mp4 needs an even width and height (H.264, yuv420p), got "
                         f"{size[0]}x{size[1]}")
    needed = held_bytes(size, count)
    if found in _HELD and needed > host_limit():
        raise UsageError(f"{count} frames of {size[0]}x{size[1]} as {found.upper()} are held "
                         f"in memory together (about {needed / 2**30:.1f} GiB, limit "
                         f"{host_limit() / 2**30:.1f} GiB): write a .gif, an .mp4 or "
                         "frames/%04d.png, which are written a frame at a time, or fewer "
                         "or smaller frames")
    if found == SEQUENCE:  # the pattern's folder may be one still to be made
        check_writable(Path(path).parent, flag, folder=True)
    else:
        check_writable(path, flag, folder=found == FOLDER)
    return found


def held_bytes(size: tuple[int, int], count: int) -> int:
    """Memory of ``count`` RGBA8 frames held for APNG or WebP: our arrays and Pillow's
    images of them."""
    return 2 * 4 * size[0] * size[1] * count


def frame_background(path, background):
    """What the frames are composited over: the user's ``--background``, else nothing
    (transparent) where the format keeps alpha, else the tile background (MP4)."""
    if background is not None or animation_format(path) != "mp4":
        return background
    return TILE_BACKGROUND


def save_animation(frames, path, count: int, fps: float = FPS) -> str:
    """Write ``count`` RGBA uint8 frames (straight alpha, any iterable: a generator is drawn
    a frame at a time) as ``path`` asks; returns what was written."""
    found = animation_format(path)
    if found in (SEQUENCE, FOLDER):
        return _save_sequence(frames, path, found, count)
    if found in _HELD:
        frames = list(frames)  # checked by `check_animation_output`
    {"apng": _save_apng, "webp": _save_webp, "gif": _save_gif, "mp4": _save_mp4}[found](
        frames, path, fps)
    return str(path)


def _save_sequence(frames, path, found: str, count: int) -> str:
    """One PNG per frame, all moved into place together at the end (`written_together`): an
    interrupted or failed sequence leaves none of its frames."""
    from PIL import Image

    if found == FOLDER:
        digits = max(4, len(str(count - 1)))
        names = [Path(path) / f"{k:0{digits}d}.png" for k in range(count)]
    else:
        names = [Path(str(path) % k) for k in range(count)]
    names[0].parent.mkdir(parents=True, exist_ok=True)
    written = 0
    with written_together():
        for rgba in frames:  # not zip or enumerate: they hold the last frame while drawing
            with atomic_path(names[written]) as tmp:
                Image.fromarray(rgba, "RGBA").save(tmp, format="PNG")
            del rgba  # released before the next frame is drawn
            written += 1
        if written != count:
            raise ValueError(f"{count} frames were to be written, {written} came")
    return str(names[0]) if count == 1 else f"{names[0]} ... {names[-1]}"


def _images(frames):
    from PIL import Image

    return [Image.fromarray(np.ascontiguousarray(f), "RGBA") for f in frames]


def _save_apng(frames, path, fps: float) -> None:
    images = _images(frames)
    with atomic_path(path) as tmp:  # each frame replaces the last (no blending over it)
        images[0].save(tmp, format="PNG", save_all=True, append_images=images[1:],
                       duration=1000.0 / fps, loop=0, disposal=0, blend=0)


def _save_webp(frames, path, fps: float) -> None:
    images = _images(frames)
    with atomic_path(path) as tmp:
        images[0].save(tmp, format="WEBP", save_all=True, append_images=images[1:],
                       duration=round(1000.0 / fps), loop=0, lossless=True)


def _gif_frame(rgba: np.ndarray):
    """255 colours of the covered pixels, index 255 transparent where alpha < 1/2."""
    from PIL import Image

    opaque = rgba[..., 3] >= 128
    quantized = Image.fromarray(np.ascontiguousarray(rgba[..., :3]), "RGB").quantize(
        colors=255, dither=Image.Dither.NONE)
    index = np.asarray(quantized).copy()
    index[~opaque] = 255
    palette = quantized.getpalette()[:255 * 3]
    out = Image.fromarray(index, "P")
    out.putpalette(palette + [0] * (768 - len(palette)))
    return out


def _save_gif(frames, path, fps: float) -> None:
    """Each frame encoded as it comes (Pillow's frame writer) and dropped; disposal 2: each
    frame starts from transparent."""
    from PIL import GifImagePlugin

    count = 0
    with atomic_path(path) as tmp, open(tmp, "wb") as out:
        for image in map(_gif_frame, frames):
            info = {"duration": 1000.0 / fps, "disposal": 2, "transparency": 255}
            if count == 0:
                header, _ = GifImagePlugin.getheader(image, info={"loop": 0, **info})
                out.write(b"".join(header))
            out.writelines(GifImagePlugin.getdata(image, include_color_table=True, **info))
            count += 1
        if count == 0:
            raise UsageError(f"{path}: an animation needs at least one frame")
        out.write(b";")  # the GIF trailer


def _save_mp4(frames, path, fps: float) -> None:
    import imageio_ffmpeg

    frames = iter(frames)
    rgba = next(frames, None)
    if rgba is None:
        raise UsageError(f"{path}: an animation needs at least one frame")
    height, width = rgba.shape[:2]
    with atomic_path(path) as tmp:
        writer = imageio_ffmpeg.write_frames(
            str(tmp), (width, height), fps=fps, codec="libx264", pix_fmt_in="rgb24",
            pix_fmt_out="yuv420p", macro_block_size=1, output_params=["-f", "mp4"],
            ffmpeg_log_level="error", quality=8)
        try:
            writer.send(None)
            while rgba is not None:
                writer.send(np.ascontiguousarray(rgba[..., :3]).tobytes())
                del rgba  # released before the next frame is drawn
                rgba = next(frames, None)
            writer.close()
        except RuntimeError as exc:  # ffmpeg's own failure, in many lines: keep its last
            last = str(exc).strip().splitlines()[-1] if str(exc).strip() else "failed"
            raise OSError(errno.EIO, f"ffmpeg: {last}") from None
