"""What a batch bakes: INPUTs expanded into jobs, each checked before anything is baked.

An INPUT is a mesh file, a folder (searched recursively for the formats the mesh loader
reads), a glob pattern, or a manifest (``.csv`` with the header ``input,kind,options``, or
``.jsonl`` with one ``{"input": ..., "kind": ..., "options": {...}}`` per line; inputs
relative to the manifest's folder; a row's kind defaults to ``--as``, its options go over
the command line's). Each output keeps its input's path relative to the folder, glob root
or manifest folder it came from: ``chairs/a.obj`` -> ``chairs/a.rk`` under ``--out``.
"""

from __future__ import annotations

import csv
import glob
import io
import json
import os
from dataclasses import dataclass, replace
from pathlib import Path, PurePosixPath

from ..core.technique import baker
from ..errors import UsageError
from .key import canonical_options

MANIFEST_SUFFIXES = (".csv", ".jsonl")
MANIFEST_FIELDS = ("input", "kind", "options")


@dataclass(frozen=True)
class Job:
    """One asset to bake: the mesh file, its output relative to ``--out`` (POSIX), the kind
    and the options as given (checked by `check_jobs`), and how the user named it."""

    input: Path
    output: str
    kind: str
    options: dict
    where: str
    kind_given_by: str = "--as"  # or "its manifest row's kind" (named in messages)
    row_options: dict | None = None  # a manifest row's own options (without the command's)


def expand_inputs(inputs, kind: str, options: dict, out: Path) -> list[Job]:
    """Every job the INPUTs name, in a stable order; files under ``out`` are never inputs
    (a second run must not bake the first one's exports). An INPUT that names nothing, or
    two jobs that would write the same output, is a UsageError."""
    if not inputs:
        raise UsageError("batch needs at least one INPUT (mesh files, folders, glob patterns "
                         "or a manifest)")
    jobs: dict[str, Job] = {}
    for spec in map(str, inputs):
        for job in _jobs_of(spec, kind, options, Path(out)):
            _add(jobs, job)
    return list(jobs.values())


def check_jobs(jobs: list[Job]) -> None:
    """Every job's kind and options checked as `reliefkit bake` checks them: the first bad
    one is a UsageError naming the asset and the option."""
    for job in jobs:
        what = f"{job.where} ({job.kind_given_by} {job.kind})"
        try:
            _, chosen = baker(job.kind)
            if "mesh" not in chosen.sources:
                raise UsageError(f"--as {job.kind} bakes a {' or '.join(chosen.sources)}, "
                                 "not a mesh")
            canonical_options(job.kind, job.options, what)
        except UsageError as exc:
            message = str(exc)
            if job.where not in message:
                message = f"{job.where}: {message}"
            if job.row_options is not None and _valid(job.kind, job.row_options, what):
                message += ("; the command line's options go to every row of a manifest: "
                            "give one only some kinds take in those rows' options")
            raise UsageError(message) from None


def _valid(kind: str, options: dict, what: str) -> bool:
    try:
        canonical_options(kind, options, what)
    except UsageError:
        return False
    return True


def _add(jobs: dict[str, Job], job: Job) -> None:
    """``job`` under its output; the same asset named twice alike is one job."""
    other = jobs.get(job.output)
    if other is None:
        jobs[job.output] = job
    elif (other.input.resolve(), other.kind, other.options) != \
            (job.input.resolve(), job.kind, job.options):
        raise UsageError(f"{other.where} and {job.where} would both write {job.output}; "
                         "rename one, or bake them into different --out folders")


def _mesh_suffixes() -> tuple[str, ...]:
    from ..io.meshes import SUPPORTED_EXTENSIONS  # trimesh: slow to import

    return SUPPORTED_EXTENSIONS


def _jobs_of(spec: str, kind: str, options: dict, out: Path):
    path = Path(spec)
    suffixes = _mesh_suffixes()
    if path.suffix.lower() in MANIFEST_SUFFIXES and path.is_file():
        yield from _manifest_jobs(path, kind, options, suffixes)
    elif path.is_dir():
        found = _outside(out, spec, [p for p in sorted(path.rglob("*"))
                                     if p.suffix.lower() in suffixes and p.is_file()])
        if not found:
            raise UsageError(f"{spec}: no mesh files ({' '.join(suffixes)}) in this folder")
        yield from (_job(p, path, kind, options, str(p)) for p in found)
    elif glob.has_magic(spec):
        found = _outside(out, spec, [Path(p) for p in sorted(glob.glob(spec, recursive=True))
                                     if Path(p).suffix.lower() in suffixes
                                     and Path(p).is_file()])
        if not found:
            raise UsageError(f"{spec}: the pattern matches no mesh file ({' '.join(suffixes)})")
        root = _glob_root(spec)
        yield from (_job(p, root, kind, options, str(p)) for p in found)
    elif path.is_file():
        if path.suffix.lower() not in suffixes:
            raise UsageError(f"{spec}: not a mesh file ({' '.join(suffixes)}) or a manifest "
                             f"({' '.join(MANIFEST_SUFFIXES)})")
        yield _job(path, path.parent, kind, options, spec)
    else:
        raise UsageError(f"{spec}: no such file or folder" if not os.path.lexists(spec) else
                         f"{spec}: not a file or folder")


