"""The cache key of a bake: what decides whether an output on disk can be kept.

SHA-256 over the source file's bytes, the bytes of every file it references (by their
names relative to it: `reliefkit.io.meshes.references`), the kind, the bake options with
every default filled in (so giving a default explicitly keys the same) and reliefkit's
version. `reliefkit bake` and `reliefkit batch` both store it in the .rk manifest
(``cache_key``); a batch skips an asset whose output already holds its key.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
from pathlib import Path

from .. import __version__
from ..compact.compact import CompressOptions, bake_compression
from ..core.params import applicable, make, options_of
from ..core.technique import baker
from ..errors import MeshError

COMPRESSION = tuple(opt.name for opt in options_of(CompressOptions))


def split_options(kind: str, options: dict, what: str) -> tuple[dict, dict]:
    """``options`` (bake and compression options by name, as given) checked for ``kind``:
    (the baker's parameters, the compression's), each converted by its declaration; a
    flag that does not apply or a bad value is a UsageError naming ``what``."""
    _, chosen = baker(kind)
    compression = {k: v for k, v in options.items() if k in COMPRESSION}
    params = applicable({k: v for k, v in options.items() if k not in COMPRESSION},
                        chosen.options, what)
    return params, applicable(compression, options_of(CompressOptions), what)


def canonical_options(kind: str, options: dict, what: str) -> dict:
    """Every option of the bake, defaults filled in, as JSON values."""
    params, compression = split_options(kind, options, what)
    _, chosen = baker(kind)
    values = make(chosen.params, params, what)
    how = bake_compression(compression)
    return json.loads(json.dumps({"params": dataclasses.asdict(values),
                                  "compress": dataclasses.asdict(how)}))


def cache_key(kind: str, options: dict, source: bytes, files: dict[str, bytes],
              what: str = "bake") -> str:
    """The key of baking ``source`` (a mesh file's bytes, with ``files``: the files it
    references by relative name) as ``kind`` with ``options``."""
    record = {"reliefkit": __version__, "kind": kind,
              "options": canonical_options(kind, options, what),
              "source": hashlib.sha256(source).hexdigest(),
              "files": {name: hashlib.sha256(data).hexdigest()
                        for name, data in sorted(files.items())}}
    text = json.dumps(record, sort_keys=True, separators=(",", ":"), allow_nan=False)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def read_sources(path: Path) -> tuple[bytes, dict[str, bytes]]:
    """A mesh file's bytes and those of the files it references, by relative name."""
    from ..io.meshes.badfile import BadFile, read_regular  # trimesh: slow to import
    from ..io.meshes.references import referenced_files

    try:
        files = {name: read_regular(file) for name, file in referenced_files(path).items()}
        return read_regular(path), files
    except BadFile as exc:
        raise MeshError(f"{path}: {exc}") from None


def file_cache_key(path, kind: str, options: dict, what: str = "bake") -> str:
    """`cache_key` of a mesh file on disk (what `reliefkit bake` stores)."""
    source, files = read_sources(Path(path))
    return cache_key(kind, options, source, files, what)
