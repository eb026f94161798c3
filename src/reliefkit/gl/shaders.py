"""Shader loading: namespaced package .glsl files, ``#include``, define variants, ``#line``.

Programs are named ``namespace:path`` (``"relief:relief.glsl"``); a bare path is in the
``core`` namespace (``reliefkit/shaders``), a technique's namespace is its package's
``shaders/`` folder. ``#include "core:include/shading.glsl"`` names a file absolutely;
``#include "heightfield.glsl"`` is relative to the including file's folder.

A program lives in one file with ``#if defined VERTEX_SHADER`` / ``FRAGMENT_SHADER`` /
``COMPUTE_SHADER`` sections. The file declares the defines it accepts on a line

    //! defines: METHOD_BINARY METHOD_EXACT WRITE_DEPTH

and, when it needs more than the draw-path default (GLSL 3.30), ``//! version: 430``.
Every program also gets ``RK_FRAME_ATTACHMENTS`` (the first free colour attachment, used by
shaders/include/iterations.glsl) and may be given ``COUNT_ITERATIONS``. Every piece is
preceded by a ``#line`` whose number encodes file and line (file k's line n is reported as
k * 100000 + n: Mesa ignores the source-string argument of ``#line``), so a compile error
raises GPUError("relief:relief.glsl:42: ...").

Draw-path programs can be built as GLSL ES 3.00 (``es=True``) for the browser viewer;
a test compiles each that way on llvmpipe.
"""

from __future__ import annotations

import posixpath
import re
from collections import OrderedDict
from collections.abc import Callable, Mapping
from functools import cache
from importlib import resources

from ..errors import GPUError
from .targets import FRAME_ATTACHMENTS

STAGES = ("VERTEX_SHADER", "GEOMETRY_SHADER", "FRAGMENT_SHADER", "COMPUTE_SHADER")
DEFAULT_VERSION = "330 core"
ES_VERSION = "300 es"
ES_PRECISION = ("precision highp float;", "precision highp int;",
                "precision highp sampler2D;", "precision highp sampler3D;",
                "precision highp usampler2D;", "precision highp isampler2D;")
MAX_INCLUDE_DEPTH = 8
LINE_BASE = 100000  # reported line = file index * LINE_BASE + line in that file
CACHE_SIZE = 128     # programs kept per context; the least recently used is released
CORE_DEFINES = {"COUNT_ITERATIONS"}  # accepted by every program (iterations.glsl)

_INCLUDE = re.compile(r'^\s*#include\s+"([^"]+)"\s*$')
_DEFINES = re.compile(r"^//!\s*defines:(.*)$", re.M)
_VERSION = re.compile(r"^//!\s*version:\s*(\d+)\s*$", re.M)
# Mesa: "0:12(5): error: ..." ; NVIDIA: "0(12) : error C0000: ..."
_ERROR_LOC = re.compile(r"^\s*(?:ERROR:\s*)?(\d+)[:(](\d+)\)?(?:\(\d+\))?\s*:\s*(.*)$", re.M)


def _core_only() -> Mapping[str, str]:
    return {"core": "reliefkit"}


_namespace_table: Callable[[], Mapping[str, str]] = _core_only


def use_namespaces(table: Callable[[], Mapping[str, str]]) -> None:
    """Where namespaces are found: ``table()`` maps each to the package whose ``shaders/``
    folder it is, asked on each lookup (the composition root hands over the registry's)."""
    global _namespace_table
    _namespace_table = table


def qualify(name: str, base: str | None = None) -> str:
    """``ns:path`` for ``name`` as written in a program call or an include in ``base``."""
    if ":" in name:
        ns, path = name.split(":", 1)
    elif base is None:
        ns, path = "core", name
    else:
        ns, base_path = base.split(":", 1)
        path = posixpath.join(posixpath.dirname(base_path), name)
    path = posixpath.normpath(path)
    if path.startswith("..") or posixpath.isabs(path):
        raise GPUError(f"shader path {name!r} leaves its namespace")
    return f"{ns}:{path}"


def read_shader_file(name: str) -> str:
    """The text of the shader ``ns:path``."""
    return _read_text(qualify(name))


def _read_text(name: str) -> str:
    ns, path = name.split(":", 1)
    namespaces = _namespace_table()
    if ns not in namespaces:
        raise GPUError(f"unknown shader namespace {ns!r} in {name!r} (known: "
                       f"{', '.join(sorted(namespaces))})")
    return _read_package_file(namespaces[ns], ns, path)


@cache
def _read_package_file(package: str, ns: str, path: str) -> str:
    file = resources.files(package).joinpath("shaders", *path.split("/"))
    if not file.is_file():
        raise GPUError(f"shader file not found: {ns}:{path}")
    return file.read_text(encoding="utf-8")


