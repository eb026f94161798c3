"""Shader loading: package .glsl files, ``#include``, define variants, ``#line``, a cache.

A program lives in one file with ``#if defined VERTEX_SHADER`` / ``FRAGMENT_SHADER`` /
``COMPUTE_SHADER`` sections. The file declares the defines it accepts on a line

    //! defines: METHOD_BINARY METHOD_EXACT WRITE_DEPTH

and, when it needs more than the draw-path default (GLSL 3.30), ``//! version: 430``.
Includes are resolved here (``#include "include/raybox.glsl"``, depth-limited) and every
piece is preceded by a ``#line`` whose number encodes file and line (file k's line n is
reported as k * 100000 + n: Mesa ignores the source-string argument of ``#line``), so a
compile error raises GPUError("shaders/relief.glsl:42: ...").
"""

from __future__ import annotations

import re
from functools import cache
from importlib import resources

from ..errors import GPUError

STAGES = ("VERTEX_SHADER", "GEOMETRY_SHADER", "FRAGMENT_SHADER", "COMPUTE_SHADER")
DEFAULT_VERSION = "330 core"
MAX_INCLUDE_DEPTH = 8
LINE_BASE = 100000  # reported line = file index * LINE_BASE + line in that file

_INCLUDE = re.compile(r'^\s*#include\s+"([^"]+)"\s*$')
_DEFINES = re.compile(r"^//!\s*defines:(.*)$", re.M)
_VERSION = re.compile(r"^//!\s*version:\s*(\d+)\s*$", re.M)
# Mesa: "0:12(5): error: ..." ; NVIDIA: "0(12) : error C0000: ..."
_ERROR_LOC = re.compile(r"^\s*(?:ERROR:\s*)?(\d+)[:(](\d+)\)?(?:\(\d+\))?\s*:\s*(.*)$", re.M)


@cache
def read_shader_file(name: str) -> str:
    """The text of ``reliefkit/shaders/<name>``."""
    path = resources.files("reliefkit").joinpath("shaders", name)
    if not path.is_file():
        raise GPUError(f"shader file not found: shaders/{name}")
    return path.read_text(encoding="utf-8")


def _line_directive(file_id: int, line: int) -> str:
    """``#line`` making the next line report as file ``file_id``, line ``line``."""
    return f"#line {file_id * LINE_BASE + line} {file_id}"


def _expand(name: str, files: list[str], depth: int = 0) -> str:
    """Inline includes recursively, emitting ``#line`` so each piece keeps its numbering."""
    if depth > MAX_INCLUDE_DEPTH:
        raise GPUError(f"shaders/{name}: includes nested deeper than {MAX_INCLUDE_DEPTH}")
    if name not in files:
        files.append(name)
    file_id = files.index(name)
    out = [_line_directive(file_id, 1)]
    for lineno, line in enumerate(read_shader_file(name).splitlines(), start=1):
        match = _INCLUDE.match(line)
        if match:
            out.append(_expand(match.group(1), files, depth + 1))
            out.append(_line_directive(file_id, lineno + 1))
        else:
            out.append(line)
    return "\n".join(out)


def allowed_defines(name: str) -> set[str]:
    """The define names a program file declares on its ``//! defines:`` line(s)."""
    text = read_shader_file(name)
    return {word for m in _DEFINES.finditer(text) for word in m.group(1).split()}


def _define_lines(defines: dict) -> list[str]:
    lines = []
    for key, value in sorted(defines.items()):
        if value is False or value is None:
            continue
        lines.append(f"#define {key}" if value is True else f"#define {key} {value}")
    return lines


def stage_sources(name: str, defines: dict | None = None) -> dict[str, str]:
    """Full source per stage present in the file, keyed by moderngl's argument names."""
    defines = dict(defines or {})
    unknown = set(defines) - allowed_defines(name)
    if unknown:
        known = ", ".join(sorted(allowed_defines(name))) or "none"
        raise GPUError(f"shaders/{name}: unknown define(s) {', '.join(sorted(unknown))} "
                       f"(known: {known})")
    text = read_shader_file(name)
    match = _VERSION.search(text)
    version = f"{match.group(1)} core" if match else DEFAULT_VERSION
    body = _expand(name, files := [])
    sources = {}
    for stage in STAGES:
        if f"defined {stage}" not in text and f"defined({stage})" not in text:
            continue
        head = [f"#version {version}", f"#define {stage}", *_define_lines(defines)]
        sources[stage.split("_")[0].lower() + "_shader"] = "\n".join(head) + "\n" + body + "\n"
    if not sources:
        raise GPUError(f"shaders/{name}: no '#if defined VERTEX_SHADER' (or other stage) section")
    return sources | {"_files": files}


def _explain(exc: Exception, files: list[str]) -> str:
    """Turn a driver's compile log into 'shaders/file.glsl:LINE: message'."""
    text = str(exc)
    match = _ERROR_LOC.search(text)
    if match:
        file_id, line = divmod(int(match.group(2)), LINE_BASE)
        if file_id < len(files):
            return f"shaders/{files[file_id]}:{line}: {match.group(3).strip()}"
    return " ".join(text.split())[:400]


_programs: dict = {}


def program(ctx, name: str, defines: dict | None = None):
    """A compiled and linked program for ``name`` with ``defines``, cached per context."""
    key = (id(ctx), name, tuple(sorted((defines or {}).items())))
    if key in _programs:
        return _programs[key]
    sources = stage_sources(name, defines)
    files = sources.pop("_files")
    try:
        if "compute_shader" in sources:
            prog = ctx.compute_shader(sources["compute_shader"])
        else:
            prog = ctx.program(**sources)
    except Exception as exc:  # moderngl raises plain Exception with the compiler log
        raise GPUError(f"shader compile failed: {_explain(exc, files)}") from None
    _programs[key] = prog
    return prog
