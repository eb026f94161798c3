"""The .gltf form of a document: JSON, one .bin buffer and PNG image files side by side.

`write_gltf` writes the three kinds of file together (`io.atomic.written_together`: all or
none); `read_gltf` reads them back with the GLB reader's discipline: the JSON's size capped,
the buffer and each image a plain file name in the document's own folder (no paths, no
``data:`` or remote URIs), each file's size checked against the document's claims and the
total against ``max_bytes`` before it is read, then the same layout checks as a GLB.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

from ...errors import FormatError
from ..atomic import atomic_path, written_together
from .glb import DEFAULT_MAX_BYTES, MAX_JSON_BYTES, Glb, GlbBuilder, check_layout, parse_document

__all__ = ["gltf_builder", "write_gltf", "read_gltf"]

_FILE_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.-]*\Z")


def gltf_builder(path) -> GlbBuilder:
    """A builder for the .gltf ``path``: its images become files named after it."""
    return GlbBuilder(image_files=f"{Path(path).stem}_")


def write_gltf(path, builder: GlbBuilder) -> Path:
    """Write ``builder``'s document as ``path`` (.gltf), ``STEM.bin`` and its image files,
    atomically and all together; the paths written, the document first."""
    path = Path(path)
    document, binary = builder.finish()
    outputs = dict(builder.files)
    if binary:
        document["buffers"][0]["uri"] = f"{path.stem}.bin"
        outputs[f"{path.stem}.bin"] = binary
    text = json.dumps(document, sort_keys=True, separators=(",", ":"), allow_nan=False)
    with written_together(error=FormatError):
        for name, data in outputs.items():
            with atomic_path(path.with_name(name), error=FormatError) as tmp:
                Path(tmp).write_bytes(data)
        with atomic_path(path, error=FormatError) as tmp:
            Path(tmp).write_text(text + "\n", encoding="utf-8")
    return path


def read_gltf(path, *, max_bytes: int = DEFAULT_MAX_BYTES) -> Glb:
    """Read and validate a .gltf, its .bin and its PNG image files (see the module's
    docstring); a one-line `FormatError` naming ``path`` for anything wrong."""
    path = Path(path)
    if not path.is_file():
        raise FormatError(f"{path}: {'is not a file' if path.exists() else 'no such file'}")
    try:
        return _read(path, max_bytes)
    except FormatError as exc:
        raise FormatError(f"{path}: {exc}") from None
    except OSError as exc:
        raise FormatError(f"{path}: cannot read ({exc.strerror or exc}); check the path and "
                          "its permissions") from None


def _read(path: Path, max_bytes: int) -> Glb:
    size = path.stat().st_size
    if size > MAX_JSON_BYTES:
        raise FormatError(f"the JSON is {size:,} bytes, over the {MAX_JSON_BYTES:,}-byte limit")
    document = parse_document(path.read_bytes(), "the file")
    buffers = document.get("buffers", [])
    wanted = {}
    if isinstance(buffers, list) and len(buffers) == 1 and isinstance(buffers[0], dict):
        wanted[_file_of(buffers[0].get("uri"), "buffers[0]")] = "buffer"
    images = document.get("images", [])
    for k, image in enumerate(images if isinstance(images, list) else []):
        if isinstance(image, dict) and "uri" in image:
            wanted[_file_of(image["uri"], f"images[{k}]")] = "image"
    sizes = {}
    for name in wanted:
        file = path.with_name(name)
        if not file.is_file():
            raise FormatError(f"{name} (beside it) is missing; copy the .gltf with its .bin and "
                              "image files")
        sizes[name] = file.stat().st_size
    if sum(sizes.values()) > max_bytes:
        raise FormatError(f"its files hold {sum(sizes.values()):,} bytes, over the "
                          f"{max_bytes:,}-byte limit; pass a larger max_bytes if you trust it")
    binary, files = b"", {}
    for name, what in wanted.items():
        data = path.with_name(name).read_bytes()
        if len(data) != sizes[name]:
            raise FormatError(f"{name} changed while it was read")
        if what == "buffer":
            binary = data
        else:
            files[name] = data
    check_layout(document, len(binary), files=files, external_buffer=True)
    return Glb(document, binary, files)


def _file_of(uri, where: str) -> str:
    if not isinstance(uri, str) or not _FILE_NAME.match(uri) or uri in (".", ".."):
        raise FormatError(f"{where} has uri {uri!r}; reliefkit reads only plain file names "
                          "beside the .gltf (no folders, data: or remote URIs)")
    return uri
