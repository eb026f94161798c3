"""``reliefkit bench compact``: what compressing a representation's textures saves and costs.

Each demo asset is baked by every registered baker that takes a mesh, with its defaults (a
baker that refuses the asset is a row saying why), then compressed (``bake --compress bc``)
three ways: BC7 colour and normals with 16-bit heights (the default), the
same with 8-bit heights, and BC1 colour with 8-bit heights (where the colour is opaque).
Per variant: the .rk file's bytes, the bytes a GPU holds (`compact.gpu_bytes`), and the
image error of its frames against the mesh's and against the uncompressed
representation's, from three views at 192 x 192 (PSNR and SSIM of the displayed colour,
mask IoU). A representation with nothing to encode has its raw row only. With ``--quick``:
one asset, the first baker.
"""

from __future__ import annotations

import tempfile
from dataclasses import replace
from pathlib import Path

import numpy as np

from ..bake import bake
from ..compact.compact import CompressOptions, compress, gpu_bytes
from ..errors import UsageError
from ..io.inputs import load_input
from ..io.rk import save
from ..metrics import mask_iou, psnr, ssim
from ..render.draw import render
from ..scene.views import orbit_bounds
from ..units import format_bytes
from .kinds import mesh_kinds
from .report import machine, machine_line, write_report

ASSETS = ("vehicle", "tree", "blob")
VIEWS = ((30.0, 25.0), (150.0, 10.0), (260.0, 60.0))
SIZE = (192, 192)
BC = CompressOptions(compress="bc")
VARIANTS = (("bc7, 16-bit heights", BC), ("bc7, 8-bit heights", replace(BC, height_bits=8)),
            ("bc1 colour, 8-bit heights", replace(BC, color_format="bc1", height_bits=8)))


def run_suite(quick: bool, out: Path, log) -> tuple[str, list[Path]]:
    kinds = mesh_kinds()
    rows = []
    for asset in ASSETS[:1] if quick else ASSETS:
        mesh = load_input(f"demo:{asset}")
        cameras = [orbit_bounds(mesh.bounds, az, el, size=SIZE) for az, el in VIEWS]
        mesh_frames = render(mesh, cameras)
        for kind in kinds[:1] if quick else kinds:
            log(f"{asset}: baking {kind}")
            try:
                raw = bake(mesh, kind)
            except UsageError as exc:  # a shell volume of a mesh without uvs, say
                rows.append({"asset": asset, "kind": kind, "textures": "raw",
                             "refused": str(exc)})
                continue
            raw_frames = render(raw, cameras)
            rows.append(_row(asset, kind, "raw", raw, raw_frames, mesh_frames, raw_frames))
            for name, options in VARIANTS:
                log(f"{asset}: {kind} {name}")
                try:
                    rep = compress(raw, options)
                except UsageError as exc:  # bc1 refused for a colour with alpha
                    rows.append({"asset": asset, "kind": kind, "textures": name,
                                 "refused": str(exc)})
                    continue
                if all(fmt == "raw" for fmt, _, _ in gpu_bytes(rep).values()):
                    break  # nothing of it has a role: the raw row says it all
                frames = render(rep, cameras)
                rows.append(_row(asset, kind, name, rep, frames, mesh_frames, raw_frames))
    data = {"views": VIEWS, "size": SIZE, "machine": machine(), "rows": rows}
    return _markdown(data), write_report(out, "compact", data, _markdown)


def _row(asset, kind, textures, rep, frames, mesh_frames, raw_frames) -> dict:
    with tempfile.TemporaryDirectory() as folder:
        file_bytes = save(Path(folder) / "r.rk", rep).stat().st_size
    sizes = gpu_bytes(rep).values()
    return {"asset": asset, "kind": kind, "textures": textures, "file_bytes": file_bytes,
            "gpu_bytes": sum(gpu for _, gpu, _ in sizes),
            "raw_gpu_bytes": sum(raw for _, _, raw in sizes),
            "iou_mesh": _mean(mask_iou, frames, mesh_frames),
            "psnr_mesh": _mean(psnr, frames, mesh_frames),
            "ssim_mesh": _mean(ssim, frames, mesh_frames),
            "psnr_raw": _mean(psnr, frames, raw_frames),
            "ssim_raw": _mean(ssim, frames, raw_frames)}


def _mean(metric, frames, references) -> float:
    return float(np.mean([metric(f, r) for f, r in zip(frames, references, strict=True)]))


def _markdown(data: dict) -> str:
    size = data["size"]
    lines = [f"# Compact textures: bytes and image error, {len(data['views'])} views at "
             f"{size[0]}x{size[1]}", "", machine_line(data["machine"]), "",
             "| asset | kind | textures | .rk file | on the GPU | IoU vs mesh | PSNR / SSIM vs "
             "mesh | PSNR / SSIM vs raw |", "|---|---|---|---|---|---|---|---|"]
    for r in data["rows"]:
        if "refused" in r:
            lines.append(f"| {r['asset']} | {r['kind']} | {r['textures']} | refused: "
                         f"{r['refused']} | | | | |")
            continue
        vs_raw = "-" if r["textures"] == "raw" else \
            f"{_db(r['psnr_raw'])} / {r['ssim_raw']:.4f}"
        lines.append(f"| {r['asset']} | {r['kind']} | {r['textures']} | "
                     f"{format_bytes(r['file_bytes'])} | {format_bytes(r['gpu_bytes'])} | "
                     f"{r['iou_mesh']:.4f} | {_db(r['psnr_mesh'])} / {r['ssim_mesh']:.4f} | "
                     f"{vs_raw} |")
    return "\n".join(lines) + "\n"


def _db(value: float) -> str:
    return "inf" if not np.isfinite(value) else f"{value:.1f} dB"
