"""``reliefkit bench export``: what a glTF export of each kind weighs, costs and shows.

Each demo asset is baked by every registered baker that takes a mesh, with its defaults (a
baker that refuses the asset is a row saying why), raw and with ``--compress bc`` (a glTF
file holds arrays uncompressed, so block-compressed textures are what shrinks it), and
exported (`reliefkit.export`). Per kind: the .rk file's bytes (deflated) against the
.glb's (with its draw plans, without shaders) and the .glb gzipped (as a web server sends
it), the export's time, the fallback mesh's
triangles, and how the fallback and the representation each cover what the mesh covers
(mask IoU from three views at 128 x 128, the fallback drawn by reliefkit's mesh renderer:
what a viewer without reliefkit's extension shows). With ``--quick``: one asset, the first
baker.
"""

from __future__ import annotations

import gzip
import tempfile
import time
from pathlib import Path

from ..bake import bake
from ..errors import UsageError
from ..export import export
from ..export.gltf import DEFAULT_FALLBACK_TRIANGLES, fallback_of
from ..io.inputs import load_input
from ..io.rk import save
from ..metrics import mask_iou
from ..render.draw import render
from ..scene.views import orbit_bounds
from ..units import format_bytes
from .kinds import mesh_kinds
from .report import machine, machine_line, write_report

ASSETS = ("vehicle", "tree", "blob", "torus")
VIEWS = ((30.0, 20.0), (150.0, -10.0), (270.0, 60.0))
SIZE = (128, 128)
TEXTURES = (("raw", {}), ("bc", {"compress": "bc"}))


def run_suite(quick: bool, out: Path, log) -> tuple[str, list[Path]]:
    kinds = mesh_kinds()
    rows = []
    for asset in ASSETS[:1] if quick else ASSETS:
        mesh = load_input(f"demo:{asset}")
        cameras = [orbit_bounds(mesh.bounds, az, el, size=SIZE) for az, el in VIEWS]
        truths = render(mesh, cameras)
        for kind in kinds[:1] if quick else kinds:
            for textures, compress in TEXTURES:
                log(f"{asset}: {kind}, {textures}")
                try:
                    rep = bake(mesh, kind, compress=compress)
                except UsageError as exc:  # a shell volume of a mesh without uvs, say
                    rows.append({"asset": asset, "kind": kind, "refused": str(exc)})
                    break
                rows.append({"textures": textures, **_row(asset, kind, rep, cameras, truths)})
    data = {"views": VIEWS, "size": SIZE, "machine": machine(),
            "fallback_triangles": DEFAULT_FALLBACK_TRIANGLES, "rows": rows}
    return _markdown(data), write_report(out, "export", data, _markdown)


def _row(asset: str, kind: str, rep, cameras, truths) -> dict:
    with tempfile.TemporaryDirectory() as folder:
        rk_bytes = save(Path(folder) / "r.rk", rep).stat().st_size
        start = time.perf_counter()
        glb = export(rep, Path(folder) / "r.glb")
        seconds = time.perf_counter() - start
        glb_bytes, gzip_bytes = glb.stat().st_size, len(gzip.compress(glb.read_bytes(), 6))
    fallback = fallback_of(rep, DEFAULT_FALLBACK_TRIANGLES)
    shown, drawn = render(fallback, cameras), render(rep, cameras)
    return {"asset": asset, "kind": kind, "rk_bytes": rk_bytes, "glb_bytes": glb_bytes,
            "glb_gzip_bytes": gzip_bytes,
            "export_seconds": seconds, "triangles": fallback.triangle_count,
            "fallback_iou": [mask_iou(f, t) for f, t in zip(shown, truths, strict=True)],
            "representation_iou": [mask_iou(f, t) for f, t in zip(drawn, truths, strict=True)]}


def _markdown(data: dict) -> str:
    size = data["size"]
    views = ", ".join(f"{az:g}/{el:g}" for az, el in data["views"])
    lines = [f"# glTF export: bytes, time and what a viewer shows ({len(data['views'])} views "
             f"at {size[0]}x{size[1]}: {views})", "", machine_line(data["machine"]), "",
             "| asset | kind | textures | .rk file | .glb | .glb gzipped | export | fallback "
             "triangles | fallback IoU (per view) | representation IoU |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in data["rows"]:
        if "refused" in r:
            lines.append(f"| {r['asset']} | {r['kind']} | refused: {r['refused']} "
                         "| | | | | | | |")
            continue
        fallback = " / ".join(f"{v:.3f}" for v in r["fallback_iou"])
        own = " / ".join(f"{v:.3f}" for v in r["representation_iou"])
        lines.append(f"| {r['asset']} | {r['kind']} | {r['textures']} | "
                     f"{format_bytes(r['rk_bytes'])} | "
                     f"{format_bytes(r['glb_bytes'])} | {format_bytes(r['glb_gzip_bytes'])} | "
                     f"{r['export_seconds']:.2f} s | "
                     f"{r['triangles']:,} | {fallback} | {own} |")
    return "\n".join(lines) + "\n"
