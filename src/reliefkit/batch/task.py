"""The task function every executor runs: one asset in, its .rk bytes (or one error) out.

`run_task(task)` takes and returns plain picklable data: the task carries the mesh file's
bytes and those of the files it references by relative name, so a worker needs no shared
file system (`reliefkit.io.meshes.load_mesh_bytes` loads them). A bad asset is a failed
`Result` with its one-line error, never an exception.
A worker process is prepared once (`prepare_worker`): its Mesa thread count and EGL device
are set before its GL context exists, which it then makes on its first task and keeps; every
task bakes on it explicitly (`reliefkit.gl.context.using`), the process-wide context is
never made.
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import os
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path

from ..bake import bake
from ..demo import tile_image
from ..errors import ReliefkitError, UsageError
from ..gl import context as gl_context
from ..io.rk import rk_bytes
from .jobs import Job
from .key import cache_key, read_sources, split_options

_context = None  # this worker's GL context (`_worker_context`)


@dataclass(frozen=True)
class Task:
    """One asset to bake, with everything a worker needs and nothing it must look up."""

    where: str                       # how the user named the asset (for messages)
    output: str                      # the .rk's path relative to --out (POSIX)
    kind: str
    options: dict                    # as given; checked up front (`jobs.check_jobs`)
    key: str                         # `key.cache_key` of what follows
    name: str                        # the mesh file's name
    source: bytes                    # its bytes
    files: dict = field(default_factory=dict)   # the files it references: {name: bytes}
    folder: str = ""                 # its folder, to name in messages instead of the worker's
    export_glb: bool = False         # also return the glTF export (`--export glb`)
    thumbnails: int = 0              # also the mesh's and the output's PNG at this size


@dataclass(frozen=True)
class Result:
    """What became of a task: ``ok`` with the file bytes, or ``failed`` with one line."""

    output: str
    status: str                      # "ok" or "failed"
    seconds: float
    rk: bytes | None = None
    glb: bytes | None = None
    figures: tuple = ()              # the bake's report lines (`bake_report`)
    warnings: tuple = ()             # the loader's and the bake's warnings
    error: str | None = None
    thumbnails: tuple = ()           # (the mesh's PNG, the output's PNG) when asked


def make_task(job: Job, *, export_glb: bool = False, thumbnails: int = 0) -> Task:
    """The task of ``job``: its files read now, its key computed from those very bytes."""
    source, files = read_sources(job.input)
    key = cache_key(job.kind, job.options, source, files, job.where)
    return Task(job.where, job.output, job.kind, job.options, key, job.input.name, source,
                files, str(job.input.parent), export_glb, thumbnails)


def prepare_worker(setup=None, *, threads: int | None = None,
                   device_index: int | None = None) -> None:
    """Make this process a baker, once, before its GL context exists: ``threads`` Mesa
    rasterizer threads (``LP_NUM_THREADS``) and as many for numba's parallel loops
    (``NUMBA_NUM_THREADS``, read when numba is imported), so workers x threads stay within
    the cores (2 workers of 2 numba threads each baked 6 relief tori in 55 s on 2 cores,
    with 1 each in 20 s); the EGL device ``device_index`` (EGL ignores
    ``CUDA_VISIBLE_DEVICES``); then ``setup()`` (the composition root's ``registry``: the
    kinds a task may name); the mesh loader is imported now, so an asset's time (and
    ``--timeout``) is its own."""
    if gl_context.has_context() or _context is not None:
        raise UsageError("prepare_worker must run before this process makes its GL context")
    if threads is not None:
        count = str(max(1, int(threads)))
        os.environ["LP_NUM_THREADS"] = os.environ["NUMBA_NUM_THREADS"] = count
    if device_index is not None:
        os.environ["GLCONTEXT_DEVICE_INDEX"] = str(int(device_index))
    if setup is not None:
        setup()
    from ..io.meshes import load_mesh  # noqa: F401 - trimesh now, not in the first asset's time


def run_task(task: Task) -> Result:
    """Bake ``task`` in this (prepared) process; never raises for a bad asset."""
    start = time.perf_counter()
    try:
        with _recorded_warnings() as caught, gl_context.using(_worker_context()):
            mesh, rep, notes = _bake(task)
            source_hash = hashlib.sha256(task.source).hexdigest()
            data = rk_bytes(rep, source_hash=source_hash, cache_key=task.key)
            glb = _export(rep, source_hash, task.key) if task.export_glb else None
            figures = [str(line) for line in getattr(rep, "bake_report", lambda: [])()]
            pictures = _thumbnails(mesh, rep, task.thumbnails, task.key) if task.thumbnails \
                else ()
    except ReliefkitError as exc:
        return _failed(task, start, str(exc))
    except MemoryError:
        return _failed(task, start, "ran out of memory while baking it")
    except Exception as exc:  # noqa: BLE001 - a bug meets one asset: the batch goes on
        detail = " ".join(str(exc).split())[:200]
        return _failed(task, start, f"internal error ({type(exc).__name__}: {detail})")
    notes += [f"warning: {w.message}" for w in caught]
    notes += [line for line in figures if line.startswith("warning:")]
    return Result(task.output, "ok", time.perf_counter() - start, data, glb,
                  tuple(line for line in figures if not line.startswith("warning:")),
                  tuple(" ".join(w.split()) for w in notes), thumbnails=pictures)


def _worker_context():
    """This worker's own GL context: made on its first task (after `prepare_worker` set its
    EGL device and threads; one that cannot be made fails that task in one line) and kept."""
    global _context
    if _context is None:
        _context = gl_context.create_context()
    return _context


@contextlib.contextmanager
def _recorded_warnings():
    """Python warnings of the bake, kept for the asset's record instead of printed by the
    worker (the CLI's policy: deprecations and numpy's floating-point notes are dropped)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("default")
        for category in (DeprecationWarning, PendingDeprecationWarning, RuntimeWarning):
            warnings.filterwarnings("ignore", category=category)
        yield caught


