"""The .rk container: one baked representation in a zip that plain numpy can open.

An .rk file is a zip of ``ZIP_DEFLATED`` members (``ZIP_STORED`` ones, as older versions
wrote, are read too): ``manifest.json`` and one ``NAME.npy`` member per array, so
``numpy.load(path, allow_pickle=False)`` reads it. The manifest names the format and its
version, the representation *kind* and the kind's version, the bake parameters, the source
file's SHA-256 and, per array, its dtype, shape and the SHA-256 of its (uncompressed)
``.npy`` member.

Kinds are `Codec` objects in a `CodecTable`: `save` / `load` find one by the
representation's type and by the manifest's ``kind``, in the table they are given or, by
default, in the one the composition root handed over (`use_codecs`). Writing is
atomic (temp file in the same folder, fsync, ``os.replace``) and deterministic (fixed dates,
order and deflate level). Reading validates everything it can from the zip directory, the
manifest and the ``.npy`` headers *before* allocating any array, then streams each member
through its own bounded reader (never more bytes than declared, stream length exact) while
verifying checksums, then finiteness. Every problem raises `FormatError`. See
``docs/format.md``.
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import itertools
import json
import math
import re
import struct
import zipfile
import zlib
from collections.abc import Callable, Iterable, Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.lib import format as npy

from .. import __version__
from ..compact.encodings import EncodedImage, check, decoded, encoding_of, stored_bytes
from ..errors import FormatError, ReliefkitError
from .atomic import atomic_path

__all__ = [
    "ArraySpec", "Codec", "CodecTable", "RkFile", "use_codecs",
    "save", "load", "read_manifest", "codec_of", "write_rk", "read_rk", "file_sha256",
    "array_bytes", "prepare", "check_stored", "check_finite_arrays", "stored_form",
    "decoded_array", "build", "codec_table",
    "FORMAT_NAME", "FORMAT_VERSION", "DEFAULT_MAX_BYTES",
]

FORMAT_NAME = "reliefkit"
FORMAT_VERSION = 1
MANIFEST_NAME = "manifest.json"
MAX_MANIFEST_BYTES = 1 << 20
DEFAULT_MAX_BYTES = 4 << 30

_MAX_NPY_HEADER = 4096                 # ours are ~128 bytes; numpy's own default is 10000
_HEADER_PEEK = _MAX_NPY_HEADER + 16    # magic + version (8) + length field (<= 4) + header
_CHUNK = 1 << 20
_FORCE_ZIP64 = 1 << 30                 # members this large get zip64 headers up front
_ZIP_DATE = (1980, 1, 1, 0, 0, 0)      # fixed, so equal inputs give byte-identical files
_DEFLATE_LEVEL = 1                     # fixed (determinism); see docs/format.md for the choice
_MAX_DEFLATE_RATIO = 1032              # deflate's most output per input byte (258 B per 2 bits)
_METHODS = (zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED)  # what is read; deflated is written
_OTHER_METHODS = {zipfile.ZIP_BZIP2: "bzip2", zipfile.ZIP_LZMA: "lzma", 9: "deflate64",
                  93: "zstandard", 95: "xz", 98: "ppmd"}
_LOCAL_HEADER = struct.Struct("<4s5H3L2H")  # the 30 fixed bytes of a zip local file header
_LOCAL_MAGIC = b"PK\x03\x04"
_FLAG_ENCRYPTED = 0x1 | 0x40               # traditional or strong encryption
_FLAG_PATCHED = 0x20                       # "compressed patched data"
_FLAG_UTF8 = 0x800
_KIND_RE = re.compile(r"[a-z][a-z0-9_.-]*\Z")
_NAME_RE = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
_SHA_RE = re.compile(r"[0-9a-f]{64}\Z")


# ------------------------------------------------------------------------------ kinds


@dataclass(frozen=True)
class ArraySpec:
    """What one array of a kind may look like.

    Attributes
    ----------
    dtypes : allowed numpy dtype names, e.g. ``("float32",)`` or ``("uint8", "uint16")``;
        stored little-endian.
    ndim : allowed number of dimensions (one int or a tuple of them).
    required : whether every file of the kind must hold the array.
    finite : whether NaN and Inf are forbidden (checked on write and after reading).
    trailing : fixed trailing dimensions, ``None`` for a free one, e.g. ``(4, 4)``.
    max_size : the most elements the kind accepts (its own limits, such as a texture's
        texels), or None; checked on the declared shape, before any data is inflated.
    role : what `reliefkit.compact.compress` may do to it: ``"color"`` (uint8 sRGB colour
        with alpha, or float32 linear colour: block-compressed sRGB), ``"normal"`` (unit
        vectors, float32 in [-1, 1] or uint8 as (n + 1) / 2: block-compressed),
        ``"height"`` (float32 in [0, 1], 0 empty: quantized), or None: stored exactly
        (positions, occupancy, derived data).
    """

    dtypes: tuple[str, ...]
    ndim: int | tuple[int, ...]
    required: bool = True
    finite: bool = False
    trailing: tuple[int | None, ...] | None = None
    max_size: int | None = None
    role: str | None = None


#: The roles an `ArraySpec` may declare (what `reliefkit.compact` may encode it as).
ROLES = ("color", "normal", "height")


#: The optional array of a baked representation that keeps its source mesh's bounds, so
#: views frame it as they frame the mesh (`scene.views.framing_bounds`).
SOURCE_BOUNDS = ArraySpec(("float64",), ndim=2, trailing=(2, 3), required=False, finite=True)


@dataclass(frozen=True)
class Codec:
    """How one representation class maps to arrays and JSON parameters.

    Attributes
    ----------
    kind : the manifest's ``kind`` string (lower case, e.g. ``"mesh"``).
    cls : the representation class it encodes; `save` finds the codec by this type.
    arrays : array name -> `ArraySpec`.
    to_arrays : ``rep -> (arrays, params)``; optional arrays may be left out or None.
    from_arrays : ``(arrays, params) -> rep``; gets validated arrays only.
    version : the kind's own version; files with a newer one are refused.
    check_shapes : ``{name: shape} -> None``, raising `FormatError` where the arrays' shapes
        disagree (a colour image not the size of its height field), or None; run on the
        declared shapes before anything is inflated, and before writing.
    rederive : ``(arrays, params) -> arrays``: the arrays derived from others (safety radii
        from heights) computed again, for `reliefkit.compact.compress` once it changed the
        values they derive from; None when nothing derived is stored.
    """

    kind: str
    cls: type
    arrays: dict[str, ArraySpec]
    to_arrays: Callable[[object], tuple[dict[str, np.ndarray], dict]]
    from_arrays: Callable[[dict[str, np.ndarray], dict], object]
    version: int = 1
    check_shapes: Callable[[dict[str, tuple[int, ...]]], None] | None = None
    rederive: Callable[[dict[str, np.ndarray], dict], dict[str, np.ndarray]] | None = None


@dataclass(frozen=True)
class RkFile:
    """The validated content of an .rk file (what `read_rk` returns)."""

    kind: str
    manifest: dict
    params: dict
    arrays: dict[str, np.ndarray]


class CodecTable:
    """The kinds a reader or writer knows: by manifest ``kind`` and by representation class.

    Immutable; built from codecs, each checked (kind name, version, array specs), and a kind
    or a class claimed twice refused with `FormatError`. The registry
    (`reliefkit.core.technique.Registry.codecs`) derives the process's table from the
    techniques it holds; `use_codecs` hands it to the functions here.
    """

    def __init__(self, codecs: Iterable[Codec] = ()) -> None:
        self._by_kind: dict[str, Codec] = {}
        self._by_class: dict[type, Codec] = {}
        for codec in codecs:
            self._add(codec)

    def _add(self, codec: Codec) -> None:
        if not isinstance(codec, Codec):
            raise FormatError(f"a codec table needs Codecs, got {type(codec).__name__}")
        if not isinstance(codec.kind, str) or not _KIND_RE.match(codec.kind):
            raise FormatError(f"invalid kind {codec.kind!r}: use lower-case letters, digits, _.-")
        if type(codec.version) is not int or codec.version < 1:
            raise FormatError(f"kind '{codec.kind}': version must be an int >= 1")
        for name, spec in codec.arrays.items():
            _check_spec(codec.kind, name, spec)
        old = self._by_kind.get(codec.kind)
        if old is not None:
            raise FormatError(f"kind '{codec.kind}' is already registered for "
                              f"{old.cls.__qualname__}; pick another kind name")
        other = self._by_class.get(codec.cls)
        if other is not None:
            raise FormatError(f"{codec.cls.__qualname__} is already registered as kind "
                              f"'{other.kind}'; unregister it first")
        self._by_kind[codec.kind] = codec
        self._by_class[codec.cls] = codec

    def __iter__(self) -> Iterator[Codec]:
        return iter(self._by_kind.values())

    @property
    def kinds(self) -> tuple[str, ...]:
        """The kinds it reads and writes, sorted."""
        return tuple(sorted(self._by_kind))

    def for_kind(self, kind) -> Codec:
        codec = self._by_kind.get(kind) if isinstance(kind, str) else None
        if codec is None:
            known = ", ".join(self.kinds) or "none"
            raise FormatError(f"unknown kind {kind!r} (known kinds: {known}); register the "
                              "technique that reads it, or upgrade reliefkit")
        return codec

    def for_object(self, rep) -> Codec:
        for cls in type(rep).__mro__:
            if cls in self._by_class:
                return self._by_class[cls]
        raise FormatError(f"cannot save a {type(rep).__qualname__}: no .rk kind is registered "
                          "for it; register the technique that declares its Codec")


_codec_table: Callable[[], CodecTable] = CodecTable


def use_codecs(table: Callable[[], CodecTable]) -> None:
    """Where the functions here find their kinds when they are not given ``codecs``:
    ``table()`` is asked on each call (the composition root hands over the registry's)."""
    global _codec_table
    _codec_table = table


def _table(codecs: CodecTable | None) -> CodecTable:
    return codecs if codecs is not None else _codec_table()


def codec_table(codecs: CodecTable | None = None) -> CodecTable:
    """``codecs``, or the process's table (the one handed to `use_codecs`)."""
    return _table(codecs)


def _check_spec(kind: str, name: str, spec: ArraySpec) -> None:
    where = f"kind '{kind}', array {name!r}"
    if not isinstance(name, str) or not _NAME_RE.match(name):
        raise FormatError(f"{where}: array names must be Python identifiers")
    if not isinstance(spec, ArraySpec) or not spec.dtypes:
        raise FormatError(f"{where}: needs an ArraySpec with at least one dtype")
    for text in spec.dtypes:
        try:
            dtype = np.dtype(text)
        except TypeError:
            raise FormatError(f"{where}: {text!r} is not a numpy dtype") from None
        if dtype.hasobject or dtype.fields is not None or dtype.subdtype is not None:
            raise FormatError(f"{where}: dtype {text!r} is not a plain numeric dtype")
    if spec.role is not None and spec.role not in ROLES:
        raise FormatError(f"{where}: role {spec.role!r} is none of {', '.join(ROLES)}")
    tail = len(spec.trailing or ())
    if any(type(n) is not int or n < tail for n in _ndims(spec)):
        raise FormatError(f"{where}: ndim must be ints >= the number of trailing dims")


def _ndims(spec: ArraySpec) -> tuple[int, ...]:
    return spec.ndim if isinstance(spec.ndim, tuple) else (spec.ndim,)


# --------------------------------------------------------------------- shared checks


def _expected_shape(spec: ArraySpec) -> str:
    tail = ["*" if t is None else str(t) for t in (spec.trailing or ())]
    forms = []
    for n in _ndims(spec):
        dims = ["*"] * (n - len(tail)) + tail
        forms.append("(" + ", ".join(dims) + ("," if n == 1 else "") + ")")
    return " or ".join(forms)


def _check_array(kind: str, name: str, spec: ArraySpec, dtype: np.dtype, shape: tuple) -> None:
    """Dtype and shape of one array against its spec (no data needed)."""
    if dtype.hasobject:
        raise FormatError(f"array '{name}' has an object dtype (pickled Python objects); "
                          "reliefkit never stores or loads pickles")
    allowed = [np.dtype(d).newbyteorder("<") for d in spec.dtypes]
    if dtype not in allowed:
        names = ", ".join(spec.dtypes)
        raise FormatError(f"array '{name}' has dtype {dtype.str}; kind '{kind}' allows {names} "
                          "(little-endian)")
    tail = spec.trailing or ()
    ok = len(shape) in _ndims(spec) and all(
        t is None or s == t for s, t in zip(shape[len(shape) - len(tail):], tail, strict=True))
    if not ok:
        raise FormatError(f"array '{name}' has shape {tuple(shape)}; kind '{kind}' expects "
                          f"{_expected_shape(spec)}")
    if spec.max_size is not None and math.prod(shape) > spec.max_size:
        raise FormatError(f"array '{name}' has shape {tuple(shape)}, {math.prod(shape):,} "
                          f"elements; kind '{kind}' takes at most {spec.max_size:,}")


def _check_array_set(codec: Codec, names: Iterable[str]) -> None:
    names = set(names)
    missing = [n for n, s in codec.arrays.items() if s.required and n not in names]
    if missing:
        raise FormatError(f"missing required array '{missing[0]}' (kind '{codec.kind}' needs "
                          f"{', '.join(n for n, s in codec.arrays.items() if s.required)})")
    unknown = sorted(names - set(codec.arrays))
    if unknown:
        raise FormatError(f"unknown array {unknown[0]!r} for kind '{codec.kind}' (it has: "
                          f"{', '.join(codec.arrays)})")


def _check_finite(name: str, arr: np.ndarray) -> None:
    if arr.dtype.kind in "fc" and not np.isfinite(arr).all():
        bad = int(np.count_nonzero(~np.isfinite(arr)))
        raise FormatError(f"array '{name}' has {bad} NaN or Inf values where finite values "
                          "are required")


def _check_json(value, where: str = "params") -> None:
    """Allow only what JSON stores faithfully (tuples come back as lists)."""
    if value is None or isinstance(value, (str, bool, int)):
        return
    if isinstance(value, float):
        if not math.isfinite(value):
            raise FormatError(f"{where} is {value}; JSON cannot store NaN or Inf")
        return
    if isinstance(value, (list, tuple)):
        for i, item in enumerate(value):
            _check_json(item, f"{where}[{i}]")
        return
    if isinstance(value, dict):
        for key, item in value.items():
            if not isinstance(key, str):
                raise FormatError(f"{where} has key {key!r}; JSON keys must be strings")
            _check_json(item, f"{where}[{key!r}]")
        return
    raise FormatError(f"{where} is a {type(value).__name__}, which JSON cannot store; convert "
                      "it (float(), int(), .tolist()) or store it as an array")


def _check_source_hash(value, field: str = "source_hash") -> None:
    """``source_hash`` and ``cache_key`` (the same check): None or a SHA-256 hex digest."""
    if value is not None and not (isinstance(value, str) and _SHA_RE.match(value)):
        how = ("use reliefkit.io.rk.file_sha256" if field == "source_hash" else
               "use reliefkit.batch.key.cache_key")
        raise FormatError(f"{field} must be None or 64 lower-case hex digits, got {value!r}"
                          f"; {how}")


# --------------------------------------------------------------------------- writing


def array_bytes(representation, *, codecs: CodecTable | None = None) -> dict[str, int]:
    """Bytes of each array a representation stores (its memory, uncompressed; an encoded
    array: its encoded level 0, as the file stores it), by name."""
    arrays, _ = _table(codecs).for_object(representation).to_arrays(representation)
    return {name: int(np.asarray(a).nbytes if encoding_of(a) is None
                      else encoding_of(a).data.size)
            for name, a in arrays.items() if a is not None}


def save(path, representation, *, source_hash: str | None = None,
         cache_key: str | None = None, codecs: CodecTable | None = None) -> Path:
    """Write a representation to an .rk file atomically.

    Parameters
    ----------
    path : destination file; its folder must exist.
    representation : an object whose type (or a base class) has a registered `Codec`.
    source_hash : SHA-256 hex of the mesh or heightmap it was baked from (`file_sha256`).
    cache_key : SHA-256 hex of everything the bake depended on (`reliefkit.batch.key`);
        written into the manifest only when given.
    codecs : the kinds known (default: the table handed to `use_codecs`).

    Returns
    -------
    Path : the path written.
    """
    codecs = _table(codecs)
    codec = codecs.for_object(representation)
    arrays, params = codec.to_arrays(representation)
    return write_rk(path, codec.kind, arrays, params, source_hash=source_hash,
                    cache_key=cache_key, codecs=codecs)


def rk_bytes(representation, *, source_hash: str | None = None, cache_key: str | None = None,
             codecs: CodecTable | None = None) -> bytes:
    """The bytes `save` writes, made in memory (a batch worker returns them to the driver,
    which writes them atomically): the same writer, so the same bytes."""
    codecs = _table(codecs)
    codec = codecs.for_object(representation)
    arrays, params = codec.to_arrays(representation)
    head, arrays = _checked(codec.kind, arrays, params, source_hash, cache_key, codecs,
                            "cannot write the .rk bytes")
    buffer = io.BytesIO()
    _write_zip(buffer, head, arrays)
    return buffer.getvalue()


def codec_of(representation, *, codecs: CodecTable | None = None) -> Codec:
    """The codec that saves ``representation`` (in ``codecs`` or the process's table)."""
    return _table(codecs).for_object(representation)


def write_rk(path, kind: str, arrays: Mapping[str, np.ndarray], params: dict, *,
             source_hash: str | None = None, cache_key: str | None = None,
             codecs: CodecTable | None = None) -> Path:
    """Validate arrays and params against a registered kind, then write atomically.

    Arrays are stored C-contiguous and little-endian; values are kept bit for bit. An array
    that carries an encoding (`reliefkit.compact.encodings.encoding_of`) is stored as its
    encoded level 0 instead. On any failure nothing is left behind and an existing file at
    `path` is unchanged.
    """
    path = Path(path)
    head, arrays = _checked(kind, arrays, params, source_hash, cache_key, _table(codecs),
                            f"cannot write {path}")
    with atomic_path(path, error=FormatError) as tmp, open(tmp, "wb") as fh:
        _write_zip(fh, head, arrays)
    return path


def _checked(kind: str, arrays, params, source_hash, cache_key, codecs: CodecTable,
             where: str) -> tuple[dict, dict[str, np.ndarray]]:
    """The manifest's head and the arrays as stored, every value checked (else FormatError
    prefixed with ``where``)."""
    try:
        codec = codecs.for_kind(kind)
        arrays = _prepare_arrays(codec, arrays)
        if not isinstance(params, dict):
            raise FormatError(f"params must be a dict, got {type(params).__name__}")
        _check_json(params)
        _check_source_hash(source_hash)
        _check_source_hash(cache_key, "cache_key")
    except FormatError as exc:
        raise FormatError(f"{where}: {exc}") from None
    head = {"format": FORMAT_NAME, "format_version": FORMAT_VERSION, "kind": codec.kind,
            "kind_version": codec.version, "params": params, "source_hash": source_hash,
            "created_by": f"reliefkit {__version__}"}
    if cache_key is not None:  # optional: files baked without one keep their bytes
        head["cache_key"] = cache_key
    return head, arrays


def _prepare_arrays(codec: Codec, arrays) -> dict[str, np.ndarray]:
    if not isinstance(arrays, Mapping):
        raise FormatError(f"arrays must be a dict of numpy arrays, got {type(arrays).__name__}")
    present = {name: value for name, value in arrays.items() if value is not None}
    _check_array_set(codec, present)
    out = {}
    for name, spec in codec.arrays.items():
        if name not in present:
            continue
        arr = np.asarray(present[name])
        _check_array(codec.kind, name, spec, arr.dtype.newbyteorder("<"), arr.shape)
        if spec.finite:
            _check_finite(name, arr)
        out[name] = arr.astype(arr.dtype.newbyteorder("<"), order="C", copy=False)
    if codec.check_shapes is not None:
        codec.check_shapes({name: arr.shape for name, arr in out.items()})
    return out


class _HashingWriter:
    """A write-only file that hashes what passes through it."""

    def __init__(self, raw) -> None:
        self.raw = raw
        self.sha = hashlib.sha256()

    def write(self, data) -> int:
        self.sha.update(data)
        return self.raw.write(data)


def _zipinfo(name: str) -> zipfile.ZipInfo:
    info = zipfile.ZipInfo(name, date_time=_ZIP_DATE)
    info.compress_type = zipfile.ZIP_DEFLATED
    # ZipFile.open(info, "w") and writestr(info) take the level from the ZipInfo: the
    # attribute is public `compress_level` from Python 3.13, `_compresslevel` before.
    if hasattr(zipfile.ZipInfo, "compress_level"):
        info.compress_level = _DEFLATE_LEVEL
    else:
        info._compresslevel = _DEFLATE_LEVEL
    info.create_system = 3  # "Unix" on every platform (zipfile says 0 on Windows)
    info.external_attr = 0o644 << 16
    return info


def _write_zip(fh, head: dict, arrays: dict[str, np.ndarray]) -> None:
    entries = {}
    with zipfile.ZipFile(fh, "w", compression=zipfile.ZIP_DEFLATED, allowZip64=True) as zf:
        for name, arr in arrays.items():
            encoded = encoding_of(arr)
            stored = arr if encoded is None else encoded.data
            big = stored.nbytes > _FORCE_ZIP64
            with zf.open(_zipinfo(f"{name}.npy"), "w", force_zip64=big) as raw:
                out = _HashingWriter(raw)
                npy.write_array(out, stored, allow_pickle=False)
            entries[name] = {"dtype": stored.dtype.str, "shape": list(stored.shape),
                             "sha256": out.sha.hexdigest()}
            if encoded is not None:
                entries[name]["encoding"] = _encoding_entry(encoded)
        manifest = {**head, "arrays": entries}
        zf.writestr(_zipinfo(MANIFEST_NAME), json.dumps(manifest, indent=2) + "\n")


# ------------------------------------------ the same checks for other containers (io.gltf)


def prepare(representation, *, codecs: CodecTable | None = None
            ) -> tuple[Codec, dict[str, np.ndarray], dict]:
    """A representation's codec, arrays and params, checked as `save` checks them (dtypes,
    shapes, finiteness, JSON params), for a container other than .rk."""
    codec = _table(codecs).for_object(representation)
    arrays, params = codec.to_arrays(representation)
    arrays = _prepare_arrays(codec, arrays)
    if not isinstance(params, dict):
        raise FormatError(f"params must be a dict, got {type(params).__name__}")
    _check_json(params)
    return codec, arrays, params


def stored_form(array: np.ndarray) -> tuple[np.ndarray, dict | None]:
    """What a container stores of ``array``: the array itself, or its encoded level 0 and
    the encoding's record (everything but the bytes)."""
    encoded = encoding_of(array)
    return (array, None) if encoded is None else (encoded.data, _encoding_entry(encoded))


def check_stored(codec: Codec, names: Iterable[str], declared: Mapping[str, tuple]) -> None:
    """The arrays a container declares, before any is read: the set against the kind, each
    ``name -> (dtype, stored shape, encoding record or None)`` against its spec, and the
    decoded shapes against each other (`Codec.check_shapes`)."""
    _check_array_set(codec, names)
    shapes = {}
    for name, (dtype, shape, encoding) in declared.items():
        if encoding is None:
            _check_array(codec.kind, name, codec.arrays[name], dtype, shape)
            shapes[name] = tuple(shape)
        else:
            _check_encoding(codec, name, encoding, dtype, shape)
            shapes[name] = tuple(encoding["shape"])
    if codec.check_shapes is not None:
        codec.check_shapes(shapes)


def decoded_array(stored: np.ndarray, encoding: dict | None) -> np.ndarray:
    """A stored array as the representation holds it (decoded when it has an encoding)."""
    return _decoded(stored, encoding)


def check_finite_arrays(codec: Codec, arrays: Mapping[str, np.ndarray]) -> None:
    """NaN and Inf where the kind requires finite values, once the arrays are read."""
    for name, arr in arrays.items():
        if codec.arrays[name].finite:
            _check_finite(name, arr)


# --------------------------------------------------------------------------- reading


@dataclass(frozen=True)
class _Archive:
    """An open .rk: its zip directory, the binary file (or bytes) it was read from and that
    file's size."""

    zf: zipfile.ZipFile
    fh: io.BufferedIOBase
    size: int


@dataclass(frozen=True)
class _Span:
    """Where one member's raw (stored or deflated) bytes lie, checked to fit in the file."""

    info: zipfile.ZipInfo
    start: int  # the first data byte, just after the local header

    @property
    def end(self) -> int:
        return self.start + self.info.compress_size


@dataclass(frozen=True)
class _Member:
    """One .npy member whose header passed every check; nothing read yet. ``encoding``:
    the manifest's encoding of it (the member holds its blocks), checked."""

    span: _Span
    dtype: np.dtype
    shape: tuple[int, ...]
    fortran: bool
    header_len: int
    sha256: str
    encoding: dict | None = None

    @property
    def array_shape(self) -> tuple[int, ...]:
        """The shape of the array it stands for (an encoded one: decoded)."""
        return self.shape if self.encoding is None else tuple(self.encoding["shape"])

    @property
    def nbytes(self) -> int:
        """Bytes of the array it stands for in memory (an encoded one: decoded)."""
        dtype = self.dtype if self.encoding is None else np.dtype(self.encoding["dtype"])
        return math.prod(self.array_shape) * dtype.itemsize


def load(source, *, max_bytes: int = DEFAULT_MAX_BYTES, codecs: CodecTable | None = None):
    """Read an .rk file (or its bytes) and rebuild its representation.

    Parameters
    ----------
    source : the .rk file's path; or the bytes `rk_bytes` returns (bytes, bytearray,
        memoryview) or a seekable binary file object holding them, read with the same
        checks (a batch worker's result needs no file system).
    max_bytes : refuse files whose arrays declare more bytes than this in total
        (uncompressed, as the arrays will be in memory).
    codecs : the kinds known (default: the table handed to `use_codecs`).

    Raises
    ------
    FormatError : the file is missing, malformed, forged, corrupt or of an unknown kind, or
        the representation rejects its data (the message names the file, or "the .rk
        bytes").
    """
    codecs = _table(codecs)
    rk = read_rk(source, max_bytes=max_bytes, codecs=codecs)
    return build(codecs.for_kind(rk.kind), rk.arrays, rk.params, _named(source))


def build(codec: Codec, arrays: Mapping[str, np.ndarray], params: dict, where):
    """The representation of validated ``arrays`` and ``params``; what it rejects is a
    `FormatError` naming ``where`` (the file)."""
    try:
        return codec.from_arrays(dict(arrays), dict(params))
    except FormatError as exc:
        raise FormatError(f"{where}: {exc}") from exc
    except (ReliefkitError, KeyError, TypeError, ValueError, ArithmeticError) as exc:
        raise FormatError(f"{where}: invalid {codec.kind} data ({exc}); the file is corrupt or "
                          "forged") from exc


def read_manifest(source, *, codecs: CodecTable | None = None) -> dict:
    """The manifest of an .rk file (or its bytes, as `load` takes them), after every check
    that needs no array data.

    The manifest, the zip directory and every ``.npy`` header are validated; array data and
    checksums are not read (beyond the first few KiB of each member), so this is cheap for
    any file size.
    """
    with _open_rk(source) as archive:
        manifest, _, _ = _inspect(archive, None, _table(codecs))
    return manifest


def read_rk(source, *, max_bytes: int = DEFAULT_MAX_BYTES,
            codecs: CodecTable | None = None) -> RkFile:
    """Validate an .rk file (or its bytes, as `load` takes them) completely and return its
    arrays without building the object.

    Checks run before any array is allocated: zip directory and local headers, manifest,
    kind, member set, compression method, ``.npy`` headers, declared sizes against the zip
    directory's sizes and `max_bytes`. Then each member is streamed into its array with its
    SHA-256 and CRC-32 verified and its length exact, and finite-required arrays are checked.
    """
    with _open_rk(source) as archive:
        manifest, codec, members = _inspect(archive, max_bytes, _table(codecs))
        arrays = {name: _decoded(_read_member(archive, name, m), m.encoding)
                  for name, m in members.items()}
        check_finite_arrays(codec, arrays)
    return RkFile(codec.kind, manifest, manifest["params"], arrays)


@contextlib.contextmanager
def _open_rk(source):
    """Open the file (or wrap the bytes) and its zip directory; prefix every FormatError
    with what `_named` calls it and map zip/IO errors. Members are read from the same open
    file as the directory."""
    where = _named(source)
    try:
        with _binary(source) as fh:
            if not zipfile.is_zipfile(fh):
                raise FormatError("not a .rk file (not a zip archive, or truncated); "
                                  "re-create it with reliefkit")
            size = fh.seek(0, io.SEEK_END)
            with zipfile.ZipFile(fh) as zf:
                yield _Archive(zf, fh, size)
    except FormatError as exc:
        raise FormatError(f"{where}: {exc}") from None
    except (zipfile.BadZipFile, zipfile.LargeZipFile, EOFError, OSError,
            NotImplementedError) as exc:
        raise FormatError(f"{where}: the zip is corrupt or truncated ({exc}); re-create it "
                          "with reliefkit") from exc


def _named(source) -> str:
    """What messages call ``source``: its path, or the bytes or stream (never their
    content)."""
    if isinstance(source, bytes | bytearray | memoryview):
        return "the .rk bytes"
    if hasattr(source, "read"):
        name = getattr(source, "name", None)  # an open file says its own path
        return name if isinstance(name, str) else "the .rk stream"
    return str(Path(source))


def _binary(source):
    """A context manager of a seekable binary file holding the .rk: the bytes wrapped, a
    caller's file object as it is (left open), a path opened (closed on exit). What cannot
    be read is a FormatError without the prefix `_open_rk` adds."""
    if isinstance(source, bytes | bytearray | memoryview):
        return contextlib.nullcontext(io.BytesIO(source))
    if hasattr(source, "read"):
        seekable = getattr(source, "seekable", None)
        if isinstance(source, io.TextIOBase) or seekable is None or not seekable():
            raise FormatError("needs the bytes or a seekable file object opened in binary "
                              "mode ('rb')")
        return contextlib.nullcontext(source)
    path = Path(source)
    if not path.is_file():
        raise FormatError("is not a file" if path.exists() else "no such file")
    try:
        return open(path, "rb")  # noqa: SIM115 - the caller's with closes it
    except OSError as exc:
        raise FormatError(f"cannot read ({exc.strerror or exc}); check the path and its "
                          "permissions") from None


def _inspect(archive: _Archive, max_bytes: int | None, codecs: CodecTable):
    """All checks that need no array data; returns (manifest, codec, members)."""
    infos = _member_table(archive.zf)
    manifest = _read_manifest_json(archive, infos)
    codec = _check_manifest(manifest, codecs)
    entries = manifest["arrays"]
    _check_array_set(codec, entries)
    _check_member_set(entries, infos)
    spans = _layout(archive, infos.values())
    members = {name: _inspect_member(archive, codec, name, entry, spans[f"{name}.npy"])
               for name, entry in entries.items()}
    if codec.check_shapes is not None:
        codec.check_shapes({name: member.array_shape for name, member in members.items()})
    total = sum(m.nbytes for m in members.values())
    if max_bytes is not None and total > max_bytes:
        raise FormatError(f"arrays declare {total / 2**30:.2f} GiB, over the "
                          f"{max_bytes / 2**30:.2f} GiB limit; pass a larger max_bytes if you "
                          "trust this file")
    return manifest, codec, members


def _member_table(zf: zipfile.ZipFile) -> dict[str, zipfile.ZipInfo]:
    infos = zf.infolist()
    table = {info.filename: info for info in infos}
    if len(table) != len(infos):
        raise FormatError("the zip has duplicate member names; the file is corrupt or forged")
    for info in infos:
        if info.flag_bits & _FLAG_ENCRYPTED:
            raise FormatError(f"zip member {info.filename!r} is encrypted; .rk files never "
                              "are")
        if info.flag_bits & _FLAG_PATCHED:
            raise FormatError(f"zip member {info.filename!r} is compressed patched data, "
                              "which .rk files never use; the file is corrupt or forged")
    return table


def _locate(archive: _Archive, info: zipfile.ZipInfo) -> _Span:
    """Find a member's data after its local header; it must lie inside the file."""
    what = f"zip member {info.filename!r}"
    fixed = b""
    if 0 <= info.header_offset <= archive.size:
        archive.fh.seek(info.header_offset)
        fixed = archive.fh.read(_LOCAL_HEADER.size)
    if len(fixed) != _LOCAL_HEADER.size or fixed[:4] != _LOCAL_MAGIC:
        raise FormatError(f"{what} has no local header at offset {info.header_offset}; the "
                          "file is truncated or corrupt")
    flags, name_len, extra_len = (_LOCAL_HEADER.unpack(fixed)[i] for i in (2, 9, 10))
    name = archive.fh.read(name_len).decode("utf-8" if flags & _FLAG_UTF8 else "cp437",
                                            errors="replace")
    if name != info.orig_filename:
        raise FormatError(f"{what} has the name {name!r} in its local header; the file is "
                          "corrupt or forged")
    span = _Span(info, info.header_offset + _LOCAL_HEADER.size + name_len + extra_len)
    if span.end > archive.size:
        raise FormatError(f"{what} claims {info.compress_size} bytes of data at offset "
                          f"{span.start}, more than the zip holds; the file is truncated or "
                          "forged")
    return span


def _layout(archive: _Archive, infos: Iterable[zipfile.ZipInfo]) -> dict[str, _Span]:
    """Every member located; no two may overlap (shared data is a zip-bomb trick)."""
    spans = {info.filename: _locate(archive, info) for info in infos}
    ordered = sorted(spans.values(), key=lambda span: span.info.header_offset)
    for a, b in itertools.pairwise(ordered):
        if a.end > b.info.header_offset:
            raise FormatError(f"zip members {a.info.filename!r} and {b.info.filename!r} "
                              "overlap; the file is corrupt or forged")
    return spans


def _member_chunks(archive: _Archive, span: _Span, what: str,
                   chunk: int | None = None) -> Iterator[bytes]:
    """A member's uncompressed bytes in pieces of at most `chunk`, exactly its declared
    ``file_size`` of them in all (stored or deflated members only); `chunk` defaults to
    1 MiB and also bounds each read of compressed bytes.

    The method and sizes are checked now; the stream as it is read. It never yields more than
    declared and never inflates more than one byte past it: a stream that ends early, runs on
    past the declared size or leaves compressed bytes over is refused, and so is a CRC-32
    mismatch once the whole member is read.
    """
    info = span.info
    method = info.compress_type
    if method not in _METHODS:
        label = _OTHER_METHODS.get(method, "unknown")
        raise FormatError(f"{what} uses zip compression method {method} ({label}); .rk "
                          "members are stored or deflated: re-create the file with "
                          "reliefkit.save")
    if method == zipfile.ZIP_STORED and info.compress_size != info.file_size:
        raise FormatError(f"{what} is stored in {info.compress_size} bytes but claims "
                          f"{info.file_size}; the file is truncated or forged")
    if method == zipfile.ZIP_DEFLATED and \
            info.file_size > _MAX_DEFLATE_RATIO * info.compress_size + _MAX_DEFLATE_RATIO:
        raise FormatError(f"{what} claims {info.file_size} bytes from {info.compress_size} "
                          "deflated bytes, more than deflate can expand; the file is forged")
    chunk = max(1, chunk or _CHUNK)
    raw = _RawReader(archive.fh, span, what, chunk)
    if method == zipfile.ZIP_STORED:
        return _checked_crc(raw, info, what)
    return _checked_crc(_inflate(raw, info.file_size, what, chunk), info, what)


class _RawReader:
    """A member's raw bytes, `chunk` at a time; it seeks before every read (the one open
    file is shared) and refuses to read past the member or to come back short."""

    def __init__(self, fh, span: _Span, what: str, chunk: int) -> None:
        self.fh, self.what, self.chunk = fh, what, chunk
        self.pos, self.left = span.start, span.info.compress_size

    def __iter__(self) -> Iterator[bytes]:
        while self.left:
            n = min(self.chunk, self.left)
            self.fh.seek(self.pos)
            data = self.fh.read(n)
            if len(data) != n:
                raise FormatError(f"{self.what} ends early; the file is truncated")
            self.pos += n
            self.left -= n
            yield data


def _inflate(raw: _RawReader, size: int, what: str, chunk: int) -> Iterator[bytes]:
    """Inflate a raw deflate stream that must hold exactly `size` bytes and end with the
    member's compressed bytes; output comes at most `chunk` bytes at a time."""
    inflater = zlib.decompressobj(-zlib.MAX_WBITS)
    pieces = iter(raw)
    pending = b""
    left = size
    read_all = False  # zlib may still hold output (and the end) after the last input byte
    try:
        while left or not inflater.eof:
            if inflater.eof:
                raise FormatError(f"{what} inflates to {size - left} bytes, fewer than its "
                                  f"declared {size}; the file is truncated, corrupt or forged")
            if not pending and not read_all:
                pending = next(pieces, b"")
                read_all = not pending
            out = inflater.decompress(pending, min(chunk, left) if left else 1)
            if out and not left:
                raise FormatError(f"{what} inflates to more than its declared {size} bytes; "
                                  "the file is corrupt or forged")
            if not out and not inflater.eof and len(inflater.unconsumed_tail) == len(pending):
                if read_all:
                    raise FormatError(f"{what}: its deflate stream ends early; the file is "
                                      "truncated or corrupt")
                raise FormatError(f"{what}: its deflate stream does not progress; the file is "
                                  "corrupt")
            pending = inflater.unconsumed_tail
            if out:
                left -= len(out)
                yield out
    except zlib.error as exc:
        raise FormatError(f"{what}: its deflate stream is corrupt ({exc}); the file is "
                          "corrupt") from None
    if inflater.unused_data or pending or raw.left:
        raise FormatError(f"{what} has compressed bytes after the end of its deflate stream; "
                          "the file is corrupt or forged")


def _checked_crc(pieces: Iterable[bytes], info: zipfile.ZipInfo, what: str) -> Iterator[bytes]:
    crc = 0
    for piece in pieces:
        crc = zlib.crc32(piece, crc)
        yield piece
    if crc != info.CRC:
        raise FormatError(f"checksum mismatch for {what} (zip CRC-32): the file is corrupt")


def _peek(archive: _Archive, span: _Span, what: str, n: int) -> bytes:
    """The first (at most) `n` uncompressed bytes of a member; reads about that much."""
    head = bytearray()
    pieces = _member_chunks(archive, span, what, chunk=n)
    try:
        for piece in pieces:
            head += piece
            if len(head) >= n:
                break
    finally:
        pieces.close()
    return bytes(head[:n])


def _read_manifest_json(archive: _Archive, infos: dict) -> dict:
    info = infos.get(MANIFEST_NAME)
    if info is None:
        raise FormatError(f"no {MANIFEST_NAME} in the zip; this is not a .rk file (a plain "
                          ".npz?) — write it with reliefkit.save")
    if info.file_size > MAX_MANIFEST_BYTES:
        raise FormatError(f"{MANIFEST_NAME} is {info.file_size} bytes, over the 1 MiB limit; "
                          "the file is corrupt or forged")
    raw = b"".join(_member_chunks(archive, _locate(archive, info), MANIFEST_NAME))
    try:
        manifest = json.loads(raw.decode("utf-8"))
    except (UnicodeDecodeError, ValueError, RecursionError) as exc:
        raise FormatError(f"{MANIFEST_NAME} is not valid JSON ({exc}); the file is "
                          "corrupt") from None
    if not isinstance(manifest, dict):
        raise FormatError(f"{MANIFEST_NAME} is not a JSON object; the file is corrupt")
    return manifest


def _check_manifest(manifest: dict, codecs: CodecTable) -> Codec:
    """The manifest's top-level fields, in order; returns the kind's codec."""
    if manifest.get("format") != FORMAT_NAME:
        raise FormatError(f"manifest format is {manifest.get('format')!r}, not "
                          f"'{FORMAT_NAME}'; this is not a .rk file")
    version = manifest.get("format_version")
    _check_version(version, FORMAT_VERSION, "format_version")
    codec = codecs.for_kind(manifest.get("kind"))
    _check_version(manifest.get("kind_version"), codec.version,
                   f"kind '{codec.kind}' version")
    if not isinstance(manifest.get("params"), dict):
        raise FormatError("manifest params is not a JSON object; the file is corrupt")
    _check_source_hash(manifest.get("source_hash"))
    _check_source_hash(manifest.get("cache_key"), "cache_key")
    entries = manifest.get("arrays")
    if not isinstance(entries, dict):
        raise FormatError("manifest arrays is not a JSON object; the file is corrupt")
    for name, entry in entries.items():
        _check_entry(name, entry)
    return codec


def _check_version(value, supported: int, what: str) -> None:
    if type(value) is not int or value < 1:
        raise FormatError(f"unsupported {what} {value!r}; expected an integer from 1 to "
                          f"{supported}")
    if value > supported:
        raise FormatError(f"{what} {value} was written by a newer reliefkit (this one reads "
                          f"up to {supported}); upgrade reliefkit")


def _check_entry(name, entry) -> None:
    if not _NAME_RE.match(name):
        raise FormatError(f"manifest lists an invalid array name {name!r}; the file is forged")
    ok = (isinstance(entry, dict) and isinstance(entry.get("dtype"), str)
          and isinstance(entry.get("shape"), list)
          and all(type(d) is int and d >= 0 for d in entry["shape"])
          and isinstance(entry.get("sha256"), str) and _SHA_RE.match(entry["sha256"]))
    if not ok:
        raise FormatError(f"manifest entry for array '{name}' needs dtype, shape (non-negative "
                          "ints) and sha256 (64 hex digits); the file is corrupt")


def _check_member_set(entries: dict, infos: dict) -> None:
    for name in entries:
        if f"{name}.npy" not in infos:
            raise FormatError(f"array '{name}' is listed in the manifest but {name}.npy is not "
                              "in the zip; the file is incomplete")
    expected = {f"{name}.npy" for name in entries} | {MANIFEST_NAME}
    extra = sorted(set(infos) - expected)
    if extra:
        raise FormatError(f"zip member {extra[0]!r} is not listed in the manifest; the file is "
                          "corrupt or forged")


def _inspect_member(archive: _Archive, codec: Codec, name: str, entry: dict,
                    span: _Span) -> _Member:
    """Check one member's zip entry and .npy header; read at most a few KiB."""
    info = span.info
    head = _peek(archive, span, f"array '{name}'", _HEADER_PEEK)
    dtype, shape, fortran, header_len = _parse_npy_header(name, head)
    encoding = entry.get("encoding")
    if encoding is None:
        _check_array(codec.kind, name, codec.arrays[name], dtype, shape)
    else:
        _check_encoding(codec, name, encoding, dtype, shape)
    if dtype.str != entry["dtype"] or list(shape) != entry["shape"]:
        raise FormatError(f"array '{name}': the .npy header says {dtype.str} {shape} but the "
                          f"manifest says {entry['dtype']} {tuple(entry['shape'])}; the file is "
                          "corrupt")
    member = _Member(span, dtype, shape, fortran, header_len, entry["sha256"], encoding)
    stored = math.prod(shape) * dtype.itemsize
    if header_len + stored != info.file_size:
        raise FormatError(f"array '{name}' declares shape {shape} {dtype.str} "
                          f"({stored} bytes) but its member holds "
                          f"{info.file_size - header_len} bytes of data; the file is truncated "
                          "or forged")
    return member


_ENCODING_KEYS = {"format": str, "shape": list, "dtype": str, "layered": bool, "srgb": bool,
                  "mipmaps": bool, "scale": float, "bias": float}


def _encoding_entry(encoded: EncodedImage) -> dict:
    """The manifest's record of an encoded array (everything but its bytes)."""
    return {key: list(getattr(encoded, key)) if key == "shape" else getattr(encoded, key)
            for key in _ENCODING_KEYS}


def _check_encoding(codec: Codec, name: str, encoding, dtype: np.dtype, shape: tuple) -> None:
    """An encoded member: its manifest record, the array it decodes to against the kind's
    spec, and its bytes (uint8, one dimension) exactly what the encoding holds."""
    where = f"array '{name}'"
    ok = isinstance(encoding, dict) and set(encoding) == set(_ENCODING_KEYS) and all(
        isinstance(encoding[k], t) and (t is not float or math.isfinite(encoding[k]))
        for k, t in _ENCODING_KEYS.items())
    if not ok:
        raise FormatError(f"{where}: its encoding needs exactly {', '.join(_ENCODING_KEYS)}; "
                          "the file is corrupt")
    try:
        check(encoding["format"], tuple(encoding["shape"]), encoding["dtype"],
              encoding["layered"])
    except ReliefkitError as exc:
        raise FormatError(f"{where}: {exc}; the file is corrupt") from None
    decoded_shape = tuple(encoding["shape"])
    _check_array(codec.kind, name, codec.arrays[name], np.dtype(encoding["dtype"]),
                 decoded_shape)
    expected = stored_bytes(encoding["format"], decoded_shape, encoding["layered"])
    if dtype != np.uint8 or shape != (expected,):
        raise FormatError(f"{where}: a {encoding['format']} encoding of {decoded_shape} is "
                          f"({expected},) uint8, its member holds {shape} {dtype.str}; the file "
                          "is corrupt or forged")


def _decoded(stored: np.ndarray, encoding: dict | None) -> np.ndarray:
    """A member's array: itself, or the array its encoding stands for."""
    if encoding is None:
        return stored
    values = dict(encoding, shape=tuple(encoding["shape"]))
    return decoded(EncodedImage(data=stored, **values))


def _parse_npy_header(name: str, head: bytes) -> tuple[np.dtype, tuple, bool, int]:
    """(dtype, shape, fortran_order, header length) from the first bytes of a .npy."""
    fp = io.BytesIO(head)
    readers = {(1, 0): npy.read_array_header_1_0, (2, 0): npy.read_array_header_2_0}
    try:
        version = npy.read_magic(fp)
        if version in readers:
            shape, fortran, dtype = readers[version](fp, max_header_size=_MAX_NPY_HEADER)
    except Exception as exc:  # noqa: BLE001 - untrusted bytes; numpy's parser raises many types
        first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise FormatError(f"array '{name}' has a malformed .npy header ({first}); the file "
                          "is corrupt") from None
    if version not in readers:
        raise FormatError(f"array '{name}' uses .npy format version {version}; .rk files use "
                          "1.0 or 2.0")
    if not all(type(d) is int and d >= 0 for d in shape):
        raise FormatError(f"array '{name}' has an invalid shape {shape}; the file is corrupt")
    return dtype, shape, fortran, fp.tell()


def _read_member(archive: _Archive, name: str, member: _Member) -> np.ndarray:
    """Stream one validated member into a fresh array, hashing the bytes on the way."""
    arr = np.empty(member.shape, member.dtype, order="F" if member.fortran else "C")
    flat = arr.ravel(order="K").view(np.uint8)
    sha = hashlib.sha256()
    skip, pos = member.header_len, 0
    for piece in _member_chunks(archive, member.span, f"array '{name}'"):
        sha.update(piece)
        data = memoryview(piece)
        if skip:
            cut = min(skip, len(data))
            data, skip = data[cut:], skip - cut
        if pos + len(data) > flat.size:  # unreachable: the size was checked against the header
            raise FormatError(f"array '{name}' holds more data than declared; the file is "
                              "forged")
        flat[pos:pos + len(data)] = np.frombuffer(data, np.uint8)
        pos += len(data)
    if pos != flat.size:
        raise FormatError(f"array '{name}' ends early; the file is truncated")
    if sha.hexdigest() != member.sha256:
        raise FormatError(f"checksum mismatch for array '{name}': the file is corrupt")
    return np.ascontiguousarray(arr) if member.fortran else arr


def file_sha256(path) -> str:
    """SHA-256 hex digest of a file, read in 1 MiB blocks (for ``source_hash``)."""
    sha = hashlib.sha256()
    try:
        with open(path, "rb") as fh:
            for block in iter(lambda: fh.read(_CHUNK), b""):
                sha.update(block)
    except OSError as exc:
        raise FormatError(f"{path}: cannot read ({exc.strerror or exc}); check the path") \
            from exc
    return sha.hexdigest()
