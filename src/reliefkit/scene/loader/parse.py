"""Parsing with trimesh: referenced files come from the mesh's folder; failures raise `BadFile`."""

from __future__ import annotations

import io
import urllib.parse
from pathlib import Path

import numpy as np
import trimesh

from .badfile import BadFile, as_utf8


class _RecordingResolver(trimesh.resolvers.FilePathResolver):
    """Find referenced files next to the mesh and remember the ones that are missing.

    trimesh skips a missing .mtl, texture or image silently, so `parse_file` asks this resolver
    afterwards. Names are also tried URL-decoded (glTF URIs escape spaces as %20), and .mtl
    files are handed over as UTF-8 like the OBJ itself.
    """

    def __init__(self, source: Path):
        super().__init__(str(source))
        self.missing: list[str] = []
        self.outside: list[str] = []

    def get(self, name: str) -> bytes:
        for candidate in dict.fromkeys((name, urllib.parse.unquote(name))):
            try:
                data = super().get(candidate)
            except FileNotFoundError:
                continue
            except ValueError:  # the name leads out of the mesh's folder
                self.outside.append(name)
                raise
            return as_utf8(data, "MTL") if name.lower().endswith(".mtl") else data
        self.missing.append(name)
        raise FileNotFoundError(name)

    def problem(self) -> str | None:
        """A message for the first unusable reference, or None."""
        if self.missing:
            return f"references missing file '{self.missing[0]}' (looked in {self.parent})"
        if self.outside:
            return (
                f"references '{self.outside[0]}' outside its folder, which is not read; "
                "copy it next to the mesh"
            )
        return None


def parse_file(data: bytes, file_type: str, path: Path) -> trimesh.Scene:
    """Parse with trimesh, converting everything it raises into `BadFile`."""
    resolver = _RecordingResolver(path)
    try:
        with np.errstate(all="ignore"):  # trimesh's own arithmetic on odd but valid data
            scene = trimesh.load_scene(
                io.BytesIO(data), file_type=file_type, resolver=resolver, process=False
            )
    except Exception as exc:  # noqa: BLE001 - any parser failure is a bad file
        raise BadFile(resolver.problem() or _parse_failure(file_type, exc)) from None
    problem = resolver.problem()
    if problem:
        raise BadFile(problem)
    return scene if isinstance(scene, trimesh.Scene) else trimesh.Scene(scene)


def _parse_failure(file_type: str, exc: Exception) -> str:
    detail = " ".join(str(exc).split())[:200] or "no details"
    return (
        f"could not read it as {file_type.upper()} ({type(exc).__name__}: {detail}); "
        "is it corrupt or truncated?"
    )
