"""A batch from INPUTs to outputs: plan, skip what is up to date, bake the rest on an
executor, write each result atomically in this process (the driver), report."""

from __future__ import annotations

import contextlib
import signal
import time
from pathlib import Path

from ..errors import FormatError, ReliefkitError, UsageError
from ..io.atomic import atomic_path, check_writable, written_together
from ..io.gltf.representation import stored_cache_key
from ..io.rk import read_manifest
from ..progress import progress_bar
from .jobs import Job, check_jobs, expand_inputs
from .key import cache_key, read_sources
from .local import LocalExecutor
from .report import AssetRecord, BatchInterrupted, BatchReport
from .sheet import (
    INDEX_NAME,
    SHEET_NAME,
    THUMBNAIL_SIZE,
    thumbnail_key,
    thumbnail_paths,
    write_sheet,
)
from .task import Result, Task, make_task

EXECUTORS = ("local", "ray")
EXPORTS = ("glb",)


def executor_for(name: str, *, workers=None, timeout=None, max_memory=None, setup=None,
                 address=None):
    """The executor ``name`` with its limits (checked now, before anything is planned)."""
    if name not in EXECUTORS:
        raise UsageError(f"--executor must be one of {', '.join(EXECUTORS)}, got {name!r}")
    if name == "ray":
        from .ray_executor import RayExecutor  # imports Ray only when it runs

        return RayExecutor(workers, timeout=timeout, max_memory=max_memory, setup=setup,
                           address=address)
    if address is not None:
        raise UsageError("--address names a Ray cluster: it goes with --executor ray")
    return LocalExecutor(workers, timeout=timeout, max_memory=max_memory, setup=setup)


def run_batch(inputs, kind: str, out, executor, *, force: bool = False,
              export: str | None = None, sheet: bool = False, progress: bool = True,
              **bake_options) -> BatchReport:
    """Bake every asset ``inputs`` name (`jobs.expand_inputs`) into ``out`` on ``executor``
    (an object with ``run(tasks, count, on_result)``: `local.LocalExecutor`); with
    ``sheet`` also each output's thumbnail beside its mesh's (`sheet.write_sheet`)."""
    if export is not None and export not in EXPORTS:
        raise UsageError(f"--export writes {', '.join(EXPORTS)}, got {export!r}")
    out = Path(out)
    check_writable(out, "--out", folder=True)
    jobs = expand_inputs(inputs, kind, bake_options, out)
    check_jobs(jobs)
    _check_no_input_overwritten(jobs, out, export)
    _make_folder(out)
    report = BatchReport(out, total=len(jobs))
    start = time.monotonic()
    try:
        with progress_bar("batch", len(jobs), enabled=progress, eta=True) as advance:
            todo = _plan(jobs, out, force, export, sheet, report, advance)
            by_output = {job.output: job for job in todo}

            def finished(task: Task, result: Result) -> None:
                with _uninterrupted():  # the files and their line, or neither
                    record = _committed(by_output[task.output], task, result, out)
                    if record.status == "ok":
                        report.stale_removed += _remove_stale(out, task, result)
                    report.add(record)
                advance(len(report.records))

            executor.run(_tasks(todo, export, sheet, report, advance), len(todo), finished)
    except KeyboardInterrupt as exc:
        report.seconds = time.monotonic() - start
        raise BatchInterrupted(report) from exc
    report.seconds = time.monotonic() - start
    if sheet:
        report.wrote += write_sheet(out, report)
    elif report.ok and (out / SHEET_NAME).exists():
        report.notes.append(f"warning: {out / SHEET_NAME} and {INDEX_NAME} are from an earlier "
                            f"run: they do not show the {len(report.ok)} asset(s) baked now; "
                            "rerun with --sheet")
    return report


def _make_folder(out: Path) -> None:
    """``out`` made, or a UsageError (exit status 2, as for any output refused before work):
    a folder the access check lets through can still fail (root under /proc: exit 1 before)."""
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise UsageError(f"--out {out}: cannot make the folder ({exc.strerror or exc})") \
            from None


@contextlib.contextmanager
def _uninterrupted():
    """Ctrl-C and SIGTERM wait until the block is done (POSIX; elsewhere they do not), so an
    output committed is also recorded in batch.jsonl: a rerun then counts it once."""
    if not hasattr(signal, "pthread_sigmask"):
        yield
        return
    held = {signal.SIGINT, signal.SIGTERM}
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, held)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


