"""Parsing with trimesh, quietly: referenced files come from the mesh's folder (found as other
importers find them), and failures, also ones trimesh only logs, raise `BadFile`."""

from __future__ import annotations

import contextlib
import io
import logging
import os
import urllib.parse
import warnings
from pathlib import Path, PurePosixPath

import numpy as np
import trimesh

from .badfile import BadFile, as_utf8, read_regular
from .materials import begin_warnings, note_texture_problem
from .plain_obj import PlainObj
from .stl import BinaryStl


class RecordingResolver(trimesh.resolvers.FilePathResolver):
    """Find referenced files next to the mesh and remember the ones that are missing.

    trimesh skips a missing .mtl, texture or image silently, so `parse_file` asks this resolver
    afterwards (a missing buffer makes trimesh fail, and the resolver names it). Names are
    looked up as other importers do: also URL-decoded (glTF URIs escape spaces as %20), with
    `\\` as a separator (files written on Windows), and at last with any case, in the named
    subfolder or the mesh's own folder. Names that lead out of the folder are refused. .mtl
    files are handed over as UTF-8 like the OBJ itself. Only regular files within the size
    cap are read (`read_regular`): a FIFO, a device or a socket is refused and remembered,
    never opened for blocking reads.
    """

    def __init__(self, source: Path):
        super().__init__(str(source))
        # trimesh names geometry after the file and hashes those names as UTF-8: a file name
        # that is not valid UTF-8 (surrogate escapes) gets replacement characters there
        safe = os.fsencode(str(source)).decode("utf-8", "replace")
        self.file_path, self.file_name = safe, os.path.basename(safe)
        self.missing: list[str] = []
        self.outside: list[str] = []
        self.refused: list[tuple[str, str]] = []
        self.last_name: str | None = None  # the file asked for last (an image that may fail)

    def _read(self, candidate: str) -> bytes:
        """A name as trimesh's resolver looks it up, read only if it is a regular file."""
        stripped = candidate.strip()
        for option in (stripped, stripped.lstrip("/"), os.path.split(candidate)[-1]):
            try:
                path = Path(self.absolute(option))
            except ValueError:
                continue
            if os.path.lexists(path):
                return read_regular(path)
        self.absolute(candidate)  # raises ValueError for a name that leads out of the folder
        raise FileNotFoundError(candidate)

    def get(self, name: str) -> bytes:
        self.last_name = name
        unquoted = urllib.parse.unquote(name)
        spellings = (name, unquoted, name.replace("\\", "/"), unquoted.replace("\\", "/"))
        for candidate in dict.fromkeys(spellings):
            try:
                data = self._read(candidate)
            except BadFile as exc:
                self.refused.append((name, str(exc)))
                raise FileNotFoundError(name) from None
            except FileNotFoundError:
                continue
            except ValueError:  # the name leads out of the mesh's folder
                self.outside.append(name)
                raise
            return self._decoded(name, data)
        found = _any_case(Path(self.parent), PurePosixPath(spellings[-1].strip()))
        if found is None:
            self.missing.append(name)
            raise FileNotFoundError(name)
        try:
            data = read_regular(found)
        except BadFile as exc:
            self.refused.append((name, str(exc)))
            raise FileNotFoundError(name) from None
        return self._decoded(name, data)

    @staticmethod
    def _decoded(name: str, data: bytes) -> bytes:
        return as_utf8(data, "MTL") if name.lower().endswith(".mtl") else data

    def problem(self) -> str | None:
        """Why a parse that failed failed: the first unusable reference other than a missing
        .mtl, or None (a parse that succeeded did without them: see `warnings`)."""
        if self.refused:
            name, reason = self.refused[0]
            return f"references '{name}', which {reason.removeprefix('is ')}"
        missing = [m for m in self.missing if not _is_mtl(m)]
        if missing:
            return f"references missing file '{missing[0]}' (looked in {self.parent})"
        if self.outside:
            return (
                f"references '{self.outside[0]}' outside its folder, which is not read; "
                "copy it next to the mesh"
            )
        return None

    def warnings(self) -> list[str]:
        """One line per reference a parse that succeeded did without: a .mtl (the mesh renders
        with the default material) or a texture (drawn with its material's colour)."""
        why = {name: f"not found (looked in {self.parent})" for name in self.missing}
        why.update((name, "is outside the mesh's folder and is not read (copy it next to the "
                    "mesh)") for name in self.outside)
        why.update((name, reason) for name, reason in self.refused)
        return [f"material library '{name}' {reason}; using the default material"
                if _is_mtl(name) else
                f"texture '{name}' {reason}; drawn with the material colour instead"
                for name, reason in why.items()]

    def unread(self) -> set[str]:
        """The names of the references that were not read."""
        return {*self.missing, *self.outside, *(name for name, _ in self.refused)}


def _is_mtl(name: str) -> bool:
    return name.strip().lower().endswith(".mtl")