def _job(path: Path, root: Path, kind: str, options: dict, where: str) -> Job:
    relative = PurePosixPath(*Path(os.path.relpath(path, root)).parts)
    return Job(path, str(relative.with_suffix(".rk")), kind, dict(options), where)


def _outside(out: Path, spec: str, paths: list[Path]) -> list[Path]:
    """``paths`` less those under ``out``; when that leaves none, a UsageError that says so
    ("no mesh files" would be wrong: they are there)."""
    kept = [p for p in paths if not _inside(p, out)]
    if paths and not kept:
        raise UsageError(f"{spec}: its {len(paths)} mesh file(s) are all inside --out {out}, "
                         "whose files a batch never takes as inputs (they may be an earlier "
                         "run's exports): give an --out outside the inputs' folders")
    return kept


def _inside(path: Path, folder: Path) -> bool:
    try:
        path.resolve().relative_to(folder.resolve())
    except ValueError:
        return False
    return True


def _glob_root(pattern: str) -> Path:
    """The folder a glob pattern starts from: its parts before the first wildcard."""
    parts = Path(pattern).parts
    fixed = []
    for part in parts[:-1]:
        if glob.has_magic(part):
            break
        fixed.append(part)
    return Path(*fixed) if fixed else Path(".")


def _manifest_jobs(path: Path, kind: str, options: dict, suffixes):
    root = path.parent
    for line, row in _manifest_rows(path):
        where = f"{path}:{line}"
        name = row.get("input")
        if not isinstance(name, str) or not name.strip():
            raise UsageError(f"{where}: no input")
        source = root / name.strip()
        if Path(name).is_absolute() or ".." in Path(name).parts:
            raise UsageError(f"{where}: input {name!r} must be a path inside the manifest's "
                             "folder")
        if source.suffix.lower() not in suffixes or not source.is_file():
            raise UsageError(f"{where}: {name}: " + ("no such file" if not source.exists()
                             else f"not a mesh file ({' '.join(suffixes)})"))
        row_kind = row.get("kind") or kind
        row_options = row.get("options") or {}
        if not isinstance(row_kind, str) or not isinstance(row_options, dict):
            raise UsageError(f"{where}: kind must be a string and options a JSON object")
        job = replace(_job(source, root, row_kind, {**options, **row_options},
                           f"{where} ({name})"), row_options=row_options)
        yield replace(job, kind_given_by="its manifest row's kind") if row.get("kind") else job


def _manifest_rows(path: Path):
    """(line number, {"input", "kind", "options"}) for each row of a CSV or JSONL manifest."""
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise UsageError(f"{path}: cannot read the manifest ({exc})") from None
    if path.suffix.lower() == ".jsonl":
        for number, line in enumerate(text.splitlines(), 1):
            if line.strip():
                yield number, _json_row(line, f"{path}:{number}")
        return
    reader = csv.DictReader(io.StringIO(text))
    if not reader.fieldnames or "input" not in reader.fieldnames or \
            set(reader.fieldnames) - set(MANIFEST_FIELDS):
        raise UsageError(f"{path}: a CSV manifest's header is {','.join(MANIFEST_FIELDS)} "
                         f"(kind and options optional), got {','.join(reader.fieldnames or [])}")
    for row in reader:
        where = f"{path}:{reader.line_num}"
        cell = (row.get("options") or "").strip()
        yield reader.line_num, {**row, "options": _json_object(cell, where) if cell else {}}


def _json_row(line: str, where: str) -> dict:
    row = _json_object(line, where)
    unknown = set(row) - set(MANIFEST_FIELDS)
    if unknown:
        raise UsageError(f"{where}: unknown field(s) {', '.join(sorted(unknown))} (a row has "
                         f"{', '.join(MANIFEST_FIELDS)})")
    return row


def _json_object(text: str, where: str) -> dict:
    try:
        value = json.loads(text)
    except (ValueError, RecursionError) as exc:
        raise UsageError(f"{where}: not valid JSON ({exc})") from None
    if not isinstance(value, dict):
        raise UsageError(f"{where}: expected a JSON object, got {text.strip()[:40]!r}")
    return value


__all__ = ["Job", "check_jobs", "expand_inputs"]