def _check_no_input_overwritten(jobs: list[Job], out: Path, export: str | None) -> None:
    """Refuse, before anything is written, a batch whose outputs would replace one of its
    inputs (``--export glb`` beside a .glb source baked into its own folder replaced it)."""
    sources = {job.input.resolve(): job for job in jobs}
    for job in jobs:
        rk_path = out / job.output
        for path in [rk_path] + ([rk_path.with_suffix(f".{export}")] if export else []):
            source = sources.get(path.resolve())
            if source is not None:
                raise UsageError(f"{path} would be written over the input {source.input}: "
                                 "give an --out outside the inputs' folders")


def _plan(jobs: list[Job], out: Path, force: bool, export: str | None, sheet: bool,
          report: BatchReport, advance) -> list[Job]:
    """The jobs to bake; those whose outputs hold their key are recorded as skipped (each
    read and hashed here: a library's plan takes a while, so it shows as progress)."""
    todo = []
    for job in jobs:
        if force:
            todo.append(job)
            continue
        try:
            key = cache_key(job.kind, job.options, *read_sources(job.input), job.where)
        except ReliefkitError:
            todo.append(job)  # its task fails with the one line (`_tasks`)
            continue
        if _up_to_date(out, job.output, key, export, sheet):
            report.add(AssetRecord(job.where, job.output, job.kind, "skipped", key=key))
            advance(len(report.records))
        else:
            todo.append(job)
    return todo


def _up_to_date(out: Path, output: str, key: str, export: str | None, sheet: bool) -> bool:
    """Whether the .rk ``output`` holds ``key``, and so do the export and the thumbnails
    asked for (one left from an earlier bake is stale: the asset is baked again)."""
    path = out / output
    if export is not None and stored_cache_key(path.with_suffix(f".{export}")) != key:
        return False
    if sheet and any(thumbnail_key(p) != key for p in thumbnail_paths(out, output)):
        return False
    try:
        return path.is_file() and read_manifest(path).get("cache_key") == key
    except FormatError:
        return False  # a file that is no valid .rk is baked again


def _tasks(jobs: list[Job], export: str | None, sheet: bool, report: BatchReport, advance):
    """Each job's task, its files read as it is handed out; one whose files cannot be read
    is failed here, with its line."""
    for job in jobs:
        try:
            yield make_task(job, export_glb=export == "glb",
                            thumbnails=THUMBNAIL_SIZE if sheet else 0)
        except ReliefkitError as exc:
            report.add(AssetRecord(job.where, job.output, job.kind, "failed",
                                   error=" ".join(str(exc).split())))
            advance(len(report.records))


def _remove_stale(out: Path, task: Task, result: Result) -> int:
    """Remove the .glb and thumbnails beside a just-baked .rk that an earlier bake made
    (they hold another cache key) and this one did not write again: left, they showed the
    old bake beside the new .rk. Files without a key (not reliefkit's) stay. How many."""
    path = out / task.output
    stale = []
    if result.glb is None and stored_cache_key(path.with_suffix(".glb")) not in (None, task.key):
        stale.append(path.with_suffix(".glb"))
    if not result.thumbnails:
        stale += [p for p in thumbnail_paths(out, task.output)
                  if thumbnail_key(p) not in (None, task.key)]
    for file in stale:
        file.unlink(missing_ok=True)
    return len(stale)


def _committed(job: Job, task: Task, result: Result, out: Path) -> AssetRecord:
    """``result`` written under ``out`` (the .rk and its export together, atomically), as
    its record; a write that fails fails the asset."""
    record = AssetRecord(job.where, job.output, job.kind, result.status, result.seconds,
                         figures=result.figures, warnings=result.warnings,
                         error=result.error, key=task.key)
    if result.status != "ok":
        return record
    path = out / job.output
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with written_together():
            extras = [(path.with_suffix(".glb"), result.glb)] if result.glb is not None else []
            if result.thumbnails:
                extras += zip(thumbnail_paths(out, job.output), result.thumbnails, strict=True)
            for extra, data in extras:  # written with the .rk, which holds the key
                extra.parent.mkdir(parents=True, exist_ok=True)
                with atomic_path(extra) as tmp:
                    tmp.write_bytes(data)
            with atomic_path(path) as tmp:
                tmp.write_bytes(result.rk)
    except (ReliefkitError, OSError) as exc:
        return AssetRecord(job.where, job.output, job.kind, "failed", result.seconds,
                           error=f"{job.where}: {exc}", key=task.key)
    written = len(result.rk) + len(result.glb or b"")
    return AssetRecord(job.where, job.output, job.kind, "ok", result.seconds, written,
                       result.figures, result.warnings, key=task.key)