def _any_case(folder: Path, name: PurePosixPath) -> Path | None:
    """The file `name` inside `folder` matched with any case: its own path, else its file name.

    Only relative names without '..' are followed into subfolders (the others were refused or
    not found above); an absolute name from another machine is tried by its file name alone.
    """
    parts = [p for p in name.parts if p not in (".", "/")]
    if not parts:
        return None
    relative = not name.is_absolute() and ".." not in parts and ":" not in parts[0]
    for candidate in ([parts] if relative else []) + [parts[-1:]]:
        path = folder
        for part in candidate:
            path = _child_any_case(path, part)
            if path is None:
                break
        else:
            if path.is_file():
                return path
    return None


def _child_any_case(folder: Path, name: str) -> Path | None:
    if not folder.is_dir():
        return None
    return min((p for p in folder.iterdir() if p.name.lower() == name.lower()), default=None)


def parse_file(data: bytes | PlainObj | BinaryStl, file_type: str, path: Path,
               warnings_out: list[str] | None = None) -> trimesh.Scene:
    """Parse with trimesh quietly; what it raises, or logs as lost, becomes `BadFile`.

    `data` is the file's bytes, or the arrays of a plain OBJ (:mod:`.plain_obj`) or a binary
    STL (:mod:`.stl`), which trimesh turns into its scene as it would the file's. Problems
    that still leave a usable mesh (a .mtl or a texture that is missing, outside the mesh's
    folder or not a regular file) are appended to `warnings_out`, one line per file.
    """
    resolver = RecordingResolver(path)
    begin_warnings()  # a new load: notes a failed one may have left are forgotten
    try:
        with _quiet(resolver) as logged:
            source = (data.scene_kwargs(resolver.file_name)
                      if isinstance(data, (PlainObj, BinaryStl)) else io.BytesIO(data))
            scene = trimesh.load_scene(
                source, file_type=file_type, resolver=resolver, process=False
            )
            del source
    except MemoryError:
        raise BadFile(resolver.problem() or "ran out of memory while parsing it; is it corrupt, "
                      "or too large for this machine?") from None
    except RecursionError:
        raise BadFile(resolver.problem() or "is nested too deeply to parse (its scene graph or "
                      "structure recurses without end); is it corrupt?") from None
    except Exception as exc:  # noqa: BLE001 - any parser failure is a bad file
        raise BadFile(resolver.problem() or _parse_failure(file_type, exc)) from None
    problem = _data_lost(logged.messages)
    if problem:
        raise BadFile(problem)
    unread = resolver.unread()  # already explained by the resolver's warnings
    for name in dict.fromkeys(n for n in logged.failed_images if n not in unread):
        note_texture_problem(os.path.basename(name.replace("\\", "/")),
                             "could not be opened (corrupt, truncated or too large)")
    if warnings_out is not None:
        warnings_out.extend(resolver.warnings())
    return scene if isinstance(scene, trimesh.Scene) else trimesh.Scene(scene)


IMAGE_FAILURES = ("failed to load image", "unable to load image")  # trimesh's DEBUG notes


class _Collect(logging.Handler):
    """trimesh's log of one parse: warnings, and the images it could not open (which it
    notes only at DEBUG level and then drops), named by the resolver's last request."""

    def __init__(self, resolver=None) -> None:
        super().__init__(logging.DEBUG)
        self.messages: list[str] = []
        self.resolver = resolver
        self.failed_images: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        message = record.getMessage()
        if message.lower().startswith(IMAGE_FAILURES):
            name = getattr(self.resolver, "last_name", None) or "an embedded image"
            self.failed_images.append(name)
        elif record.levelno >= logging.WARNING:
            self.messages.append(message)


@contextlib.contextmanager
def _quiet(resolver=None):
    """Keep what trimesh logs and any library warns off the caller's handlers and stderr.

    Yields the messages trimesh logged at WARNING and above, for `_data_lost` to judge. Python
    warnings (Pillow's, numpy's) are dropped, and so is trimesh's arithmetic on odd but valid
    data (`np.errstate`).
    """
    log = logging.getLogger("trimesh")
    collect, propagate, level = _Collect(resolver), log.propagate, log.level
    log.addHandler(collect)
    log.propagate = False
    log.setLevel(logging.DEBUG)
    try:
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")
            yield collect
    finally:
        log.removeHandler(collect)
        log.propagate = propagate
        log.setLevel(level)


def _data_lost(messages: list[str]) -> str | None:
    """A message when trimesh said it left geometry undecoded (it only logs that)."""
    if not any("placeholder zeros" in m for m in messages):
        return None
    failed = [m for m in messages if m.startswith("failed to process extension")]
    detail = " ".join((failed or messages)[0].split())[:200]
    return f"could not be decoded ({detail}); is it corrupt?"


def _parse_failure(file_type: str, exc: Exception) -> str:
    detail = " ".join(str(exc).split())[:200] or "no details"
    return (
        f"could not read it as {file_type.upper()} ({type(exc).__name__}: {detail}); "
        "is it corrupt or truncated?"
    )