def _line_directive(file_id: int, line: int) -> str:
    """``#line`` making the next line report as file ``file_id``, line ``line``."""
    return f"#line {file_id * LINE_BASE + line} {file_id}"


def _expand(name: str, files: list[str], depth: int = 0) -> str:
    """Inline includes recursively, emitting ``#line`` so each piece keeps its numbering."""
    if depth > MAX_INCLUDE_DEPTH:
        raise GPUError(f"{name}: includes nested deeper than {MAX_INCLUDE_DEPTH}")
    if name not in files:
        files.append(name)
    file_id = files.index(name)
    out = [_line_directive(file_id, 1)]
    for lineno, line in enumerate(read_shader_file(name).splitlines(), start=1):
        match = _INCLUDE.match(line)
        if match:
            out.append(_expand(qualify(match.group(1), name), files, depth + 1))
            out.append(_line_directive(file_id, lineno + 1))
        else:
            out.append(line)
    return "\n".join(out)


def allowed_defines(name: str) -> set[str]:
    """The define names a program file declares on its ``//! defines:`` line(s)."""
    text = read_shader_file(qualify(name))
    return {word for m in _DEFINES.finditer(text) for word in m.group(1).split()} | CORE_DEFINES


def _define_lines(defines: dict) -> list[str]:
    lines = []
    for key, value in sorted(defines.items()):
        if value is False or value is None:
            continue
        lines.append(f"#define {key}" if value is True else f"#define {key} {value}")
    return lines


def stage_sources(name: str, defines: dict | None = None, *, es: bool = False) -> dict[str, str]:
    """Full source per stage present in the file, keyed by moderngl's argument names."""
    name = qualify(name)
    defines = dict(defines or {})
    unknown = set(defines) - allowed_defines(name)
    if unknown:
        known = ", ".join(sorted(allowed_defines(name))) or "none"
        raise GPUError(f"{name}: unknown define(s) {', '.join(sorted(unknown))} "
                       f"(known: {known})")
    text = read_shader_file(name)
    match = _VERSION.search(text)
    if es and match:
        raise GPUError(f"{name}: declares //! version: {match.group(1)}; not a draw-path "
                       "program, cannot build it as GLSL ES")
    version = ES_VERSION if es else (f"{match.group(1)} core" if match else DEFAULT_VERSION)
    body = _expand(name, files := [])
    sources = {}
    for stage in STAGES:
        if f"defined {stage}" not in text and f"defined({stage})" not in text:
            continue
        head = [f"#version {version}", *(ES_PRECISION if es else ()), f"#define {stage}",
                f"#define RK_FRAME_ATTACHMENTS {FRAME_ATTACHMENTS}", *_define_lines(defines)]
        sources[stage.split("_")[0].lower() + "_shader"] = "\n".join(head) + "\n" + body + "\n"
    if not sources:
        raise GPUError(f"{name}: no '#if defined VERTEX_SHADER' (or other stage) section")
    return sources | {"_files": files}


def _explain(exc: Exception, files: list[str]) -> str:
    """Turn a driver's compile log into 'ns:file.glsl:LINE: message'."""
    text = str(exc)
    match = _ERROR_LOC.search(text)
    if match:
        file_id, line = divmod(int(match.group(2)), LINE_BASE)
        if file_id < len(files):
            return f"{files[file_id]}:{line}: {match.group(3).strip()}"
    return " ".join(text.split())[:400]


def _cache_of(ctx) -> OrderedDict:
    """The program cache lives on the context itself, so two contexts never share entries."""
    extra = ctx.extra if isinstance(ctx.extra, dict) else {}
    ctx.extra = extra
    return extra.setdefault("reliefkit_programs", OrderedDict())


def program(ctx, name: str, defines: dict | None = None, *, es: bool = False):
    """A compiled and linked program for ``name`` with ``defines``, cached per context."""
    programs = _cache_of(ctx)
    key = (qualify(name), tuple(sorted((defines or {}).items())), es)
    if key in programs:
        programs.move_to_end(key)
        return programs[key]
    sources = stage_sources(name, defines, es=es)
    files = sources.pop("_files")
    try:
        if "compute_shader" in sources:
            prog = ctx.compute_shader(sources["compute_shader"])
        else:
            prog = ctx.program(**sources)
    except Exception as exc:  # moderngl raises plain Exception with the compiler log
        raise GPUError(f"shader compile failed: {_explain(exc, files)}") from None
    programs[key] = prog
    while len(programs) > CACHE_SIZE:
        _, oldest = programs.popitem(last=False)
        oldest.release()
    return prog