def _bake(task: Task):
    """The task's mesh loaded from its bytes (messages name it in the user's folder) and
    baked."""
    from ..io.meshes import load_mesh_bytes  # trimesh: slow to import

    mesh = load_mesh_bytes(str(Path(task.folder, task.name)), task.source, task.files)
    notes = [f"warning: {' '.join(str(w).split())}" for w in mesh.extra.get("warnings", ())]
    params, compression = split_options(task.kind, task.options, task.where)
    return mesh, bake(mesh, task.kind, compress=compression, **params), notes


def _thumbnails(mesh, rep, size: int, key: str) -> tuple[bytes, bytes]:
    """The mesh and what it was baked into from the default view, as PNG bytes that carry
    the bake's ``key`` (`sheet.thumbnail_key`: a rerun tells a stale one)."""
    from PIL import Image

    from .sheet import keyed_png_info

    pictures = []
    for obj in (mesh, rep):
        buffer = io.BytesIO()
        Image.fromarray(tile_image(obj, size=(size, size)), "RGBA").save(
            buffer, format="PNG", pnginfo=keyed_png_info(key))
        pictures.append(buffer.getvalue())
    return tuple(pictures)


def _export(rep, source_hash: str, key: str) -> bytes:
    from ..export.gltf import export_bytes  # the draw plans' modules: imported when asked

    return export_bytes(rep, source_hash=source_hash, cache_key=key)


def _failed(task: Task, start: float, error: str) -> Result:
    return failed(task, error, time.perf_counter() - start)


def failed(task: Task, error: str, seconds: float = 0.0) -> Result:
    """A failed result whose one line names the asset (a loader's message already does)."""
    named = error if task.name in error else f"{task.where}: {error}"
    return Result(task.output, "failed", seconds, error=" ".join(named.split()))
