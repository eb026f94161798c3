"""``reliefkit bench loading``: the memory `load_mesh` needs, as a multiple of the file's size.

One mesh (an icosphere tiled side by side: 2,048,000 triangles, 245,760 with ``--quick``) is
written as OBJ, binary STL, binary PLY and GLB (``--mesh FILE``: that file instead); each is
loaded in a fresh process, which loads a small file of the same format first (the modules
loading imports lazily), then resets its peak-memory mark (Linux ``/proc/self/clear_refs``)
and reports the resident memory then and the peak after loading. The ratio (peak minus
that baseline) / file size is the figure; the target is <= 5.
"""

from __future__ import annotations

import json
import platform
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from ..errors import MeshError
from ..io.atomic import atomic_path
from ..units import format_bytes

TARGET_RATIO = 5.0
FORMATS = ("obj", "stl", "ply", "glb")

# the child: imports and a warm-up load, then the peak reset (Linux clear_refs 5) and the
# resident baseline, then the load and its peak; both in KiB
_CHILD = """
import json, sys, time
from reliefkit.io.meshes import load_mesh
load_mesh(sys.argv[2])  # a small file of the same format: what loading imports lazily

def status(key):
    for line in open("/proc/self/status"):
        if line.startswith(key + ":"):
            return int(line.split()[1])

with open("/proc/self/clear_refs", "w") as refs:
    refs.write("5")
base = status("VmRSS")
start = time.perf_counter()
mesh = load_mesh(sys.argv[1])
seconds = time.perf_counter() - start
print(json.dumps({"baseline_kib": base, "peak_kib": status("VmHWM"), "seconds": seconds,
                  "triangles": mesh.triangle_count, "vertices": len(mesh.positions)}))
"""


def tiled_spheres(tiles: int, subdivisions: int = 6) -> tuple[np.ndarray, np.ndarray]:
    """(V, 3) float64 vertices and (F, 3) faces: ``tiles`` unit icospheres (81,920 triangles
    each at 6 subdivisions) in a row, 2.5 units apart."""
    import trimesh

    sphere = trimesh.creation.icosphere(subdivisions=subdivisions)
    v, f = np.asarray(sphere.vertices), np.asarray(sphere.faces)
    vertices = np.concatenate([v + [2.5 * k, 0.0, 0.0] for k in range(tiles)])
    faces = np.concatenate([f + k * len(v) for k in range(tiles)])
    return vertices, faces


def write_meshes(folder: Path, tiles: int, subdivisions: int = 6) -> dict[str, Path]:
    """The same mesh in every format of `FORMATS`, written into ``folder``."""
    import trimesh

    vertices, faces = tiled_spheres(tiles, subdivisions)
    folder.mkdir(parents=True, exist_ok=True)
    paths = {fmt: folder / f"spheres-{len(faces)}.{fmt}" for fmt in FORMATS}
    with open(paths["obj"], "w") as out:  # as exporters write it: 8 decimals, v and f lines
        np.savetxt(out, vertices, fmt="v %.8f %.8f %.8f")
        np.savetxt(out, faces + 1, fmt="f %d %d %d")
    triangles = np.zeros(len(faces), [("normal", "<f4", 3), ("corners", "<f4", (3, 3)),
                                      ("attributes", "<u2")])
    triangles["corners"] = vertices[faces]
    with open(paths["stl"], "wb") as out:
        out.write(b"reliefkit bench loading".ljust(80, b" "))
        out.write(np.uint32(len(faces)).tobytes())
        out.write(triangles.tobytes())
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    mesh.export(paths["ply"])
    mesh.export(paths["glb"])
    return paths


def measure(path: Path, warm_up: Path) -> dict:
    """Peak memory of loading ``path`` in a fresh process (after loading ``warm_up``)."""
    done = subprocess.run([sys.executable, "-c", _CHILD, str(path), str(warm_up)],
                          capture_output=True, text=True)
    if done.returncode != 0:  # the loader's one-line reason is the traceback's last line
        last = (done.stderr.strip().splitlines() or ["the loader failed"])[-1]
        raise MeshError(f"bench loading: {last.split(': ', 1)[-1]}")
    row = json.loads(done.stdout.strip().splitlines()[-1])
    size = path.stat().st_size
    used = (row["peak_kib"] - row["baseline_kib"]) * 1024
    return {"format": path.suffix[1:], "file_bytes": size, "baseline_bytes":
            row["baseline_kib"] * 1024, "peak_bytes": row["peak_kib"] * 1024,
            "load_bytes": used, "ratio": used / size, "seconds": row["seconds"],
            "triangles": row["triangles"], "vertices": row["vertices"]}


def markdown(results: dict) -> str:
    lines = ["| format | file | peak RSS | loading (peak - imports) | x file | seconds |",
             "|---|---|---|---|---|---|"]
    for r in results["rows"]:
        lines.append(f"| {r['format']} | {format_bytes(r['file_bytes'])} | "
                     f"{format_bytes(r['peak_bytes'])} | {format_bytes(r['load_bytes'])} | "
                     f"{r['ratio']:.2f} | {r['seconds']:.1f} |")
    rows = results["rows"]
    lines += ["", f"{rows[0]['triangles']:,} triangles; imports alone "
              f"{format_bytes(rows[0]['baseline_bytes'])} ({results['machine']}).", ""]
    for r in rows:
        met = "met" if r["ratio"] <= TARGET_RATIO else "NOT met"
        lines.append(f"- {r['format']}: {r['ratio']:.2f} x the file's size "
                     f"(target <= {TARGET_RATIO:g}): {met}")
    return "\n".join(lines) + "\n"


#: The small file that warms a process up for a format `write_meshes` does not write.
WARM_UP_FORMAT = {"gltf": "glb", "off": "ply"}


def run_suite(quick: bool, out: Path, log, mesh: str | None = None) -> tuple[str, list[Path]]:
    """The four formats of one generated mesh, or with ``mesh`` that file alone."""
    small = write_meshes(Path(out) / "loading-meshes", 1, subdivisions=1)
    if mesh is not None:
        path = Path(mesh)
        paths = {path.suffix[1:].lower(): path}
    else:
        tiles = 3 if quick else 25
        log(f"writing {tiles * 81920:,} triangles as {', '.join(FORMATS)}")
        paths = write_meshes(Path(out) / "loading-meshes", tiles)
    rows = []
    for fmt, path in paths.items():
        log(f"loading {path.name}")
        start = time.perf_counter()
        rows.append(measure(path, small[WARM_UP_FORMAT.get(fmt, fmt)]))
        log(f"{fmt}: {rows[-1]['ratio']:.2f} x the file, {time.perf_counter() - start:.1f} s")
    results = {"machine": f"{platform.processor() or platform.machine()}, Python "
                          f"{platform.python_version()}", "rows": rows}
    report = markdown(results)
    written = [Path(out) / "loading-bench.json", Path(out) / "loading-bench.md"]
    with atomic_path(written[0]) as tmp:
        tmp.write_text(json.dumps(results, indent=2))
    with atomic_path(written[1]) as tmp:
        tmp.write_text(report)
    return report, written
